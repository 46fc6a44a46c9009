// Division and MOD by a constant (compiled to a multiplication by a reciprocal) give
// exactly what the hardware division gives, for every sign and the extreme values.
#include <gtest/gtest.h>

#include <climits>
#include <random>

#include "engine.hpp"

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

}  // namespace
}  // namespace plcfi::st
