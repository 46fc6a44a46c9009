// Both tiers against MATIEC: the interpreter and the native tier run each kernel in
// tests/bench/matiec and must reach the recorded program state after 1, 1000 and 100000
// scans (tests/bench/matiec/matiec_expected.hpp; every variable listed, integers exactly,
// REAL and LREAL bit for bit). The five MATIEC kernels' states are MATIEC's own results;
// nested_fbs and crc16 are plcfi's kernels, their states computed by the hand-written C++
// in matiec_kernels.hpp.
//
// Scan k runs at IEC time k x 10 ms, the program instance being the CONFIGURATION's
// `instance0`, as in MATIEC's recorded runs.
//
// Under AddressSanitizer the interpreter is ~10x slower and 100000 scans of the heavy
// kernels take minutes, so there the interpreter checks the states after 1 and 1000 scans
// and only the native tier (compiled without sanitizers by the system compiler) goes on
// to 100000. The normal tree checks everything in both tiers.
#include <gtest/gtest.h>

#include <bit>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>

#include "engine.hpp"
#include "matiec_expected.hpp"
#include "native/native.hpp"

#ifndef PLCFI_MATIEC_KERNEL_DIR
#error "PLCFI_MATIEC_KERNEL_DIR must name tests/bench/matiec"
#endif

#if defined(__SANITIZE_ADDRESS__)
#define PLCFI_MATIEC_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PLCFI_MATIEC_UNDER_ASAN 1
#endif
#endif

namespace plcfi::st {
namespace {

namespace mk = plcfi::bench::matiec;

#ifdef PLCFI_MATIEC_UNDER_ASAN
constexpr bool kUnderAsan = true;
#else
constexpr bool kUnderAsan = false;
#endif

std::string read_kernel(const std::string& name) {
  std::ifstream f(std::string(PLCFI_MATIEC_KERNEL_DIR) + "/" + name + ".st", std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Interpreter and Native: compiled with coverage marks (the default options); Run: as
// `plcfi run` compiles without --coverage (selects for IFs on bits, rule 26), in the
// interpreter.
enum class Tier { Interpreter, Native, Run };

struct Param {
  const char* kernel;
  Tier tier;
};

// gtest prints a parameter's bytes otherwise (and ctest shows them beside the test's name).
void PrintTo(const Param& p, std::ostream* os) {
  *os << p.kernel
      << (p.tier == Tier::Interpreter ? " in the interpreter" : p.tier == Tier::Native ? " in the native tier" : " as plcfi run compiles it");
}

std::string param_name(const ::testing::TestParamInfo<Param>& p) {
  return std::string(p.param.tier == Tier::Interpreter ? "interp_" : p.param.tier == Tier::Native ? "native_" : "run_") +
         p.param.kernel;
}

class MatiecState : public ::testing::TestWithParam<Param> {};

// A REAL with 9, an LREAL with 17 significant digits: as many as the recorded values have.
std::string digits(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// One variable against its recorded value; a failure names the kernel, scan and both values.
void expect_var(const Application& app, const Machine& m, const mk::ExpectedVar& e, int scans) {
  std::string err;
  auto h = resolve(app, "instance0." + std::string(e.name), &err);
  ASSERT_TRUE(h) << err;
  SCOPED_TRACE(std::string(e.name) + " after " + std::to_string(scans) + " scans, MATIEC/recorded " + e.value);
  switch (e.kind) {
    case mk::Kind::Int:
      EXPECT_EQ(read_int(m, *h), std::strtoll(e.value, nullptr, 10));
      break;
    case mk::Kind::Real: {
      ASSERT_EQ(h->type->kind, TypeKind::Real) << e.name << " is not a REAL";
      float got = static_cast<float>(read_real(m, *h)), want = std::strtof(e.value, nullptr);
      EXPECT_EQ(std::bit_cast<uint32_t>(got), std::bit_cast<uint32_t>(want)) << "ours " << digits("%.9g", got);
      break;
    }
    case mk::Kind::LReal: {
      ASSERT_EQ(h->type->kind, TypeKind::LReal) << e.name << " is not an LREAL";
      double got = read_real(m, *h), want = std::strtod(e.value, nullptr);
      EXPECT_EQ(std::bit_cast<uint64_t>(got), std::bit_cast<uint64_t>(want)) << "ours " << digits("%.17g", got);
      break;
    }
  }
}

TEST_P(MatiecState, ReproducesTheRecordedState) {
  const Param& p = GetParam();
  const mk::KernelInfo* ki = nullptr;
  for (const auto& k : mk::kernels())
    if (std::string(k.name) == p.kernel) ki = &k;
  ASSERT_NE(ki, nullptr);
  const std::string source = read_kernel(p.kernel);
  ASSERT_FALSE(source.empty()) << "cannot read " << PLCFI_MATIEC_KERNEL_DIR << "/" << p.kernel << ".st";

  CompileOptions options;
  options.coverage = p.tier != Tier::Run;
  auto b = build_sources({{std::string(p.kernel) + ".st", source}}, options);
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  const Application& app = *b->app;
  const ProgramInstance* inst = nullptr;
  for (const auto& pi : app.programs)
    if (pi.name == "instance0") inst = &pi;
  ASSERT_NE(inst, nullptr) << "no program instance instance0";
  ASSERT_EQ(app.tasks.size(), 1u);
  EXPECT_EQ(app.tasks[0].interval_ns, 10'000'000);

  std::unique_ptr<NativeCode> native;
  Machine m(app);
  if (p.tier == Tier::Native) {
    std::string err;
    native = NativeCode::build(app, NativeOptions{}, &err);
    ASSERT_TRUE(native) << err;
    EXPECT_EQ(native->interpreted(), 0u);
    m.set_native(native.get());
  }

  const int limit = kUnderAsan && p.tier != Tier::Native ? 1000 : 100000;
  int done = 0;
  for (const mk::ExpectedState& es : ki->states) {
    if (es.scans > limit) continue;
    for (; done < es.scans; ++done) {
      m.set_now(static_cast<int64_t>(done) * 10'000'000);
      ASSERT_TRUE(m.call(inst->pou->entry, inst->addr))
          << "scan " << done << ": " << describe_trap(app, m.trap());
    }
    for (const mk::ExpectedVar& e : es.vars) expect_var(app, m, e, es.scans);
  }
  EXPECT_GT(done, 0);
}

INSTANTIATE_TEST_SUITE_P(
    Kernels, MatiecState,
    ::testing::Values(Param{"statemachine", Tier::Interpreter}, Param{"statemachine", Tier::Native},
                      Param{"intloop", Tier::Interpreter}, Param{"intloop", Tier::Native},
                      Param{"realmath", Tier::Interpreter}, Param{"realmath", Tier::Native},
                      Param{"arrays", Tier::Interpreter}, Param{"arrays", Tier::Native},
                      Param{"fbcalls", Tier::Interpreter}, Param{"fbcalls", Tier::Native},
                      Param{"nested_fbs", Tier::Interpreter}, Param{"nested_fbs", Tier::Native},
                      Param{"crc16", Tier::Interpreter}, Param{"crc16", Tier::Native},
                      Param{"statemachine", Tier::Run}, Param{"intloop", Tier::Run}, Param{"realmath", Tier::Run},
                      Param{"arrays", Tier::Run}, Param{"fbcalls", Tier::Run}, Param{"nested_fbs", Tier::Run},
                      Param{"crc16", Tier::Run}),
    param_name);

// Every kernel in the table has a test above, and every state lists at least a checksum.
TEST(MatiecState, EveryKernelIsCoveredWithThreeStates) {
  EXPECT_EQ(mk::kernels().size(), 7u);
  for (const auto& k : mk::kernels()) {
    ASSERT_EQ(k.states.size(), 3u) << k.name;
    EXPECT_EQ(k.states[0].scans, 1);
    EXPECT_EQ(k.states[1].scans, 1000);
    EXPECT_EQ(k.states[2].scans, 100000);
    for (const auto& s : k.states) {
      ASSERT_FALSE(s.vars.empty());
      EXPECT_STREQ(s.vars[0].name, "checksum");
    }
  }
}

}  // namespace
}  // namespace plcfi::st
