// bench_report.hpp: what the ST benchmark's parts (bench_st.cpp, bench_matiec.cpp) share:
// the reporter that keeps every run's CPU time for the summary tables printed after the
// run, and the entry points of the MATIEC comparison (bench_matiec.cpp).
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

namespace plcfi::bench {

// Console output as usual, and the per-iteration CPU time of every run (in ns) kept for
// the summary tables: the minimum over repetitions when --benchmark_repetitions is given.
class CollectingReporter : public benchmark::ConsoleReporter {
 public:
  explicit CollectingReporter(OutputOptions opts) : ConsoleReporter(opts) {}
  void ReportRuns(const std::vector<Run>& reports) override {
    ConsoleReporter::ReportRuns(reports);
    for (const auto& r : reports) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred || r.iterations == 0) continue;
      double ns = r.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(r.time_unit) * 1e9;
      auto& v = best_[r.run_name.function_name];
      v = v == 0 ? ns : std::min(v, ns);
      auto it = r.counters.find("lines");
      if (it != r.counters.end()) lines_[r.run_name.function_name] = it->second.value;
    }
  }
  // 0 when the benchmark did not run (filtered out, or it failed).
  double ns(const std::string& name) const {
    auto it = best_.find(name);
    return it == best_.end() ? 0.0 : it->second;
  }
  double lines(const std::string& name) const {
    auto it = lines_.find(name);
    return it == lines_.end() ? 0.0 : it->second;
  }

 private:
  std::map<std::string, double> best_, lines_;
};

// bench_matiec.cpp: the MATIEC kernels (tests/bench/matiec) and plcfi's nested_fbs and
// crc16. check_matiec() runs before anything is timed: the interpreter, the native tier
// and the hand-written C++ must each reproduce the recorded state after 1 and 1000 scans,
// or it exits with status 1 naming every variable that differs. print_matiec_table()
// prints the ratio table for the BM_matiec_* runs that ran.
void check_matiec();
void print_matiec_table(const CollectingReporter& rep);

}  // namespace plcfi::bench
