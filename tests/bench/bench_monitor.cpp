// Benchmarks of the EDTL monitors: online cost per requirement per scan (a requirement
// of ten operators) and offline throughput on a one-million-state trace.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "engine.hpp"
#include "monitor/edtl.hpp"

namespace {

using namespace plcfi;

// Ten operators: RISING, AND, OR, NOT, >, =, FALLING, PASSED, comparison and a second
// edge, spread over the six formulas.
const char* kRequirement = R"Y(requirements:
  - id: TEN_OPS
    trigger: "/P.a AND P.n > 3 OR \\P.b"
    invariant: "NOT P.c OR P.n = 7"
    final: "PASSED(T#50ms)"
    delay: "PASSED(T#200ms)"
    reaction: "P.b AND ~P.a"
    release: "P.c AND P.n < 0"
)Y";

const char* kProgram = R"(PROGRAM P
VAR a, b, c : BOOL; n : INT; END_VAR
END_PROGRAM
)";

std::string temp_file(const std::string& name, const std::string& text) {
  auto p = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream f(p);
  f << text;
  return p;
}

void BM_edtl_online_per_requirement_scan(benchmark::State& state) {
  monitor::RequirementsFile reqs;
  std::string err;
  auto path = temp_file("plcfi_bench_req.yaml", kRequirement);
  if (!monitor::load_requirements(path, &reqs, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  auto mon = monitor::generate_monitors(reqs);
  auto b = st::build_sources({{"p.st", kProgram}}, st::CompileOptions{}, {{mon.name, mon.text}});
  if (!b->ok()) {
    state.SkipWithError(b->diags.render_all().c_str());
    return;
  }
  auto set = monitor::MonitorSet::create(*b->app, reqs, &err);
  st::Machine m(*b->app);
  st::VarHandle a = *st::resolve(*b->app, "P.a", &err), bb = *st::resolve(*b->app, "P.b", &err);
  st::VarHandle c = *st::resolve(*b->app, "P.c", &err), n = *st::resolve(*b->app, "P.n", &err);
  // A pseudo-random signal pattern, precomputed so the loop measures only the monitor.
  // Busy (range 0): signals toggle at random every scan, so many trigger instances with
  // their own timer points are open at once. Quiet (range 1): a machine-like pattern
  // where a trigger fires every 100 scans and its instance resolves within a few scans.
  std::mt19937 rng(7);
  std::vector<uint8_t> pattern(4096);
  bool busy = state.range(0) == 0;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (busy) pattern[i] = static_cast<uint8_t>(rng());
    else pattern[i] = static_cast<uint8_t>((i % 100 < 3 ? 1 : 0) | (i % 100 >= 3 && i % 100 < 8 ? 2 : 0) | (5 << 4));
  }
  // The harness alone (pattern lookup and the four signal writes that a program's scan
  // would do), timed in the same process, so the monitor's own cost can be reported.
  auto set_signals = [&](uint64_t scan) {
    uint8_t p = pattern[scan & 4095];
    st::write_bool(m, a, p & 1);
    st::write_bool(m, bb, p & 2);
    st::write_bool(m, c, (p & 12) == 12);
    st::write_int(m, n, (p >> 4) & 7);
  };
  constexpr uint64_t kHarness = 2'000'000;
  auto h0 = std::chrono::steady_clock::now();
  for (uint64_t i = 0; i < kHarness; ++i) {
    set_signals(i);
    benchmark::DoNotOptimize(m.mem());
  }
  double harness_ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - h0).count() / kHarness;
  uint64_t scan = 0;
  auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    set_signals(scan);
    set->step(m, scan, static_cast<int64_t>(scan) * 10'000'000);
    ++scan;
  }
  double total_ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() /
                    static_cast<double>(state.iterations());
  state.counters["harness_ns"] = harness_ns;
  state.counters["monitor_ns"] = total_ns - harness_ns;
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
  std::filesystem::remove(path);
}

void BM_edtl_offline_1m_states(benchmark::State& state) {
  std::string csv = "time,H,D,N\n";
  std::mt19937 rng(11);
  bool h = false, d = false;
  for (int i = 0; i < 1'000'000; ++i) {
    if (rng() % 8 == 0) h = !h;
    d = h || (d && rng() % 4 != 0);
    csv += std::to_string(i) + "e-2," + (h ? "1," : "0,") + (d ? "1," : "0,") + std::to_string(rng() % 100) + "\n";
  }
  auto trace = temp_file("plcfi_bench_trace.csv", csv);
  auto reqs_path = temp_file("plcfi_bench_dryer.yaml", R"Y(requirements:
  - id: OFF
    trigger: "\\H AND D"
    invariant: "D"
    final: "PASSED(T#20ms)"
    delay: "TRUE"
    reaction: "NOT D"
    release: "H"
  - id: ON
    trigger: "/H"
    delay: "TRUE"
    reaction: "D"
  - id: LEVEL
    trigger: "INCREASES(N) AND N > 90"
    delay: "PASSED(T#30ms)"
    reaction: "N < 50"
)Y");
  monitor::RequirementsFile reqs;
  std::string err;
  if (!monitor::load_requirements(reqs_path, &reqs, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  uint64_t states = 0;
  for (auto _ : state) {
    monitor::TraceCheck out;
    if (!monitor::check_trace(reqs, trace, 0, &out, &err)) {
      state.SkipWithError(err.c_str());
      break;
    }
    states += out.states;
  }
  state.SetItemsProcessed(static_cast<int64_t>(states));
  state.counters["states/s"] = benchmark::Counter(static_cast<double>(states), benchmark::Counter::kIsRate);
  std::filesystem::remove(trace);
  std::filesystem::remove(reqs_path);
}

}  // namespace

BENCHMARK(BM_edtl_online_per_requirement_scan)->Arg(0)->Arg(1)->ArgName("quiet");
BENCHMARK(BM_edtl_offline_1m_states)->Unit(benchmark::kMillisecond)->Iterations(1);
