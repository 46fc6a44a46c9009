// Benchmarks of the fault-injection campaign: wall time of the whole stamping campaign,
// and the passive driver's cost per scan with 1, 100 and 10,000 pending test cases on a
// synthetic plant (measured against the same scans without the driver, in-process).
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <fmt/format.h>

#include "campaign/driver.hpp"
#include "campaign/generate.hpp"
#include "runtime/runtime.hpp"
#include "../support/fake_backend.hpp"

namespace {

using namespace plcfi;
namespace fs = std::filesystem;

void BM_campaign_stamping(benchmark::State& state) {
  std::string path = std::string(PLCFI_SOURCE_DIR) + "/faults/campaigns/stamping/campaign.yaml";
  size_t executions = 0;
  for (auto _ : state) {
    campaign::Campaign c;
    std::string err;
    if (!campaign::load_campaign(path, &c, &err)) {
      state.SkipWithError(err.c_str());
      return;
    }
    campaign::CampaignBuild cb;
    if (!campaign::prepare_campaign(std::move(c), &cb, &err)) {
      state.SkipWithError(err.c_str());
      return;
    }
    campaign::CampaignResult r;
    campaign::DriverOptions opt;
    if (!campaign::run_campaign(cb, opt, &r, &err)) {
      state.SkipWithError(err.c_str());
      return;
    }
    executions = r.executions.size();
  }
  state.counters["executions"] = static_cast<double>(executions);
}
BENCHMARK(BM_campaign_stamping)->Unit(benchmark::kMillisecond);

// A synthetic plant: a counter on %IW0 that never reaches the preconditions' values, so
// every case stays pending and the driver evaluates all preconditions every scan.
testing_support::FakeBackend counter_backend() {
  testing_support::FakeBackend b(4, 0, "counter");
  b.on_read = [n = uint64_t{0}](uint8_t* in, int64_t) mutable {
    testing_support::FakeBackend::put_u16(in, static_cast<uint16_t>(n++ % 30000));
  };
  return b;
}

// Writes a campaign with n cases (one TSD step and one FMEA row each) into a folder.
std::string synthetic_campaign(size_t n) {
  fs::path dir = fs::temp_directory_path() / fmt::format("plcfi_bench_campaign_{}_{}", n, ::getpid());
  fs::create_directories(dir);
  std::ofstream(dir / "p.st") << "PROGRAM P\nVAR x AT %IW0 : INT; y AT %IX2.0 : BOOL; alarm : BOOL; n : DINT; END_VAR\n"
                                 "n := n + 1;\nIF x > 29990 THEN alarm := TRUE; END_IF;\nEND_PROGRAM\n";
  std::ofstream tsd(dir / "tsd.yaml");
  tsd << "lifelines:\n  - {name: X, bind: P.x, kind: analog}\n  - {name: Y, bind: \"%IX2.0\", kind: sensor}\n"
         "scenarios:\n  - id: s\n    steps:\n";
  for (size_t k = 0; k < n; ++k)
    tsd << fmt::format("      - {{id: k{}, precondition: {{X: -{}}}, start: previous, transitions: [{{lifeline: Y, to: TRUE, max: 1s}}]}}\n",
                       k, k + 1);
  std::ofstream fmea(dir / "fmea.csv");
  fmea << "id,tsd_transition,failure_mode,S,effect,cause,O,detection,D,RPN,fault_class,alarm\n";
  for (size_t k = 0; k < n; ++k) fmea << fmt::format("F{},s.k{}.Y,m,1,e,c,1,d,1,1,1,P.alarm\n", k, k);
  std::ofstream(dir / "classes.yaml") << "fault_classes:\n  - id: 1\n    requirements:\n      - {id: alarm, reaction: \"{alarm}\"}\n";
  std::ofstream(dir / "campaign.yaml") << "campaign: synthetic\nprogram: p.st\nplant: none\ncycle: 10ms\ntsd: tsd.yaml\n"
                                          "fmea: fmea.csv\nfault_classes: classes.yaml\nsearch_window: 24h\n";
  return (dir / "campaign.yaml").string();
}

void BM_campaign_driver_per_scan(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  std::string path = synthetic_campaign(n);
  campaign::Campaign c;
  std::string err;
  if (!campaign::load_campaign(path, &c, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  const int64_t scans = 2000;
  c.budget_ns = scans * 10'000'000;
  campaign::CampaignBuild cb;
  if (!campaign::prepare_campaign(std::move(c), &cb, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  fs::remove_all(fs::path(path).parent_path());
  auto backend = counter_backend();
  double with_driver = 0, baseline = 0;
  for (auto _ : state) {
    // The same scans of the same program without the driver (baseline)...
    auto t0 = std::chrono::steady_clock::now();
    {
      rt::Runtime r(*cb.build->app, cb.schedule, &backend);
      r.cold_restart(1);
      for (int64_t i = 0; i < scans; ++i) r.scan();
    }
    auto t1 = std::chrono::steady_clock::now();
    // ...and with every precondition checked before each scan.
    campaign::CampaignResult res;
    campaign::DriverOptions opt;
    if (!campaign::run_campaign_on(cb, &backend, opt, &res, &err) || !res.executions.empty()) {
      state.SkipWithError("synthetic campaign did not run as planned");
      return;
    }
    auto t2 = std::chrono::steady_clock::now();
    baseline += std::chrono::duration<double, std::nano>(t1 - t0).count();
    with_driver += std::chrono::duration<double, std::nano>(t2 - t1).count();
  }
  double iters = static_cast<double>(state.iterations()) * static_cast<double>(scans);
  state.counters["scan_ns"] = baseline / iters;
  state.counters["scan_with_driver_ns"] = with_driver / iters;
  state.counters["driver_ns_per_precondition"] = (with_driver - baseline) / iters / static_cast<double>(n);
}
BENCHMARK(BM_campaign_driver_per_scan)->Arg(1)->Arg(100)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace
