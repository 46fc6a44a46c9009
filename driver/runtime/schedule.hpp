// Cyclic task schedule: which program instances run at which base tick. From the
// CONFIGURATION's tasks (base tick = greatest common divisor of the intervals, higher
// priority = lower PRIORITY number first) or from one program and a cycle time.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine.hpp"
#include "vm/program.hpp"
#include "vm/vm.hpp"

namespace plcfi::rt {

struct ScheduledTask {
  std::string name;
  int64_t interval_ns = 0;
  int64_t priority = 0;
  std::vector<size_t> programs;  // indices into Application::programs
  uint8_t index = 1;  // 1-based, in the configuration's order (GETCURTASKINDEX)
  uint64_t ticks = 1;  // interval_ns in base ticks (set by the schedule)
};

class Schedule {
 public:
  // From the application's configuration. Fails (returns false, err) without tasks.
  bool from_configuration(const st::Application& app, std::string* err);
  // One program instance (by instance or type name) every cycle_ns.
  bool single_program(const st::Application& app, const std::string& program, int64_t cycle_ns, std::string* err);

  int64_t tick_ns() const { return tick_ns_; }
  const std::vector<ScheduledTask>& tasks() const { return tasks_; }
  // Tasks due at base tick n (n = 0 is the first scan), in priority order.
  template <class F>
  void for_each_due(uint64_t n, F&& f) const {
    // (Every scan of a run asks: the period in ticks is worked out once, and a task on
    // the base tick needs no division.)
    for (const auto& t : tasks_)
      if (t.ticks == 1 || n % t.ticks == 0) f(t);
  }
  // Calls the programs of the tasks due at base tick n on m, in order, until one traps:
  // then false, with *trap describing it ("... (program Main, cycle 12)").
  bool run_due(const st::Application& app, st::Machine& m, uint64_t n, std::string* trap) const;
  // Before a task's programs run: the task index GETCURTASKINDEX gives, and, where the
  // program uses TwinCAT's _TaskInfo, its entry for the task: CycleTime (100 ns units),
  // Priority, TaskName, CycleCount (this cycle's number, from 1 after every restart) and
  // FirstCycle (TRUE in the first). LastExecTime stays 0: the scan takes no time in
  // virtual time, and real-time runs measure it elsewhere.
  void begin_task(st::Machine& m, const ScheduledTask& t) const;

 private:
  void finish(const st::Application& app);
  int64_t tick_ns_ = 0;
  std::vector<ScheduledTask> tasks_;
  struct TaskInfoSlots {
    st::VarHandle cycle_time, priority, cycle_count, first_cycle, task_name;
  };
  std::vector<std::optional<TaskInfoSlots>> task_info_;  // per task, where _TaskInfo holds it
};

// Parses "10ms", "1s", "500us", "2m", "1h30m", "T#10ms" into nanoseconds with the one
// duration parser (common/duration.hpp); a negative value is an error here, as no option
// or spec value takes one. *err: "'TEXT' is not a duration: DETAIL".
bool parse_duration(const std::string& text, int64_t* ns, std::string* err);

}  // namespace plcfi::rt
