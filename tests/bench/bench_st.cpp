// bench_st.cpp: performance benchmark of the ST engine (Google Benchmark).
//
// For each kernel in kernels/ (see kernels/README.md):
//   BM_<kernel>_vm      one scan of the compiled PROGRAM in the VM per iteration
//   BM_<kernel>_native  one scan of the hand translation in native_kernels.hpp
// Both advance the scan clock by 10 ms after every scan. Before anything is timed, 100
// scans run in a fresh VM and a fresh native state and their `result` values are compared
// with each other and with the README's expected value; a mismatch aborts (exit 1).
//
// BM_parse_check_10k_lines builds (parse + semantic check + codegen) ~10,000 generated
// lines of ST; BM_build_stdlib_only builds an empty application, i.e. the fixed cost of
// the standard library that every build_sources call includes.
//
// After the runs a table prints VM ns/scan, native ns/scan and the ratio per kernel (CPU
// time, the minimum over repetitions when --benchmark_repetitions is given).
//
// The MATIEC comparison (its kernels, checks and table) is in bench_matiec.cpp.
//
// `plcfi_bench --disasm=<kernel>` prints the kernel's bytecode instead (for profiling).
#include <benchmark/benchmark.h>
#include <cstring>

#include "native/native.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "bench_report.hpp"
#include "engine.hpp"
#include "native_kernels.hpp"

#ifndef PLCFI_BENCH_KERNEL_DIR
#error "PLCFI_BENCH_KERNEL_DIR must name tests/bench/kernels"
#endif

namespace {

using namespace plcfi;
namespace nb = plcfi::bench;
using nb::CollectingReporter;

constexpr int64_t kScanNs = 10'000'000;  // 10 ms per scan, as in the native kernels
constexpr int kCheckScans = 100;

[[noreturn]] void die(const std::string& msg) {
  std::fprintf(stderr, "plcfi_bench: FATAL: %s\n", msg.c_str());
  std::fflush(stderr);
  std::exit(1);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) die("cannot read " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ------------------------------------------------------------------ VM side

// One kernel compiled on its own: the build, the program instance and `result`.
struct VmKernel {
  std::string name;
  std::unique_ptr<st::Build> build;
  uint32_t entry = 0, addr = 0;
  st::VarHandle result;
  std::unique_ptr<st::NativeCode> native;  // the native tier (built on first use)
};

VmKernel compile_kernel(const std::string& name) {
  VmKernel k;
  k.name = name;
  std::string file = name + ".st";
  k.build = st::build_sources({{file, read_file(std::string(PLCFI_BENCH_KERNEL_DIR) + "/" + file)}},
                              st::CompileOptions{});
  if (!k.build->ok()) die("kernel " + file + " does not compile:\n" + k.build->diags.render_all());
  bool found = false;
  for (const auto& p : k.build->app->programs) {
    if (p.pou && p.pou->name == name) {
      k.entry = p.pou->entry;
      k.addr = p.addr;
      found = true;
    }
  }
  if (!found) die("kernel " + file + ": no program instance named " + name);
  std::string err;
  auto h = st::resolve(*k.build->app, name + ".result", &err);
  if (!h) die("kernel " + file + ": " + err);
  k.result = *h;
  return k;
}

// Compiled once, shared by the check and the benchmarks (the Application is immutable;
// every benchmark run makes its own Machine).
const VmKernel& kernel(const std::string& name) {
  static std::map<std::string, VmKernel> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, compile_kernel(name)).first;
  return it->second;
}

// The kernel's native tier: generated C++, compiled by the system compiler, cached.
const st::NativeCode& native_tier(const std::string& name) {
  VmKernel& k = const_cast<VmKernel&>(kernel(name));
  if (!k.native) {
    std::string err;
    k.native = st::NativeCode::build(*k.build->app, st::NativeOptions{}, &err);
    if (!k.native) die("kernel " + name + ": " + err);
    if (k.native->interpreted() != 0) die("kernel " + name + ": the native tier left code to the interpreter");
  }
  return *k.native;
}

// One scan at `now`. Returns false (after reporting) on a trap.
inline bool vm_scan(st::Machine& m, const VmKernel& k, int64_t now) {
  m.set_now(now);
  return m.call(k.entry, k.addr);
}

[[noreturn]] void die_trap(const VmKernel& k, const st::Machine& m, int scan) {
  die("kernel " + k.name + ": trap in scan " + std::to_string(scan) + ": " +
      st::describe_trap(*k.build->app, m.trap()));
}

// ------------------------------------------------------------------ kernel table

// Binds a kernel name to its native state and scan function.
template <class State, void (*Scan)(State&)>
struct Native {
  using StateT = State;
  static void scan(State& s) { Scan(s); }
};

using StateMachineK = Native<nb::StateMachineState, nb::state_machine_scan>;
using IntLoopK = Native<nb::IntLoopState, nb::int_loop_scan>;
using RealMathK = Native<nb::RealMathState, nb::real_math_scan>;
using ArrayStructK = Native<nb::ArrayStructState, nb::array_struct_scan>;
using FbCallsK = Native<nb::FbCallsState, nb::fb_calls_scan>;

// The benchmark loops. The clock handling is identical in both: scan at `now`, then
// advance it by 10 ms.
void run_vm(benchmark::State& state, const char* name) {
  const VmKernel& k = kernel(name);
  st::Machine m(*k.build->app);
  if (state.range(0) == 1) m.set_native(&native_tier(name));
  int64_t now = 0;
  int scans = 0;
  for (auto _ : state) {
    if (!vm_scan(m, k, now)) {
      state.SkipWithError("trap");
      die_trap(k, m, scans);
    }
    now += kScanNs;
    ++scans;
  }
  state.SetItemsProcessed(state.iterations());
}

template <class K>
void run_native(benchmark::State& state) {
  // Heap-allocated like the VM's memory; its address escapes so the compiler must keep
  // every scan's stores and cannot fold scans together.
  auto s = std::make_unique<typename K::StateT>();
  typename K::StateT* p = s.get();
  benchmark::DoNotOptimize(p);
  for (auto _ : state) {
    K::scan(*p);
    p->now_ns += kScanNs;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}

// ------------------------------------------------------------------ correctness check

struct Expect {
  const char* name;
  bool is_real;
  int64_t int_value;   // README: after 100 scans
  double real_value;
};

constexpr Expect kExpected[] = {
    {"state_machine", false, 154228, 0},
    {"int_loop", false, 17562871, 0},
    {"real_math", true, 0, 113833.73635594684},
    {"array_struct", false, 1538511, 0},
    {"fb_calls", false, 4603772, 0},
};

template <class K>
typename K::StateT native_after(int scans) {
  typename K::StateT s{};
  for (int i = 0; i < scans; ++i) {
    K::scan(s);
    s.now_ns += kScanNs;
  }
  return s;
}

// Runs 100 scans in a fresh VM and natively; compares. Dies on any mismatch.
template <class K>
void check_kernel(const Expect& e) {
  const VmKernel& k = kernel(e.name);
  st::Machine m(*k.build->app);
  st::Machine tier(*k.build->app);
  tier.set_native(&native_tier(e.name));
  int64_t now = 0;
  for (int i = 0; i < kCheckScans; ++i) {
    if (!vm_scan(m, k, now)) die_trap(k, m, i);
    if (!vm_scan(tier, k, now)) die_trap(k, tier, i);
    now += kScanNs;
  }
  // The native tier leaves memory (compiler temporaries aside) and coverage exactly as
  // the interpreter does.
  if (st::first_difference(st::scratch_ranges(*k.build->app), m.mem(), tier.mem(), m.mem_size()) != m.mem_size() ||
      m.taken() != tier.taken())
    die("kernel " + std::string(e.name) + ": the native tier's memory after 100 scans differs from the interpreter's");
  auto s = native_after<K>(kCheckScans);
  if (!e.is_real) {
    int64_t vm = st::read_int(m, k.result);
    int64_t nat = s.result;
    if (vm != nat || nat != e.int_value) {
      die("kernel " + std::string(e.name) + ": result after 100 scans differs: VM " + std::to_string(vm) +
          ", native " + std::to_string(nat) + ", expected (README) " + std::to_string(e.int_value));
    }
    std::printf("check %-14s OK  result after %d scans = %" PRId64 " (VM = native = README)\n", e.name,
                kCheckScans, vm);
  } else {
    double vm = st::read_real(m, k.result);
    double nat = s.result;
    if (vm == nat && nat == e.real_value) {
      std::printf("check %-14s OK  result after %d scans = %.17g (VM = native = README, exact)\n", e.name,
                  kCheckScans, vm);
    } else {
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    "kernel %s: result after 100 scans differs: VM %.17g, native %.17g, expected (README) "
                    "%.17g; VM - native = %.17g (relative %.3g), native - README = %.17g",
                    e.name, vm, nat, e.real_value, vm - nat, nat != 0 ? (vm - nat) / nat : 0.0,
                    nat - e.real_value);
      die(buf);
    }
  }
}

void check_all() {
  check_kernel<StateMachineK>(kExpected[0]);
  check_kernel<IntLoopK>(kExpected[1]);
  check_kernel<RealMathK>(kExpected[2]);
  check_kernel<ArrayStructK>(kExpected[3]);
  check_kernel<FbCallsK>(kExpected[4]);
}

// ------------------------------------------------------------------ parse/check/codegen

// ~100 lines per module: a STRUCT, a FUNCTION, a FUNCTION_BLOCK with IF/ELSIF, CASE with
// lists and ranges, FOR over arrays of elementary types and of structs, WHILE, a TON and
// a function call. One file per module plus a PROGRAM that instantiates and calls them.
std::string gen_module(int k) {
  std::string s = R"(TYPE Rec_@K@ :
STRUCT
  a : DINT;
  b : REAL;
  flag : BOOL;
END_STRUCT;
END_TYPE

FUNCTION Scale_@K@ : REAL
VAR_INPUT
  x : REAL;
  lo : REAL;
  hi : REAL;
END_VAR
VAR
  span : REAL;
END_VAR
span := hi - lo;
IF span <= 0.0 THEN
  Scale_@K@ := lo;
ELSE
  Scale_@K@ := LIMIT(lo, lo + x * span / 100.0, hi);
END_IF;
END_FUNCTION

FUNCTION_BLOCK Ctrl_@K@
VAR_INPUT
  enable : BOOL;
  setpoint : REAL;
  mode : INT;
END_VAR
VAR_OUTPUT
  out : REAL;
  state : INT;
  alarm : BOOL;
  flags : INT;
END_VAR
VAR
  buf : ARRAY[0..15] OF DINT;
  recs : ARRAY[1..4] OF Rec_@K@;
  i : INT;
  total : DINT;
  t : TON;
END_VAR
IF NOT enable THEN
  state := 0;
  out := 0.0;
  RETURN;
END_IF;
CASE mode OF
  0:
    state := 1;
  1, 2:
    state := state + 1;
  3..5:
    state := 10;
    alarm := TRUE;
ELSE
  state := -1;
END_CASE;
total := 0;
FOR i := 0 TO 15 DO
  buf[i] := buf[i] + INT_TO_DINT(i) * @K@;
  IF buf[i] > 100000 THEN
    buf[i] := 0;
  ELSIF buf[i] < -100000 THEN
    buf[i] := 0;
  END_IF;
  total := total + buf[i];
END_FOR;
flags := 0;
FOR i := 1 TO 4 DO
  recs[i].a := recs[i].a + total MOD 7;
  recs[i].b := recs[i].b * 0.5 + DINT_TO_REAL(recs[i].a);
  recs[i].flag := recs[i].a > 10;
  IF recs[i].flag THEN
    flags := flags + 1;
  END_IF;
END_FOR;
WHILE total > 1000 DO
  total := total / 2;
END_WHILE;
t(IN := alarm, PT := T#500ms);
IF t.Q THEN
  alarm := FALSE;
END_IF;
out := Scale_@K@(x := setpoint, lo := 0.0, hi := DINT_TO_REAL(total) + 1.0);
END_FUNCTION_BLOCK
)";
  const std::string ks = std::to_string(k);
  for (size_t pos = s.find("@K@"); pos != std::string::npos; pos = s.find("@K@", pos + ks.size()))
    s.replace(pos, 3, ks);
  return s;
}

struct Generated {
  std::vector<std::pair<std::string, std::string>> sources;
  size_t lines = 0;
};

const Generated& generated_10k() {
  static const Generated g = [] {
    Generated r;
    auto count = [](const std::string& t) { return static_cast<size_t>(std::count(t.begin(), t.end(), '\n')); };
    constexpr int kModules = 107;  // ~10,000 lines in total
    std::string prog = "PROGRAM Main\nVAR\n";
    for (int k = 0; k < kModules; ++k) prog += "  c" + std::to_string(k) + " : Ctrl_" + std::to_string(k) + ";\n";
    prog += "  sum : REAL;\n  alarms : INT;\n  cycle : INT;\nEND_VAR\ncycle := (cycle + 1) MOD 7;\nsum := 0.0;\n";
    for (int k = 0; k < kModules; ++k) {
      std::string c = "c" + std::to_string(k);
      prog += c + "(enable := TRUE, setpoint := " + std::to_string(k % 100) + ".0, mode := cycle);\n";
      prog += "sum := sum + " + c + ".out;\n";
      prog += "IF " + c + ".alarm THEN\n  alarms := alarms + 1;\nEND_IF;\n";
    }
    prog += "END_PROGRAM\n";
    for (int k = 0; k < kModules; ++k) {
      std::string text = gen_module(k);
      r.lines += count(text);
      r.sources.emplace_back("ctrl_" + std::to_string(k) + ".st", std::move(text));
    }
    r.lines += count(prog);
    r.sources.emplace_back("main.st", std::move(prog));
    return r;
  }();
  return g;
}

void check_generated() {
  const Generated& g = generated_10k();
  auto b = st::build_sources(g.sources, st::CompileOptions{});
  if (!b->ok()) die("generated 10k-line application does not compile:\n" + b->diags.render_all());
  std::printf("check %-14s OK  %zu lines in %zu files compile (%zu warnings)\n", "parse_10k", g.lines,
              g.sources.size(), b->diags.warning_count());
}

void BM_parse_check_10k_lines(benchmark::State& state) {
  const Generated& g = generated_10k();
  for (auto _ : state) {
    auto b = st::build_sources(g.sources, st::CompileOptions{});
    if (!b->ok()) {
      state.SkipWithError("compile failed");
      break;
    }
    benchmark::DoNotOptimize(b);
  }
  state.counters["lines"] = static_cast<double>(g.lines);
}

void BM_build_stdlib_only(benchmark::State& state) {
  for (auto _ : state) {
    auto b = st::build_sources({{"empty.st", "PROGRAM Empty\nVAR\n  x : INT;\nEND_VAR\nx := x + 1;\nEND_PROGRAM\n"}},
                               st::CompileOptions{});
    if (!b->ok()) {
      state.SkipWithError("compile failed");
      break;
    }
    benchmark::DoNotOptimize(b);
  }
}

// ------------------------------------------------------------------ reporting

void print_table(const CollectingReporter& rep) {
  static const char* const kNames[] = {"state_machine", "int_loop", "real_math", "array_struct", "fb_calls"};
  bool any = false;
  for (const char* n : kNames) {
    double vm = rep.ns(std::string("BM_") + n + "_vm"), nat = rep.ns(std::string("BM_") + n + "_native");
    double tier = rep.ns(std::string("BM_") + n + "_tier");
    if (vm == 0 && nat == 0 && tier == 0) continue;
    if (!any) {
      std::printf("\nST engine vs native C++ (CPU time per scan; target: engine <= 5x native)\n");
      std::printf("%-14s %14s %14s %14s %10s %11s\n", "kernel", "interp ns", "tier ns", "native ns", "interp/nat",
                  "tier/nat");
      any = true;
    }
    auto ratio = [&](double x) {
      char buf[32] = "-";
      if (x > 0 && nat > 0) std::snprintf(buf, sizeof buf, "%.2fx%s", x / nat, x / nat > 5.0 ? " !" : "");
      return std::string(buf);
    };
    std::printf("%-14s %14.1f %14.1f %14.1f %10s %11s\n", n, vm, tier, nat, ratio(vm).c_str(), ratio(tier).c_str());
  }
  double parse = rep.ns("BM_parse_check_10k_lines");
  if (parse > 0) {
    double lines = rep.lines("BM_parse_check_10k_lines");
    double base = rep.ns("BM_build_stdlib_only");
    std::printf("\nbuild_sources (parse + check + codegen): %.2f ms per 10k lines (%.0f lines in %.2f ms",
                parse / 1e6 * 10000.0 / lines, lines, parse / 1e6);
    if (base > 0) std::printf("; includes %.2f ms fixed stdlib cost per build", base / 1e6);
    std::printf(")\n");
  }
}

}  // namespace

BENCHMARK_CAPTURE(run_vm, state_machine, "state_machine")->Name("BM_state_machine_vm")->Arg(0);
BENCHMARK_CAPTURE(run_vm, state_machine_tier, "state_machine")->Name("BM_state_machine_tier")->Arg(1);
BENCHMARK(run_native<StateMachineK>)->Name("BM_state_machine_native");
BENCHMARK_CAPTURE(run_vm, int_loop, "int_loop")->Name("BM_int_loop_vm")->Arg(0);
BENCHMARK_CAPTURE(run_vm, int_loop_tier, "int_loop")->Name("BM_int_loop_tier")->Arg(1);
BENCHMARK(run_native<IntLoopK>)->Name("BM_int_loop_native");
BENCHMARK_CAPTURE(run_vm, real_math, "real_math")->Name("BM_real_math_vm")->Arg(0);
BENCHMARK_CAPTURE(run_vm, real_math_tier, "real_math")->Name("BM_real_math_tier")->Arg(1);
BENCHMARK(run_native<RealMathK>)->Name("BM_real_math_native");
BENCHMARK_CAPTURE(run_vm, array_struct, "array_struct")->Name("BM_array_struct_vm")->Arg(0);
BENCHMARK_CAPTURE(run_vm, array_struct_tier, "array_struct")->Name("BM_array_struct_tier")->Arg(1);
BENCHMARK(run_native<ArrayStructK>)->Name("BM_array_struct_native");
BENCHMARK_CAPTURE(run_vm, fb_calls, "fb_calls")->Name("BM_fb_calls_vm")->Arg(0);
BENCHMARK_CAPTURE(run_vm, fb_calls_tier, "fb_calls")->Name("BM_fb_calls_tier")->Arg(1);
BENCHMARK(run_native<FbCallsK>)->Name("BM_fb_calls_native");
BENCHMARK(BM_parse_check_10k_lines)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_build_stdlib_only)->Unit(benchmark::kMillisecond);

// The custom reporter replaces the library's default one, so apply --benchmark_color
// here: colour on a terminal unless it is switched off.
benchmark::ConsoleReporter::OutputOptions console_options(int argc, char** argv) {
  bool color = isatty(STDOUT_FILENO) != 0;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--benchmark_color=", 0) == 0) {
      std::string v = a.substr(18);
      color = v == "true" || v == "yes" || v == "1" || (v == "auto" && isatty(STDOUT_FILENO) != 0);
    }
  }
  return color ? benchmark::ConsoleReporter::OO_ColorTabular : benchmark::ConsoleReporter::OO_Tabular;
}

int main(int argc, char** argv) {
  // --disasm=<kernel>: print the kernel's bytecode (st::disassemble) and exit.
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--disasm=", 0) == 0) {
      const VmKernel& k = kernel(a.substr(9));
      std::fputs(st::disassemble(*k.build->app, k.build.get()).c_str(), stdout);
      return 0;
    }
  }
  const auto options = console_options(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  check_all();
  check_generated();
  nb::check_matiec();
  std::fflush(stdout);
  CollectingReporter rep(options);
  benchmark::RunSpecifiedBenchmarks(&rep);
  print_table(rep);
  nb::print_matiec_table(rep);
  benchmark::Shutdown();
  return 0;
}
