// Scan cycle implementation.
#include "runtime.hpp"

#include <algorithm>
#include <cstring>

#include "engine.hpp"

namespace plcfi::rt {

Runtime::Runtime(const st::Application& app, Schedule schedule, IoBackend* backend)
    : app_(&app), schedule_(std::move(schedule)), backend_(backend), machine_(app) {
  raw_in_.assign(app.image_i.size, 0);
  out_.assign(app.image_q.size, 0);
}

uint32_t Runtime::in_extent() const {
  uint32_t e = std::max(app_->image_i.used, in_overlay_.extent());
  if (backend_) e = std::max(e, backend_->input_extent());
  return std::min(e, app_->image_i.size);
}

uint32_t Runtime::out_extent() const {
  uint32_t e = std::max(app_->image_q.used, out_overlay_.extent());
  if (backend_) e = std::max(e, backend_->output_extent());
  return std::min(e, app_->image_q.size);
}

void Runtime::restart(uint64_t seed, bool warm) {
  const bool ok = warm ? machine_.warm_restart() : machine_.cold_restart();
  std::fill(raw_in_.begin(), raw_in_.end(), 0);
  std::fill(out_.begin(), out_.end(), 0);
  now_ns_ = 0;
  scans_ = 0;
  stopped_ = false;
  stop_reason_.clear();
  // A trap in FB_init or FB_exit: the program does not start.
  trap_at_restart_ = !ok;
  if (!ok) {
    stopped_ = true;
    stop_reason_ = st::describe_trap(*app_, machine_.trap()) + " (in FB_init/FB_exit at the restart)";
  }
  machine_.set_now(0);
  if (backend_) backend_->reset(seed);
}

void Runtime::cold_restart(uint64_t seed) { restart(seed, false); }
void Runtime::warm_restart(uint64_t seed) { restart(seed, true); }

void Runtime::remove_hooks(ScanHooks* h) { hooks_.erase(std::remove(hooks_.begin(), hooks_.end(), h), hooks_.end()); }

void Runtime::reapply_input_overlay() {
  in_overlay_.apply(machine_.mem() + app_->image_i.addr, raw_in_.data(), in_extent(), now_ns_);
}

void Runtime::fill_safe(uint8_t* q) {
  std::memset(q, 0, app_->image_q.size);
  for (const auto& [ref, v] : safe_values_) ref.set(q, v);
}

bool Runtime::write_safe_outputs() {
  fill_safe(machine_.mem() + app_->image_q.addr);
  std::memcpy(out_.data(), machine_.mem() + app_->image_q.addr, out_.size());
  return !backend_ || backend_->write_final(out_.data(), now_ns_);
}

Runtime::State Runtime::save_state() const {
  return State{machine_.save_state(), raw_in_, out_, in_overlay_.copy(), out_overlay_.copy(),
               now_ns_, scans_, stopped_, trap_at_restart_, stop_reason_};
}

void Runtime::restore_state(const State& s) {
  machine_.restore_state(s.machine);
  machine_.set_now(s.now_ns);
  raw_in_ = s.raw_in;
  out_ = s.out;
  in_overlay_ = s.in_overlay.copy();
  out_overlay_ = s.out_overlay.copy();
  now_ns_ = s.now_ns;
  scans_ = s.scans;
  stopped_ = s.stopped;
  trap_at_restart_ = s.trap_at_restart;
  stop_reason_ = s.stop_reason;
}

void Runtime::stop(const std::string& reason) {
  stopped_ = true;
  stop_reason_ = reason;
  write_safe_outputs();
}

bool Runtime::run_due_tasks(std::string* stop_reason) {
  bool ok = true;
  schedule_.for_each_due(scans_, [&](const ScheduledTask& t) {
    schedule_.begin_task(machine_, t);
    for (size_t pi : t.programs) {
      if (!ok) return;
      const auto& inst = app_->programs[pi];
      if (!machine_.call(inst.pou->entry, inst.addr)) {
        ok = false;
        if (stop_reason) *stop_reason = st::describe_trap(*app_, machine_.trap()) + " (program " + inst.name + ")";
      }
    }
  });
  return ok;
}

const std::vector<uint64_t>& Runtime::probe_branches() {
  probe_mem_.assign(machine_.mem(), machine_.mem() + machine_.mem_size());
  machine_.clear_taken();
  if (!stopped_) run_due_tasks(nullptr);
  probe_taken_ = machine_.taken();
  std::memcpy(machine_.mem(), probe_mem_.data(), probe_mem_.size());
  machine_.clear_taken();
  return probe_taken_;
}

void Runtime::skip_ticks(uint64_t n) {
  scans_ += n;
  now_ns_ += static_cast<int64_t>(n) * schedule_.tick_ns();
}

ScanStatus Runtime::scan() {
  const int64_t tick = schedule_.tick_ns();
  ScanStatus status = ScanStatus::Ok;
  uint8_t* mem = machine_.mem();
  if (backend_ && !backend_->read(raw_in_.data(), now_ns_)) status = ScanStatus::IoError;
  in_overlay_.apply(mem + app_->image_i.addr, raw_in_.data(), in_extent(), now_ns_);
  machine_.set_now(now_ns_);
  machine_.clear_taken();
  for (ScanHooks* h : hooks_) h->before_scan(*this);
  if (!stopped_) {
    if (!run_due_tasks(&stop_reason_)) {
      stopped_ = true;
      status = ScanStatus::Trapped;
    }
  } else if (trap_at_restart_) {
    trap_at_restart_ = false;  // the first scan reports it, as it would a trap of its own
    status = ScanStatus::Trapped;
  } else if (status == ScanStatus::Ok) {
    status = ScanStatus::Stopped;
  }
  machine_.merge_coverage();
  for (ScanHooks* h : hooks_) h->after_scan(*this);
  if (stopped_) {
    // Stopped (a trap): the safe state goes out as it is; no actuator fault overrides it.
    fill_safe(mem + app_->image_q.addr);
    std::memcpy(out_.data(), mem + app_->image_q.addr, out_extent());
  } else {
    out_overlay_.apply(out_.data(), mem + app_->image_q.addr, out_extent(), now_ns_);
  }
  if (backend_ && !backend_->write(out_.data(), now_ns_, tick) && status == ScanStatus::Ok) status = ScanStatus::IoError;
  for (ScanHooks* h : hooks_) h->end_of_scan(*this);
  ++scans_;
  now_ns_ += tick;
  return status;
}

}  // namespace plcfi::rt
