// The real-time edge of the runtime: the platform set-up of the scan thread, the stop
// signals, and the one paced scan loop that bench runs (`plcfi run --io`) and campaigns on
// real I/O share, so both end, pace and report the same way.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "clock.hpp"
#include "runtime.hpp"

namespace plcfi::rt {

struct RealtimeOptions {
  int priority = 0;  // SCHED_FIFO priority 1..99 (0: keep the normal scheduler)
  int cpu = -1;      // CPU affinity (-1: any CPU)
  bool lock_memory = true;
};

// Timer slack of 1 ns, PM QoS (no deep idle states while the process lives), mlockall,
// affinity and SCHED_FIFO for the calling thread. Call once, from the scan thread, before
// the loop. A step that fails is skipped and returned as a warning: a bench run without
// privileges still runs, with worse latency.
std::vector<std::string> realtime_setup(const RealtimeOptions& o);

// While an instance lives, SIGINT and SIGTERM request a stop instead of killing the
// process (so the safe state still goes out), and SIGPIPE is ignored (a peer that goes
// away is the backend's error to report). The previous dispositions come back when it is
// destroyed. One instance at a time, owned by the thread that runs the loop.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  bool requested() const;
  // "SIGINT", "SIGTERM", or "" before any.
  std::string name() const;
};

enum class LoopEnd { None, Done, Signal, Trapped, CommunicationLost };

// The scan loop on a real clock. Each step checks the ways out first (a stop signal, a
// lost device), then sleeps until the cycle's absolute deadline (when paced), scans and
// records how long the scan took; overruns are counted, never caught up.
class ScanLoop {
 public:
  // `signals` may be null (nothing can interrupt); `lost` returns "" while every device
  // answers, else the lost device's error; it may be empty (a simulated plant).
  ScanLoop(Runtime& runtime, bool paced, const StopSignals* signals, std::function<std::string()> lost = {});

  // Sets the first deadline one cycle from now.
  void start();
  // LoopEnd::None to go on, else why the loop must end now (end_reason() says it).
  LoopEnd check_stop();
  // One scan, paced when the loop is.
  ScanStatus scan();
  // check_stop + scan until `cycles` scans (0: no limit), `duration_ns` on the real clock
  // (0: no limit), a signal, a lost device, or a trap.
  LoopEnd run(uint64_t cycles, int64_t duration_ns);

  // "done", "SIGINT", "SIGTERM", "trap: ...", "communication lost: ...".
  const std::string& end_reason() const { return reason_; }
  uint64_t scans() const { return scans_; }
  bool paced() const { return paced_; }
  const RealTimePacer& pacer() const { return pacer_; }
  // "wake latency   min ... max ...", "execution      ...", "overruns       N of M cycles of X ms";
  // empty when not paced.
  std::vector<std::string> figures() const;

 private:
  Runtime& runtime_;
  bool paced_;
  const StopSignals* signals_;
  std::function<std::string()> lost_;
  RealTimePacer pacer_;
  uint64_t scans_ = 0;
  std::string reason_;
};

}  // namespace plcfi::rt
