// Benchmark of CPTest+ scripts: a 1000-line script of WAITs and ASSERT_COMs over one hour
// of virtual time on the bead dispenser (target: under a second), the program and the
// plant scanning all the while.
#include <benchmark/benchmark.h>

#include <string>

#include "engine.hpp"
#include "io/link_fault.hpp"
#include "io/sim/sim_backend.hpp"
#include "plant_model/bead_dispenser/bead_dispenser.hpp"
#include "runtime/runtime.hpp"
#include "runtime/schedule.hpp"
#include "script/bind.hpp"
#include "script/cpt.hpp"
#include "script/runner.hpp"

namespace {

using namespace plcfi;

void BM_script_1000_lines_1h(benchmark::State& state) {
  st::CompileOptions opt;
  opt.warnings = false;
  auto b = st::build_files({std::string(PLCFI_SOURCE_DIR) + "/st_programs/bead_dispenser/bead_dispenser.st"}, opt);
  std::string err;
  rt::Schedule sched;
  if (!b->ok() || !sched.from_configuration(*b->app, &err)) {
    state.SkipWithError("the bead dispenser program does not compile");
    return;
  }
  plant::BeadParams prm;
  prm.hopper_beads[0] = 1'000'000;  // a bead per request for the whole hour
  auto sim = io::SimBackend::create(*b->app, std::make_unique<plant::BeadDispenserPlant>(prm), &err);
  io::LinkFaultBackend link(sim.get(), "plant");
  rt::Runtime runtime(*b->app, sched, &link);
  // 250 requests of 4 lines, 14.4 s each: 1000 lines, 3600 s.
  std::string text;
  for (int i = 0; i < 250; ++i)
    text += "SET PASS_ONE_BALL\nWAIT 14400 MS\nRESET PASS_ONE_BALL\nASSERT_COM ISTRUE IS_BEAD_SEEN\n";
  script::Script s;
  script::BoundScript bound;
  if (!script::parse_script("bench.cpt", text, &s, &err) || !script::bind_script(*b->app, s, {"plant"}, &bound, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  int64_t virtual_ns = 0;
  for (auto _ : state) {
    runtime.cold_restart(1);
    script::ScriptResult r = script::run_script(runtime, bound, {});
    if (r.verdict != script::Verdict::Passed) {
      state.SkipWithError(("the script did not pass: " + r.reason).c_str());
      return;
    }
    virtual_ns = r.end_ns;
  }
  state.counters["lines"] = static_cast<double>(s.commands.size());
  state.counters["virtual_s"] = static_cast<double>(virtual_ns) * 1e-9;
  state.counters["virtual_s_per_s"] = benchmark::Counter(static_cast<double>(virtual_ns) * 1e-9 * static_cast<double>(state.iterations()),
                                                          benchmark::Counter::kIsRate);
}
BENCHMARK(BM_script_1000_lines_1h)->Unit(benchmark::kMillisecond);

}  // namespace
