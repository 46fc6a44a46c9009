// Task schedule construction and duration parsing for command-line options.
#include "schedule.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numeric>

#include "syntax/source.hpp"

namespace plcfi::rt {

bool Schedule::from_configuration(const st::Application& app, std::string* err) {
  tasks_.clear();
  for (const auto& t : app.tasks) {
    if (t.programs.empty()) continue;
    tasks_.push_back(ScheduledTask{t.name, t.interval_ns, t.priority, t.programs});
  }
  if (tasks_.empty()) {
    *err = "the configuration has no task with a program";
    return false;
  }
  finish();
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
  tasks_.push_back(ScheduledTask{"cycle", cycle_ns, 0, match});
  finish();
  return true;
}

void Schedule::finish() {
  tick_ns_ = 0;
  for (const auto& t : tasks_) tick_ns_ = std::gcd(tick_ns_, t.interval_ns);
  std::stable_sort(tasks_.begin(), tasks_.end(), [](const auto& a, const auto& b) { return a.priority < b.priority; });
}

bool parse_duration(const std::string& text_in, int64_t* ns, std::string* err) {
  std::string text = st::canon(text_in);
  if (text.rfind("T#", 0) == 0) text = text.substr(2);
  else if (text.rfind("TIME#", 0) == 0) text = text.substr(5);
  if (text.empty()) {
    *err = "empty duration";
    return false;
  }
  int64_t total = 0;
  size_t i = 0;
  bool any = false;
  while (i < text.size()) {
    if (text[i] == '_') {
      ++i;
      continue;
    }
    size_t j = i;
    while (j < text.size() && (std::isdigit(static_cast<unsigned char>(text[j])) || text[j] == '.')) ++j;
    if (j == i) {
      *err = "'" + text_in + "' is not a duration (e.g. 10ms, 1s, 2m30s)";
      return false;
    }
    // strtod, not std::stod: "." or 400 digits are a bad duration, not an exception.
    std::string digits = text.substr(i, j - i);
    char* end = nullptr;
    double value = std::strtod(digits.c_str(), &end);
    if (end != digits.c_str() + digits.size() || !std::isfinite(value)) {
      *err = "'" + text_in + "' is not a duration (e.g. 10ms, 1s, 2m30s)";
      return false;
    }
    size_t k = j;
    while (k < text.size() && std::isalpha(static_cast<unsigned char>(text[k]))) ++k;
    std::string unit = text.substr(j, k - j);
    double mul = 0;
    if (unit == "D") mul = 86400e9;
    else if (unit == "H") mul = 3600e9;
    else if (unit == "M") mul = 60e9;
    else if (unit == "S") mul = 1e9;
    else if (unit == "MS") mul = 1e6;
    else if (unit == "US") mul = 1e3;
    else if (unit == "NS") mul = 1;
    else {
      *err = "'" + text_in + "': unknown unit '" + unit + "' (use d, h, m, s, ms, us, ns)";
      return false;
    }
    double v = value * mul;
    if (v > 9.2e18 || static_cast<double>(total) + v > 9.2e18) {
      *err = "'" + text_in + "' is too long";
      return false;
    }
    total += static_cast<int64_t>(v);
    any = true;
    i = k;
  }
  if (!any) {
    *err = "'" + text_in + "' is not a duration";
    return false;
  }
  *ns = total;
  return true;
}

}  // namespace plcfi::rt
