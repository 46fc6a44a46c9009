// The plant kinds compared in one run: the stamping program scanned for 60 s of virtual
// time on the built-in plant, on the same model exported as an FMU (plant steps through the
// FMI interface) and on the stamping plant written in ST. Reported: ns per PLC scan of
// each (thread CPU time), the FMU's overhead over the built-in plant in percent, and how
// many times faster than real time the ST plant runs.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <time.h>

#include <chrono>
#include <filesystem>

#include <fmt/format.h>

#include "engine.hpp"
#include "io/sim/plant_factory.hpp"
#include "io/sim/sim_backend.hpp"
#include "plant_model/fmu/export.hpp"
#include "runtime/runtime.hpp"

namespace {

using namespace plcfi;
namespace fs = std::filesystem;

constexpr int64_t kScans = 6000;  // 60 s at the program's 10 ms

struct Sim {
  std::unique_ptr<io::SimBackend> backend;
  std::unique_ptr<rt::Runtime> runtime;
};

Sim make_sim(const st::Application& app, const rt::Schedule& sched, const std::string& plant, std::string* err) {
  Sim s;
  auto p = io::open_plant(plant, "", err);
  if (!p) return s;
  s.backend = io::SimBackend::create(app, std::move(p), err);
  if (s.backend) s.runtime = std::make_unique<rt::Runtime>(app, sched, s.backend.get());
  return s;
}

// CPU time of this thread: on a shared machine another process's load does not count
// against the plant (on an idle machine it equals the wall time).
double cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

double run_ns(Sim& s) {
  const double t0 = cpu_ns();
  s.runtime->cold_restart(1);
  for (int64_t i = 0; i < kScans; ++i) s.runtime->scan();
  return cpu_ns() - t0;
}

void BM_stamping_sim_plant_kinds(benchmark::State& state) {
  const std::string src = PLCFI_SOURCE_DIR;
  std::string err;
  st::CompileOptions opt;
  opt.warnings = false;
  auto b = st::build_files({src + "/st_programs/stamping/stamping_fixed.st"}, opt);
  rt::Schedule sched;
  if (!b->ok() || !sched.from_configuration(*b->app, &err)) {
    state.SkipWithError("stamping_fixed.st does not build");
    return;
  }
  const fs::path dir = fs::temp_directory_path() / fmt::format("plcfi_bench_plant_{}", ::getpid());
  fs::create_directories(dir);
  plant::fmu::ExportOptions ex;
  ex.library = PLCFI_STAMPING_FMU_LIBRARY;
  ex.out = (dir / "stamping.fmu").string();
  ex.plant_file = (dir / "stamping_fmu.yaml").string();
  auto builtin_model = plant::make_builtin_plant("stamping", "", &err);
  plant::fmu::export_stamping_fmu(*builtin_model, ex);

  Sim builtin = make_sim(*b->app, sched, "stamping", &err);
  Sim fmu = make_sim(*b->app, sched, ex.plant_file, &err);
  Sim st = make_sim(*b->app, sched, src + "/plant_model/stamping/st/stamping_st.yaml", &err);
  if (!builtin.runtime || !fmu.runtime || !st.runtime) {
    state.SkipWithError(err.c_str());
    fs::remove_all(dir);
    return;
  }
  double t_builtin = 0, t_fmu = 0, t_st = 0;
  for (auto _ : state) {
    // Interleaved, so that a change in the machine's load hits all three alike.
    t_builtin += run_ns(builtin);
    t_fmu += run_ns(fmu);
    t_st += run_ns(st);
  }
  const double scans = static_cast<double>(state.iterations()) * static_cast<double>(kScans);
  state.counters["builtin_ns_per_scan"] = t_builtin / scans;
  state.counters["fmu_ns_per_scan"] = t_fmu / scans;
  state.counters["st_plant_ns_per_scan"] = t_st / scans;
  state.counters["fmu_overhead_pct"] = 100.0 * (t_fmu - t_builtin) / t_builtin;
  // 10 ms of virtual time per scan.
  state.counters["st_plant_x_realtime"] = 1e7 / (t_st / scans);
  state.counters["builtin_x_realtime"] = 1e7 / (t_builtin / scans);
  fs::remove_all(dir);
}
BENCHMARK(BM_stamping_sim_plant_kinds)->Unit(benchmark::kMillisecond);

}  // namespace
