// Task schedule construction, and the duration reading of command-line options.
#include "schedule.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

#include "common/duration.hpp"
#include "engine.hpp"
#include "syntax/source.hpp"

namespace plcfi::rt {

bool Schedule::from_configuration(const st::Application& app, std::string* err) {
  tasks_.clear();
  for (const auto& t : app.tasks) {
    if (t.programs.empty()) continue;
    tasks_.push_back(ScheduledTask{t.name, t.interval_ns, t.priority, t.programs, static_cast<uint8_t>(tasks_.size() + 1)});
  }
  if (tasks_.empty()) {
    *err = "the configuration has no task with a program";
    return false;
  }
  finish(app);
  return true;
}

bool Schedule::single_program(const st::Application& app, const std::string& program, int64_t cycle_ns, std::string* err) {
  tasks_.clear();
  if (cycle_ns <= 0) {
    *err = "the cycle time must be positive";
    return false;
  }
  std::vector<size_t> match;
  for (size_t i = 0; i < app.programs.size(); ++i)
    if (program.empty() || st::iequals(app.programs[i].name, program) || st::iequals(app.programs[i].pou->name, program))
      match.push_back(i);
  std::string names;
  for (size_t i = 0; i < app.programs.size() && i < 20; ++i) names += (names.empty() ? "" : ", ") + app.programs[i].name;
  if (app.programs.size() > 20) names += fmt::format(" and {} more", app.programs.size() - 20);
  if (match.empty()) {
    *err = program.empty() ? "no PROGRAM to run" : "no program '" + program + "'" + (names.empty() ? "" : " (programs: " + names + ")");
    return false;
  }
  if (match.size() > 1) {
    *err = "several programs (" + names + "): choose one with --program";
    return false;
  }
  tasks_.push_back(ScheduledTask{"cycle", cycle_ns, 0, match, 1});
  finish(app);
  return true;
}

void Schedule::finish(const st::Application& app) {
  tick_ns_ = 0;
  for (const auto& t : tasks_) tick_ns_ = std::gcd(tick_ns_, t.interval_ns);
  for (auto& t : tasks_) t.ticks = tick_ns_ > 0 ? static_cast<uint64_t>(t.interval_ns / tick_ns_) : 1;
  std::stable_sort(tasks_.begin(), tasks_.end(), [](const auto& a, const auto& b) { return a.priority < b.priority; });
  // TwinCAT's _TaskInfo (Tc2_System), where the program names it.
  task_info_.assign(tasks_.size(), std::nullopt);
  std::string err;
  if (!st::resolve(app, "_TaskInfo[1].CycleCount", &err)) return;
  for (size_t i = 0; i < tasks_.size(); ++i) {
    const std::string at = fmt::format("_TaskInfo[{}].", tasks_[i].index);
    auto slot = [&](const char* field) { return st::resolve(app, at + field, &err); };
    auto ct = slot("CycleTime"), pr = slot("Priority"), cc = slot("CycleCount"), fc = slot("FirstCycle"), tn = slot("TaskName");
    if (ct && pr && cc && fc && tn) task_info_[i] = TaskInfoSlots{*ct, *pr, *cc, *fc, *tn};
  }
}

void Schedule::begin_task(st::Machine& m, const ScheduledTask& t) const {
  m.set_task_index(t.index);
  const auto i = static_cast<size_t>(&t - tasks_.data());
  if (i >= task_info_.size() || !task_info_[i]) return;
  const TaskInfoSlots& s = *task_info_[i];
  const int64_t count = st::read_int(m, s.cycle_count);
  st::write_int(m, s.cycle_count, count + 1);
  st::write_bool(m, s.first_cycle, count == 0);
  if (count == 0) {  // after a restart: the task's settings
    std::string err;
    st::write_int(m, s.cycle_time, t.interval_ns / 100);
    st::write_int(m, s.priority, t.priority);
    st::write_text(m, s.task_name, "'" + t.name + "'", &err);
  }
}

bool parse_duration(const std::string& text, int64_t* ns, std::string* err) {
  int64_t v = 0;
  if (!common::parse_duration(text, &v, err)) return false;
  if (v < 0) {
    *err = "'" + text + "': a duration here must not be negative";
    return false;
  }
  *ns = v;
  return true;
}

bool Schedule::run_due(const st::Application& app, st::Machine& m, uint64_t n, std::string* trap) const {
  bool ok = true;
  for_each_due(n, [&](const ScheduledTask& t) {
    begin_task(m, t);
    for (size_t pi : t.programs) {
      if (!ok) return;
      const auto& inst = app.programs[pi];
      if (!m.call(inst.pou->entry, inst.addr)) {
        ok = false;
        *trap = st::describe_trap(app, m.trap()) + fmt::format(" (program {}, cycle {})", inst.name, n);
      }
    }
  });
  return ok;
}

}  // namespace plcfi::rt
