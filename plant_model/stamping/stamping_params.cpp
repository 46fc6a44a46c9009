// YAML loader of the stamping plant parameters: strict (unknown keys, wrong types and
// implausible values are errors) so that a typo never silently falls back to a default.
#include "plant_model/stamping/stamping_params.hpp"

#include "common/yaml.hpp"

namespace plcfi::plant {

namespace {

using common::YamlDoc;

// Upper bound of any time: keeps the conversion to int64 nanoseconds far from overflow.
constexpr double kMaxTime = 1e9;
constexpr double kMaxPressure = 10000.0;

double time_value(const YamlDoc& doc, const YAML::Node& node, const std::string& key) {
  double v = doc.number(node, key);
  if (v < 0.0) doc.fail(node, key + ": a time must not be negative, got " + node.Scalar());
  if (v > kMaxTime) doc.fail(node, key + ": time too large, got " + node.Scalar());
  return v;
}

double positive_time(const YamlDoc& doc, const YAML::Node& node, const std::string& key) {
  double v = time_value(doc, node, key);
  if (v <= 0.0) doc.fail(node, key + ": must be greater than 0, got " + node.Scalar());
  return v;
}

// A list of times; an empty value is an empty list.
std::vector<double> time_list(const YamlDoc& doc, const YAML::Node& node, const std::string& key) {
  std::vector<double> out;
  if (node.IsNull()) return out;
  for (const auto& item : doc.list(node, key, true)) out.push_back(time_value(doc, item, key + " entry"));
  return out;
}

TimeSpan span(const YamlDoc& doc, const YAML::Node& node, const std::string& key) {
  TimeSpan s;
  s.from = time_value(doc, doc.required(node, "from", key), key + ".from");
  s.to = time_value(doc, doc.required(node, "to", key), key + ".to");
  if (s.to <= s.from) doc.fail(node["to"], key + ": 'to' must be later than 'from'");
  return s;
}

// A list of maps (an empty value: none); f reads each.
template <class F>
void each_map(const YamlDoc& doc, const YAML::Node& node, const std::string& key, F&& f) {
  if (node.IsNull()) return;
  for (const auto& item : doc.list(node, key, true)) {
    if (!item.IsMap()) doc.fail(item, key + " entry: expected a map, got " + YamlDoc::describe(item));
    f(item);
  }
}

void read_root(const YamlDoc& doc, StampingParams& p) {
  const YAML::Node& root = doc.root();
  doc.check_keys(root, {"variation", "slider", "stamp", "pressure", "supply", "handover", "next", "operator"},
                 "the plant parameters", true);
  if (root.IsNull()) return;

  if (const auto v = root["variation"]) {
    p.variation = doc.number(v, "variation");
    // Beyond 50 % a "variation" is a different machine; also keeps travel times positive.
    if (p.variation < 0.0 || p.variation >= 0.5) doc.fail(v, "variation: expected a fraction in [0, 0.5), got " + v.Scalar());
  }
  if (const auto s = root["slider"]) {
    doc.check_keys(s, {"travel"}, "slider", true);
    if (const auto v = s["travel"]) p.slider_travel = positive_time(doc, v, "slider.travel");
  }
  if (const auto s = root["stamp"]) {
    doc.check_keys(s, {"travel", "min_pressure", "min_time", "max_time"}, "stamp", true);
    if (const auto v = s["travel"]) p.stamp_travel = positive_time(doc, v, "stamp.travel");
    if (const auto v = s["min_pressure"]) {
      p.stamp_min_pressure = doc.number(v, "stamp.min_pressure");
      if (p.stamp_min_pressure < 0.0 || p.stamp_min_pressure > kMaxPressure)
        doc.fail(v, "stamp.min_pressure: expected 0..10000, got " + v.Scalar());
    }
    if (const auto v = s["min_time"]) p.stamp_min_time = time_value(doc, v, "stamp.min_time");
    if (const auto v = s["max_time"]) p.stamp_max_time = time_value(doc, v, "stamp.max_time");
    if (p.stamp_max_time < p.stamp_min_time) {
      YAML::Node at = s["max_time"] ? s["max_time"] : s["min_time"];
      doc.fail(at, "stamp.max_time must not be less than stamp.min_time");
    }
  }
  if (const auto s = root["pressure"]) {
    doc.check_keys(s, {"tau_rise", "tau_fall"}, "pressure", true);
    if (const auto v = s["tau_rise"]) p.pressure_tau_rise = positive_time(doc, v, "pressure.tau_rise");
    if (const auto v = s["tau_fall"]) p.pressure_tau_fall = positive_time(doc, v, "pressure.tau_fall");
  }
  if (const auto s = root["supply"]) {
    doc.check_keys(s, {"mode", "delay", "schedule"}, "supply", true);
    if (const auto v = s["mode"])
      p.supply_mode = doc.word(v, "supply.mode", {"on_demand", "schedule"}) == "schedule" ? SupplyMode::Schedule : SupplyMode::OnDemand;
    if (const auto v = s["delay"]) p.supply_delay = time_value(doc, v, "supply.delay");
    if (const auto v = s["schedule"]) {
      p.supply_schedule = time_list(doc, v, "supply.schedule");
      // Deliveries under on_demand would be ignored: almost certainly a forgotten mode.
      if (p.supply_mode != SupplyMode::Schedule && !p.supply_schedule.empty())
        doc.fail(v, "supply.schedule is only used with supply.mode: schedule");
    }
  }
  if (const auto s = root["handover"]) {
    doc.check_keys(s, {"delay"}, "handover", true);
    if (const auto v = s["delay"]) p.handover_delay = time_value(doc, v, "handover.delay");
  }
  if (const auto s = root["next"]) {
    doc.check_keys(s, {"ready", "busy"}, "next", true);
    if (const auto v = s["ready"]) p.next_ready = doc.boolean(v, "next.ready");
    if (const auto v = s["busy"]) {
      p.next_busy.clear();
      each_map(doc, v, "next.busy", [&](const YAML::Node& item) {
        doc.check_keys(item, {"from", "to"}, "next.busy");
        p.next_busy.push_back(span(doc, item, "next.busy"));
      });
    }
  }
  if (const auto s = root["operator"]) {
    doc.check_keys(s, {"mode", "start_at", "press_time", "ack_at", "jog"}, "operator", true);
    if (const auto v = s["mode"])
      p.operator_mode = doc.word(v, "operator.mode", {"auto", "manual"}) == "manual" ? OperatorMode::Manual : OperatorMode::Auto;
    if (const auto v = s["start_at"]) {
      p.operator_start = !v.IsNull();  // an empty value: nobody presses start
      if (p.operator_start) p.operator_start_at = time_value(doc, v, "operator.start_at");
    }
    if (const auto v = s["press_time"]) p.operator_press_time = positive_time(doc, v, "operator.press_time");
    if (const auto v = s["ack_at"]) p.operator_ack_at = time_list(doc, v, "operator.ack_at");
    if (const auto v = s["jog"]) {
      p.operator_jogs.clear();
      each_map(doc, v, "operator.jog", [&](const YAML::Node& item) {
        doc.check_keys(item, {"button", "from", "to"}, "operator.jog");
        JogInterval j;
        j.button = doc.word(doc.required(item, "button", "operator.jog"), "operator.jog.button", {"slider", "stamp"}) == "stamp"
                       ? JogButton::Stamp
                       : JogButton::Slider;
        j.span = span(doc, item, "operator.jog");
        p.operator_jogs.push_back(j);
      });
    }
  }
}

}  // namespace

bool load_stamping_params(const std::string& path, StampingParams* params, std::string* err) {
  StampingParams p = *params;  // untouched on error
  std::string e;
  if (!common::catch_input_error(&e, [&] { read_root(common::YamlDoc::open(path), p); })) {
    if (err) *err = e;
    return false;
  }
  *params = std::move(p);
  return true;
}

}  // namespace plcfi::plant
