// Platform set-up of the scan thread, stop signals and the shared real-time scan loop.
#include "realtime.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>

#include <fcntl.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <fmt/format.h>

namespace plcfi::rt {

std::vector<std::string> realtime_setup(const RealtimeOptions& o) {
  std::vector<std::string> warnings;
  prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);
  // Keep the CPUs out of deep idle states while the run lasts (PM QoS): the request holds
  // while the file stays open, so it is opened once and never closed.
  static int dma_latency = -1;
  if (dma_latency < 0) {
    dma_latency = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    int32_t zero = 0;
    if (dma_latency >= 0 && ::write(dma_latency, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
      ::close(dma_latency);
      dma_latency = -1;
    }
  }
  if (o.lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    warnings.push_back(fmt::format("mlockall: {} (page faults may add latency)", std::strerror(errno)));
  if (o.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(o.cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0)
      warnings.push_back(fmt::format("CPU affinity {}: {}", o.cpu, std::strerror(errno)));
  }
  if (o.priority > 0) {
    sched_param sp{};
    sp.sched_priority = o.priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
      warnings.push_back(fmt::format("SCHED_FIFO priority {}: {}", o.priority, std::strerror(errno)));
  }
  return warnings;
}

namespace {

// Async-signal-safe: a handler only stores.
std::atomic<int> g_stop_signal{0};
void on_stop_signal(int s) { g_stop_signal.store(s); }

struct SavedHandlers {
  struct sigaction intr, term, pipe;
} g_saved;

}  // namespace

StopSignals::StopSignals() {
  g_stop_signal.store(0);
  struct sigaction sa{};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_saved.intr);
  sigaction(SIGTERM, &sa, &g_saved.term);
  struct sigaction ign{};
  ign.sa_handler = SIG_IGN;
  sigemptyset(&ign.sa_mask);
  sigaction(SIGPIPE, &ign, &g_saved.pipe);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &g_saved.intr, nullptr);
  sigaction(SIGTERM, &g_saved.term, nullptr);
  sigaction(SIGPIPE, &g_saved.pipe, nullptr);
}

bool StopSignals::requested() const { return g_stop_signal.load() != 0; }

std::string StopSignals::name() const {
  switch (g_stop_signal.load()) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "";
  }
}

ScanLoop::ScanLoop(Runtime& runtime, bool paced, const StopSignals* signals, std::function<std::string()> lost)
    : runtime_(runtime), paced_(paced), signals_(signals), lost_(std::move(lost)), pacer_(runtime.schedule().tick_ns()) {}

void ScanLoop::start() {
  if (paced_) pacer_.start();
}

LoopEnd ScanLoop::check_stop() {
  if (signals_ && signals_->requested()) {
    reason_ = signals_->name();
    return LoopEnd::Signal;
  }
  if (lost_) {
    std::string lost = lost_();
    if (!lost.empty()) {
      reason_ = "communication lost: " + lost;
      return LoopEnd::CommunicationLost;
    }
  }
  return LoopEnd::None;
}

ScanStatus ScanLoop::scan() {
  int64_t woke = 0;
  if (paced_) {
    // The scan clock follows the real one: cycles an overrun skipped pass unscanned.
    if (uint64_t missed = pacer_.wait_next()) runtime_.skip_ticks(missed);
    woke = RealTimePacer::monotonic_ns();
  }
  ScanStatus st = runtime_.scan();
  if (paced_) pacer_.record_exec(RealTimePacer::monotonic_ns() - woke);
  ++scans_;
  return st;
}

LoopEnd ScanLoop::run(uint64_t cycles, int64_t duration_ns) {
  const int64_t t0 = RealTimePacer::monotonic_ns();
  start();
  while (true) {
    if (LoopEnd e = check_stop(); e != LoopEnd::None) return e;
    if ((cycles && scans_ >= cycles) || (duration_ns && RealTimePacer::monotonic_ns() - t0 >= duration_ns)) {
      reason_ = "done";
      return LoopEnd::Done;
    }
    if (scan() == ScanStatus::Trapped) {
      reason_ = "trap: " + runtime_.stop_reason();
      return LoopEnd::Trapped;
    }
  }
}

std::vector<std::string> ScanLoop::figures() const {
  if (!paced_) return {};
  return {"wake latency   " + pacer_.wake_latency().summary(), "execution      " + pacer_.exec_time().summary(),
          fmt::format("overruns       {} of {} cycles of {:g} ms", pacer_.overruns(), pacer_.wake_latency().count(),
                      static_cast<double>(pacer_.period_ns()) / 1e6)};
}

}  // namespace plcfi::rt
