// Division and MOD by a constant (compiled to a multiplication by a reciprocal) give
// exactly what the hardware division gives, for every sign and the extreme values.
#include <gtest/gtest.h>

#include <climits>
#include <random>

#include "engine.hpp"
#include "vm/ops.hpp"

namespace plcfi::st {
namespace {

template <class T>
void check_divisor(int32_t k, const char* type) {
  std::string src = std::string("PROGRAM P\nVAR n : ") + type + "; q : " + type + "; r : " + type +
                    "; END_VAR\nq := n / " + (k < 0 ? "(" + std::to_string(k) + ")" : std::to_string(k)) +
                    ";\nr := n MOD " + (k < 0 ? "(" + std::to_string(k) + ")" : std::to_string(k)) + ";\nEND_PROGRAM\n";
  auto b = build_sources({{"divk.st", src}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  std::string dis = disassemble(*b->app, b.get());
  ASSERT_NE(std::string::npos, dis.find("DIVK_")) << dis;
  ASSERT_NE(std::string::npos, dis.find("MODK_")) << dis;
  Machine m(*b->app);
  std::string err;
  auto n = *resolve(*b->app, "P.n", &err), q = *resolve(*b->app, "P.q", &err), r = *resolve(*b->app, "P.r", &err);
  const auto& inst = b->app->programs[0];
  std::mt19937 rng(static_cast<unsigned>(k) * 7919u);
  const int64_t kk = k;  // neighbours of k computed without overflow
  std::vector<int64_t> values{0, 1, -1, kk, -kk, kk - 1, kk + 1, -kk + 1, -kk - 1, std::numeric_limits<T>::min(),
                              std::numeric_limits<T>::max(), std::numeric_limits<T>::min() + 1};
  for (int i = 0; i < 2000; ++i) values.push_back(static_cast<T>(rng()));
  for (int64_t v : values) {
    auto x = static_cast<T>(v);
    write_int(m, n, x);
    ASSERT_TRUE(m.call(inst.pou->entry, inst.addr));
    EXPECT_EQ(static_cast<T>(x / k), read_int(m, q)) << x << " / " << k;
    EXPECT_EQ(static_cast<T>(x % k), read_int(m, r)) << x << " MOD " << k;
  }
}

TEST(DivisionByConstant, DintMatchesHardwareDivision) {
  for (int32_t k : {2, 3, 7, 10, 97, 1000, 65536, 1 << 30, INT32_MAX, -2, -3, -97, -1000, INT32_MIN + 1})
    check_divisor<int32_t>(k, "DINT");
}

TEST(DivisionByConstant, IntMatchesHardwareDivision) {
  for (int32_t k : {2, 3, 5, 7, 100, 1000, 32767, -3, -100}) check_divisor<int16_t>(k, "INT");
}

// The instruction's arithmetic itself (ops::divk with ops::divk_constants), against the
// hardware's division, on many more divisors than the programs above: every one up to
// 600, each power of two and its neighbours, large primes, all of them negated too; the
// dividends at the type's ends, around multiples of the divisor, and random.
TEST(DivisionByConstant, MultiplyAndShiftMatchHardwareDivision) {
  std::vector<int64_t> divisors;
  for (int64_t k = 2; k <= 600; ++k) divisors.push_back(k);
  for (int s = 10; s <= 31; ++s)
    for (int64_t d : {-1, 0, 1}) divisors.push_back((int64_t{1} << s) + d);
  for (int64_t k : {65521, 1000003, 134456, 139968, 2147483629, INT32_MAX}) divisors.push_back(k);
  const size_t positive = divisors.size();
  for (size_t i = 0; i < positive; ++i) divisors.push_back(-divisors[i]);
  std::mt19937 rng(2024);
  for (int64_t k : divisors) {
    if (k > INT32_MAX || k < INT32_MIN + 1) continue;
    const uint64_t ms = ops::divk_constants(k);
    const auto k32 = static_cast<int32_t>(k);
    std::vector<int64_t> values{0, 1, -1, INT32_MIN, INT32_MAX, INT32_MIN + 1, INT32_MAX - 1};
    for (int64_t j = -3; j <= 3; ++j)
      for (int64_t d : {-1, 0, 1}) values.push_back(j * k + d);
    for (int i = 0; i < 300; ++i) values.push_back(static_cast<int32_t>(rng()));
    for (int64_t v : values) {
      if (v < INT32_MIN || v > INT32_MAX) continue;
      const auto n = static_cast<int32_t>(v);
      ASSERT_EQ((ops::divk<int32_t, false>(n, ms, k32)), n / k32) << n << " / " << k;
      ASSERT_EQ((ops::divk<int32_t, true>(n, ms, k32)), n % k32) << n << " MOD " << k;
      const auto h = static_cast<int16_t>(v);
      if (k >= -32768 && k <= 32767) {
        ASSERT_EQ((ops::divk<int16_t, false>(h, ms, k32)), static_cast<int16_t>(h / k32)) << h << " / " << k;
        ASSERT_EQ((ops::divk<int16_t, true>(h, ms, k32)), static_cast<int16_t>(h % k32)) << h << " MOD " << k;
      }
    }
  }
}

}  // namespace
}  // namespace plcfi::st
