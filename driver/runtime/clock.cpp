// Real-time pacing and latency statistics.
#include "clock.hpp"

#include <time.h>

#include <algorithm>
#include <cerrno>

#include <fmt/format.h>

namespace plcfi::rt {

LatencyStats::LatencyStats() : buckets_(kBuckets, 0) {}

void LatencyStats::add(int64_t ns) {
  if (ns < 0) ns = 0;
  ++count_;
  sum_ += ns;
  if (ns < min_) min_ = ns;
  if (ns > max_) max_ = ns;
  size_t b = static_cast<size_t>(ns / kBucketNs);
  if (b >= kBuckets) ++overflow_;
  else ++buckets_[b];
}

int64_t LatencyStats::percentile(double p) const {
  if (!count_) return 0;
  auto target = static_cast<uint64_t>(p * static_cast<double>(count_));
  if (target >= count_) target = count_ - 1;
  uint64_t seen = 0;
  for (size_t b = 0; b < kBuckets; ++b) {
    seen += buckets_[b];
    if (seen > target) return std::min(static_cast<int64_t>(b + 1) * kBucketNs, max_);
  }
  return max_;
}

namespace {
std::string us(double ns) { return fmt::format("{:.1f}us", ns / 1000.0); }
}  // namespace

std::string LatencyStats::summary() const {
  return fmt::format("min {} avg {} p99 {} max {}", us(static_cast<double>(min())), us(avg()),
                     us(static_cast<double>(percentile(0.99))), us(static_cast<double>(max())));
}

std::vector<std::pair<std::string, std::string>> RealTimePacer::properties() const {
  std::vector<std::pair<std::string, std::string>> p;
  auto us_text = [](double ns) { return fmt::format("{:.1f}", ns / 1000.0); };
  p.emplace_back("cycle_ms", fmt::format("{:g}", static_cast<double>(period_ns_) / 1e6));
  p.emplace_back("cycles", std::to_string(latency_.count()));
  p.emplace_back("overruns", std::to_string(overruns_));
  for (const auto& [name, s] : {std::pair<const char*, const LatencyStats*>{"wake_latency", &latency_}, {"execution", &exec_}}) {
    p.emplace_back(std::string(name) + "_min_us", us_text(static_cast<double>(s->min())));
    p.emplace_back(std::string(name) + "_avg_us", us_text(s->avg()));
    p.emplace_back(std::string(name) + "_p99_us", us_text(static_cast<double>(s->percentile(0.99))));
    p.emplace_back(std::string(name) + "_max_us", us_text(static_cast<double>(s->max())));
  }
  return p;
}

int64_t RealTimePacer::monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void RealTimePacer::start() { next_ = monotonic_ns() + period_ns_; }

uint64_t RealTimePacer::wait_next() {
  int64_t now = monotonic_ns();
  int64_t missed = 0;
  if (now > next_) {
    ++overruns_;
    // Skip the missed deadlines: the next one is the first in the future.
    missed = (now - next_) / period_ns_ + 1;
    next_ += missed * period_ns_;
  }
  timespec ts{static_cast<time_t>(next_ / 1'000'000'000), static_cast<long>(next_ % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
  latency_.add(monotonic_ns() - next_);
  next_ += period_ns_;
  return static_cast<uint64_t>(missed);
}

}  // namespace plcfi::rt
