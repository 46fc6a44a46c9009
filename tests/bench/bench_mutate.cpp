// Benchmark of plcfi mutate: mutants judged per second on the stamping campaign (fixed
// program) with 1 and with 2 worker processes, both measured in the same run, and their
// ratio. The campaign is prepared once; each measurement is a whole mutation run.
#include <benchmark/benchmark.h>

#include <chrono>

#include "campaign/generate.hpp"
#include "campaign/mutate.hpp"

namespace {

using namespace plcfi;

void BM_mutate_stamping_jobs(benchmark::State& state) {
  const std::string root = PLCFI_SOURCE_DIR;
  campaign::Campaign c;
  std::string err;
  if (!campaign::load_campaign(root + "/faults/campaigns/stamping/campaign.yaml", &c, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  c.programs = {root + "/st_programs/stamping/stamping_fixed.st"};
  campaign::CampaignBuild cb;
  if (!campaign::prepare_campaign(std::move(c), &cb, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  double seconds[3] = {0, 0, 0};
  size_t judged = 0;
  for (auto _ : state) {
    for (unsigned jobs : {1u, 2u}) {
      campaign::MutateOptions opt;
      opt.jobs = jobs;
      campaign::MutationRun run;
      auto t0 = std::chrono::steady_clock::now();
      if (!campaign::run_mutation(cb, opt, &run, &err)) {
        state.SkipWithError(err.c_str());
        return;
      }
      seconds[jobs] += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      judged = 0;
      for (const auto& m : run.mutants) judged += !m.equivalent;
    }
  }
  double n = static_cast<double>(judged) * static_cast<double>(state.iterations());
  state.counters["mutants"] = static_cast<double>(judged);
  state.counters["mutants_per_s_jobs1"] = n / seconds[1];
  state.counters["mutants_per_s_jobs2"] = n / seconds[2];
  state.counters["speedup_jobs2"] = seconds[1] / seconds[2];
}
BENCHMARK(BM_mutate_stamping_jobs)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
