// YAML loader of the stamping plant parameters: strict (unknown keys, wrong types and
// implausible values are errors) so that a typo never silently falls back to a default.
#include "plant_model/stamping/stamping_params.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <string_view>

#include <yaml-cpp/yaml.h>

namespace plcfi::plant {

namespace {

// Upper bound of any time: keeps the conversion to int64 nanoseconds far from overflow.
constexpr double kMaxTime = 1e9;
constexpr double kMaxPressure = 10000.0;

// Thrown inside the loader, turned into "FILE:LINE:COL: message" at the top.
struct ConfigError {
  YAML::Mark mark;
  std::string message;
};

[[noreturn]] void fail(const YAML::Node& node, const std::string& message) {
  throw ConfigError{node.Mark(), message};
}

std::string describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Null: return "nothing";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Scalar: return "'" + node.Scalar() + "'";
    default: return "an undefined value";
  }
}

// Checks that node is a map (an empty value counts as an empty map) whose keys are all
// known and unique. `section` prefixes key names in messages ("stamp.").
void check_map(const YAML::Node& node, const std::string& section, std::initializer_list<std::string_view> known) {
  if (node.IsNull()) return;
  if (!node.IsMap()) fail(node, (section.empty() ? std::string("the file") : section) + ": expected a map of keys, got " + describe(node));
  std::set<std::string> seen;
  for (const auto& kv : node) {
    const YAML::Node& key = kv.first;
    if (!key.IsScalar()) fail(key, "expected a key name, got " + describe(key));
    const std::string& name = key.Scalar();
    bool ok = false;
    for (auto k : known) ok = ok || k == name;
    if (!ok) {
      std::string list;
      for (auto k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      fail(key, "unknown key '" + section + (section.empty() ? "" : ".") + name + "' (known here: " + list + ")");
    }
    if (!seen.insert(name).second) fail(key, "duplicate key '" + section + (section.empty() ? "" : ".") + name + "'");
  }
}

double number(const YAML::Node& node, const std::string& key) {
  double v = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v) || !std::isfinite(v))
    fail(node, key + ": expected a number, got " + describe(node));
  return v;
}

double time_value(const YAML::Node& node, const std::string& key) {
  double v = number(node, key);
  if (v < 0.0) fail(node, key + ": a time must not be negative, got " + node.Scalar());
  if (v > kMaxTime) fail(node, key + ": time too large, got " + node.Scalar());
  return v;
}

double positive_time(const YAML::Node& node, const std::string& key) {
  double v = time_value(node, key);
  if (v <= 0.0) fail(node, key + ": must be greater than 0, got " + node.Scalar());
  return v;
}

bool boolean(const YAML::Node& node, const std::string& key) {
  bool v = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, v)) fail(node, key + ": expected true or false, got " + describe(node));
  return v;
}

std::string word(const YAML::Node& node, const std::string& key, std::initializer_list<std::string_view> allowed) {
  std::string list;
  for (auto a : allowed) list += (list.empty() ? "" : " or ") + std::string(a);
  if (!node.IsScalar()) fail(node, key + ": expected " + list + ", got " + describe(node));
  for (auto a : allowed)
    if (node.Scalar() == a) return node.Scalar();
  fail(node, key + ": expected " + list + ", got " + describe(node));
}

// A list of times; an empty value is an empty list.
std::vector<double> time_list(const YAML::Node& node, const std::string& key) {
  std::vector<double> out;
  if (node.IsNull()) return out;
  if (!node.IsSequence()) fail(node, key + ": expected a list of times, got " + describe(node));
  for (const auto& item : node) out.push_back(time_value(item, key + " entry"));
  return out;
}

TimeSpan span(const YAML::Node& node, const std::string& key) {
  TimeSpan s;
  if (!node["from"]) fail(node, key + ": missing 'from'");
  if (!node["to"]) fail(node, key + ": missing 'to'");
  s.from = time_value(node["from"], key + ".from");
  s.to = time_value(node["to"], key + ".to");
  if (s.to <= s.from) fail(node["to"], key + ": 'to' must be later than 'from'");
  return s;
}

// A node that is a list of maps; `check` validates each map's keys.
template <class F>
void each_map(const YAML::Node& node, const std::string& key, F&& f) {
  if (node.IsNull()) return;
  if (!node.IsSequence()) fail(node, key + ": expected a list, got " + describe(node));
  for (const auto& item : node) {
    if (!item.IsMap()) fail(item, key + " entry: expected a map, got " + describe(item));
    f(item);
  }
}

void read_root(const YAML::Node& root, StampingParams& p) {
  check_map(root, "", {"variation", "slider", "stamp", "pressure", "supply", "handover", "next", "operator"});
  if (root.IsNull()) return;

  if (const auto v = root["variation"]) {
    p.variation = number(v, "variation");
    // Beyond 50 % a "variation" is a different machine; also keeps travel times positive.
    if (p.variation < 0.0 || p.variation >= 0.5) fail(v, "variation: expected a fraction in [0, 0.5), got " + v.Scalar());
  }
  if (const auto s = root["slider"]) {
    check_map(s, "slider", {"travel"});
    if (const auto v = s["travel"]) p.slider_travel = positive_time(v, "slider.travel");
  }
  if (const auto s = root["stamp"]) {
    check_map(s, "stamp", {"travel", "min_pressure", "min_time", "max_time"});
    if (const auto v = s["travel"]) p.stamp_travel = positive_time(v, "stamp.travel");
    if (const auto v = s["min_pressure"]) {
      p.stamp_min_pressure = number(v, "stamp.min_pressure");
      if (p.stamp_min_pressure < 0.0 || p.stamp_min_pressure > kMaxPressure)
        fail(v, "stamp.min_pressure: expected 0..10000, got " + v.Scalar());
    }
    if (const auto v = s["min_time"]) p.stamp_min_time = time_value(v, "stamp.min_time");
    if (const auto v = s["max_time"]) p.stamp_max_time = time_value(v, "stamp.max_time");
    if (p.stamp_max_time < p.stamp_min_time) {
      YAML::Node at = s["max_time"] ? s["max_time"] : s["min_time"];
      fail(at, "stamp.max_time must not be less than stamp.min_time");
    }
  }
  if (const auto s = root["pressure"]) {
    check_map(s, "pressure", {"tau_rise", "tau_fall"});
    if (const auto v = s["tau_rise"]) p.pressure_tau_rise = positive_time(v, "pressure.tau_rise");
    if (const auto v = s["tau_fall"]) p.pressure_tau_fall = positive_time(v, "pressure.tau_fall");
  }
  if (const auto s = root["supply"]) {
    check_map(s, "supply", {"mode", "delay", "schedule"});
    if (const auto v = s["mode"]) p.supply_mode = word(v, "supply.mode", {"on_demand", "schedule"}) == "schedule" ? SupplyMode::Schedule : SupplyMode::OnDemand;
    if (const auto v = s["delay"]) p.supply_delay = time_value(v, "supply.delay");
    if (const auto v = s["schedule"]) {
      p.supply_schedule = time_list(v, "supply.schedule");
      // Deliveries under on_demand would be ignored: almost certainly a forgotten mode.
      if (p.supply_mode != SupplyMode::Schedule && !p.supply_schedule.empty())
        fail(v, "supply.schedule is only used with supply.mode: schedule");
    }
  }
  if (const auto s = root["handover"]) {
    check_map(s, "handover", {"delay"});
    if (const auto v = s["delay"]) p.handover_delay = time_value(v, "handover.delay");
  }
  if (const auto s = root["next"]) {
    check_map(s, "next", {"ready", "busy"});
    if (const auto v = s["ready"]) p.next_ready = boolean(v, "next.ready");
    if (const auto v = s["busy"]) {
      p.next_busy.clear();
      each_map(v, "next.busy", [&](const YAML::Node& item) {
        check_map(item, "next.busy", {"from", "to"});
        p.next_busy.push_back(span(item, "next.busy"));
      });
    }
  }
  if (const auto s = root["operator"]) {
    check_map(s, "operator", {"mode", "start_at", "press_time", "ack_at", "jog"});
    if (const auto v = s["mode"]) p.operator_mode = word(v, "operator.mode", {"auto", "manual"}) == "manual" ? OperatorMode::Manual : OperatorMode::Auto;
    if (const auto v = s["start_at"]) {
      p.operator_start = !v.IsNull();  // an empty value: nobody presses start
      if (p.operator_start) p.operator_start_at = time_value(v, "operator.start_at");
    }
    if (const auto v = s["press_time"]) p.operator_press_time = positive_time(v, "operator.press_time");
    if (const auto v = s["ack_at"]) p.operator_ack_at = time_list(v, "operator.ack_at");
    if (const auto v = s["jog"]) {
      p.operator_jogs.clear();
      each_map(v, "operator.jog", [&](const YAML::Node& item) {
        check_map(item, "operator.jog", {"button", "from", "to"});
        JogInterval j;
        if (!item["button"]) fail(item, "operator.jog: missing 'button'");
        j.button = word(item["button"], "operator.jog.button", {"slider", "stamp"}) == "stamp" ? JogButton::Stamp : JogButton::Slider;
        j.span = span(item, "operator.jog");
        p.operator_jogs.push_back(j);
      });
    }
  }
}

std::string located(const std::string& path, const YAML::Mark& mark, const std::string& message) {
  // yaml-cpp marks are 0-based; a node without position (null mark) still names the file.
  if (mark.line < 0) return path + ": " + message;
  return path + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1) + ": " + message;
}

}  // namespace

bool load_stamping_params(const std::string& path, StampingParams* params, std::string* err) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;  // a directory opens as a stream that reads nothing: not a config
  if (!in || std::filesystem::is_directory(path, ec)) {
    if (err) *err = path + ": cannot open";
    return false;
  }
  StampingParams p = *params;  // untouched on error
  try {
    YAML::Node root = YAML::Load(in);
    read_root(root, p);
  } catch (const ConfigError& e) {
    if (err) *err = located(path, e.mark, e.message);
    return false;
  } catch (const YAML::Exception& e) {
    if (err) *err = located(path, e.mark, e.msg);
    return false;
  }
  *params = std::move(p);
  return true;
}

}  // namespace plcfi::plant
