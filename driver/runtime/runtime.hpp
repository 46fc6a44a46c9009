// The scan cycle: backend read -> input overlay -> before-scan hooks -> the tasks due at
// this tick -> after-scan hooks -> output overlay -> backend write. Runs in virtual time
// (one base tick per scan) unless a real-time clock paces it from outside.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "backend.hpp"
#include "image.hpp"
#include "schedule.hpp"
#include "vm/vm.hpp"

namespace plcfi::rt {

class Runtime;

// Plug-in points of the scan (tracer, monitors, the fault-injection driver). Called from
// the scan thread; must not block.
class ScanHooks {
 public:
  virtual ~ScanHooks() = default;
  // After the inputs reached the program's image, before any task runs.
  virtual void before_scan(Runtime& rt) {}
  // After the tasks ran, before the outputs go through the output overlay.
  virtual void after_scan(Runtime& rt) {}
  // After the output overlay and the backend write (what reached the plant is final).
  virtual void end_of_scan(Runtime& rt) {}
};

enum class ScanStatus { Ok, Trapped, Stopped, IoError };

class Runtime {
 public:
  Runtime(const st::Application& app, Schedule schedule, IoBackend* backend);

  // Cold restart: every variable to its initial value, image cleared, clock to zero,
  // backend reset (a simulated plant goes back to its initial state) with this seed.
  void cold_restart(uint64_t seed);
  // Warm restart: like cold, but RETAIN variables keep their values.
  void warm_restart(uint64_t seed);

  // One base tick. After a trap the program stays stopped (outputs in the safe state)
  // until a restart; later scans only exchange I/O.
  ScanStatus scan();
  // Real time went through `n` base ticks without a scan (an overrun on the bench): the
  // clock and the task counter move on, as a PLC's do when a cycle overran, so timers
  // keep following the real clock and the plant.
  void skip_ticks(uint64_t n);

  void add_hooks(ScanHooks* h) { hooks_.push_back(h); }
  void remove_hooks(ScanHooks* h);

  Overlay& input_overlay() { return in_overlay_; }
  // Re-applies the input overlay within the current scan (a before-scan hook that just
  // injected a sensor fault wants the program to see it in this very scan).
  void reapply_input_overlay();
  Overlay& output_overlay() { return out_overlay_; }
  // Inputs as the backend delivered them / outputs as they reached the backend.
  const uint8_t* raw_inputs() const { return raw_in_.data(); }
  const uint8_t* delivered_outputs() const { return out_.data(); }
  uint8_t* raw_inputs_mut() { return raw_in_.data(); }

  st::Machine& machine() { return machine_; }
  const st::Application& app() const { return *app_; }
  const Schedule& schedule() const { return schedule_; }
  IoBackend* backend() const { return backend_; }
  int64_t now() const { return now_ns_; }
  uint64_t scan_count() const { return scans_; }
  bool stopped() const { return stopped_; }
  const std::string& stop_reason() const { return stop_reason_; }
  const st::Trap& trap() const { return machine_.trap(); }

  // Runs the tasks due in this scan on a copy of the program state and returns the branch
  // ids they took (Machine::taken() layout), then puts memory back as it was: the
  // control-flow path the scan is about to take. For before-scan hooks (the campaign
  // driver tells paths to a precondition apart with it); allocates nothing after the
  // first call. A trap in the probe is forgotten: the real scan will meet it again.
  const std::vector<uint64_t>& probe_branches();

  // All outputs to the safe state (zero: valves off, setpoints 0, except the configured
  // exceptions) and sent to the backend (IoBackend::write_final). False when it could not
  // be delivered (the backend's last_error() says why).
  bool write_safe_outputs();
  // Outputs whose safe value is not 0 (a brake released by TRUE, a slider kept out
  // under a lowered stamp). Applied after zeroing, in order.
  void set_safe_state(std::vector<std::pair<ImageRef, int64_t>> values) { safe_values_ = std::move(values); }
  // Stops the program (e.g. a watchdog of the caller); outputs go to the safe state.
  void stop(const std::string& reason);

  // Everything a later scan depends on: the program's memory, the clock and scan count,
  // both image layers, the overlays with their rules' state, a trap that stopped the
  // program. Saved and restored between scans (an FMU's fmi2GetFMUstate and
  // fmi2SetFMUstate); the backend's state is the caller's to keep.
  struct State {
    st::Machine::State machine;
    std::vector<uint8_t> raw_in, out;
    Overlay in_overlay, out_overlay;
    int64_t now_ns = 0;
    uint64_t scans = 0;
    bool stopped = false, trap_at_restart = false;
    std::string stop_reason;
  };
  State save_state() const;
  // The state must come from a runtime of the same application.
  void restore_state(const State& s);

 private:
  void restart(uint64_t seed, bool warm);
  // Runs the tasks due at the current tick; false when one trapped (the trap is in machine_).
  bool run_due_tasks(std::string* stop_reason);
  uint32_t in_extent() const;
  uint32_t out_extent() const;

  const st::Application* app_;
  Schedule schedule_;
  IoBackend* backend_;
  st::Machine machine_;
  std::vector<ScanHooks*> hooks_;
  Overlay in_overlay_, out_overlay_;
  std::vector<uint8_t> raw_in_, out_;
  std::vector<uint8_t> probe_mem_;
  std::vector<std::pair<ImageRef, int64_t>> safe_values_;
  void fill_safe(uint8_t* q);
  std::vector<uint64_t> probe_taken_;
  int64_t now_ns_ = 0;
  uint64_t scans_ = 0;
  bool stopped_ = false;
  bool trap_at_restart_ = false;  // FB_init or FB_exit trapped: the next scan says Trapped
  std::string stop_reason_;
};

}  // namespace plcfi::rt
