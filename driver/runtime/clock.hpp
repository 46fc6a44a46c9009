// Real-time pacing of the scan: absolute-deadline sleeps on CLOCK_MONOTONIC, overruns
// counted without catch-up bursts, and per-cycle wake latency / execution statistics.
// (Virtual time needs no clock object: the runtime advances one base tick per scan.)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace plcfi::rt {

// Fixed-size histogram with 1 us buckets up to 100 ms: percentiles without allocation.
class LatencyStats {
 public:
  LatencyStats();
  void add(int64_t ns);
  uint64_t count() const { return count_; }
  int64_t min() const { return count_ ? min_ : 0; }
  int64_t max() const { return max_; }
  double avg() const { return count_ ? static_cast<double>(sum_) / static_cast<double>(count_) : 0; }
  int64_t percentile(double p) const;  // upper edge of the bucket holding the p-quantile
  std::string summary() const;         // "min 3us avg 5.2us p99 12us max 40us"

 private:
  static constexpr int64_t kBucketNs = 1000;
  static constexpr size_t kBuckets = 100'000;
  std::vector<uint32_t> buckets_;
  uint64_t count_ = 0, overflow_ = 0;
  int64_t min_ = INT64_MAX, max_ = 0;
  int64_t sum_ = 0;
};

class RealTimePacer {
 public:
  explicit RealTimePacer(int64_t period_ns) : period_ns_(period_ns) {}
  // Sets the first deadline one period from now.
  void start();
  // Sleeps until the next deadline (absolute). If the deadline has already passed the
  // cycle overran: it is counted and the next deadline is the first one in the future,
  // so a late cycle is never followed by a burst of catch-up cycles. Returns how many
  // deadlines were skipped (0 on time): cycles that real time went through unscanned.
  uint64_t wait_next();
  // The caller reports how long the scan took after waking.
  void record_exec(int64_t ns) { exec_.add(ns); }
  static int64_t monotonic_ns();

  const LatencyStats& wake_latency() const { return latency_; }
  const LatencyStats& exec_time() const { return exec_; }
  uint64_t overruns() const { return overruns_; }
  int64_t period_ns() const { return period_ns_; }
  // The figures as name/value pairs (JUnit properties): cycle_ms, cycles, overruns,
  // wake_latency_{min,avg,p99,max}_us, execution_{min,avg,p99,max}_us.
  std::vector<std::pair<std::string, std::string>> properties() const;

 private:
  int64_t period_ns_;
  int64_t next_ = 0;
  uint64_t overruns_ = 0;
  LatencyStats latency_, exec_;
};

}  // namespace plcfi::rt
