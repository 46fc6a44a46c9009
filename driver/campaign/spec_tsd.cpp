// The timing sequence diagram (TSD) of a campaign: lifelines and the scenarios' steps with
// their preconditions and timed transitions.
#include <set>

#include "campaign/spec_internal.hpp"

namespace plcfi::campaign {

namespace detail {

namespace {

LifelineKind parse_kind(const common::YamlDoc& f, const YAML::Node& n) {
  const std::string k = f.word(n, "kind", {"sensor", "actuator", "analog", "mode", "interface", "variable"});
  if (k == "sensor") return LifelineKind::Sensor;
  if (k == "actuator") return LifelineKind::Actuator;
  if (k == "analog") return LifelineKind::Analog;
  if (k == "mode") return LifelineKind::Mode;
  if (k == "interface") return LifelineKind::Interface;
  return LifelineKind::Variable;
}

}  // namespace

void parse_tsd(const common::YamlDoc& f, Tsd* out) {
  f.check_keys(f.root(), {"lifelines", "scenarios"}, "a TSD");
  out->path = f.path();
  for (const auto& n : f.list(f.required(f.root(), "lifelines", "a TSD"), "lifelines")) {
    f.check_keys(n, {"name", "bind", "kind", "tolerance", "text"}, "a lifeline");
    Lifeline l;
    l.loc = loc_of(f, n);
    YAML::Node name = f.required(n, "name", "a lifeline");
    l.name = f.scalar(name, "name");
    if (!valid_name(l.name)) f.fail(name, "lifeline name '" + l.name + "' is not an identifier");
    if (out->find(l.name)) f.fail(name, "lifeline '" + l.name + "' is defined twice");
    YAML::Node bind = n["bind"];
    if (bind) {
      l.bind = f.scalar(bind, "bind");
      l.bind_loc = loc_of(f, bind);
    } else {
      l.bind = l.name;
      l.bind_loc = loc_of(f, name);
    }
    if (n["kind"]) l.kind = parse_kind(f, n["kind"]);
    if (n["tolerance"]) {
      l.tolerance = f.number(n["tolerance"], "tolerance");
      if (l.tolerance < 0) f.fail(n["tolerance"], "tolerance: must not be negative, got " + n["tolerance"].Scalar());
    }
    out->lifelines.push_back(l);
  }
  std::set<std::string> scenario_ids;
  for (const auto& sn : f.list(f.required(f.root(), "scenarios", "a TSD"), "scenarios")) {
    f.check_keys(sn, {"id", "text", "steps"}, "a scenario");
    Scenario s;
    s.loc = loc_of(f, sn);
    YAML::Node idn = f.required(sn, "id", "a scenario");
    s.id = f.scalar(idn, "id");
    if (!valid_name(s.id)) f.fail(idn, "scenario id '" + s.id + "' is not an identifier");
    if (!scenario_ids.insert(s.id).second) f.fail(idn, "scenario '" + s.id + "' is defined twice");
    if (sn["text"]) s.text = f.scalar(sn["text"], "text");
    std::set<std::string> step_ids;
    for (const auto& tn : f.list(f.required(sn, "steps", "a scenario"), "steps")) {
      f.check_keys(tn, {"id", "text", "precondition", "condition", "start", "transitions"}, "a step");
      Step st;
      st.loc = loc_of(f, tn);
      YAML::Node sid = f.required(tn, "id", "a step");
      st.id = f.scalar(sid, "id");
      if (!valid_name(st.id)) f.fail(sid, "step id '" + st.id + "' is not an identifier");
      if (!step_ids.insert(st.id).second) f.fail(sid, "step '" + st.id + "' is defined twice in scenario " + s.id);
      if (tn["text"]) st.text = f.scalar(tn["text"], "text");
      YAML::Node pre = f.required(tn, "precondition", "a step");
      if (!pre.IsMap() || pre.size() == 0)
        f.fail(pre, "precondition: expected a map of lifelines to their states, got " + common::YamlDoc::describe(pre));
      for (const auto& kv : pre) {
        LifelineState ls;
        ls.lifeline = kv.first.Scalar();
        ls.loc = loc_of(f, kv.first);
        if (!out->find(ls.lifeline)) f.fail(kv.first, "unknown lifeline '" + ls.lifeline + "'");
        ls.value = f.scalar(kv.second, "the state of " + ls.lifeline);
        st.pre.push_back(ls);
      }
      if (tn["condition"]) {
        auto c = formula(f, tn["condition"], "condition");
        st.condition = c.text;
        st.condition_loc = Loc{f.path(), c.line, c.col};
      }
      YAML::Node start = f.required(tn, "start", "a step");
      auto sf = formula(f, start, "start");
      st.start_loc = Loc{f.path(), sf.line, sf.col};
      if (sf.text != "previous") st.start = sf.text;
      for (const auto& xn : f.list(f.required(tn, "transitions", "a step"), "transitions")) {
        f.check_keys(xn, {"lifeline", "to", "max", "min", "tolerance"}, "a transition");
        Transition t;
        t.loc = loc_of(f, xn);
        YAML::Node ln = f.required(xn, "lifeline", "a transition");
        t.lifeline = f.scalar(ln, "lifeline");
        if (!out->find(t.lifeline)) f.fail(ln, "unknown lifeline '" + t.lifeline + "'");
        for (const auto& other : st.transitions)
          if (other.lifeline == t.lifeline) f.fail(ln, "lifeline '" + t.lifeline + "' has two transitions in step " + st.id);
        t.to = f.scalar(f.required(xn, "to", "a transition"), "to");
        YAML::Node mx = f.required(xn, "max", "a transition");
        t.max_ns = f.duration(mx, "max", 1);
        if (xn["min"]) {
          t.min_ns = f.duration(xn["min"], "min");
          if (t.min_ns > t.max_ns) f.fail(xn["min"], "min is above max");
        }
        if (xn["tolerance"]) {
          t.tolerance = f.number(xn["tolerance"], "tolerance");
          if (t.tolerance < 0) f.fail(xn["tolerance"], "tolerance: must not be negative, got " + xn["tolerance"].Scalar());
        }
        st.transitions.push_back(t);
      }
      s.steps.push_back(st);
    }
    out->scenarios.push_back(s);
  }
}

}  // namespace detail

bool load_tsd(const std::string& path, Tsd* out, std::string* err) {
  return common::catch_input_error(err, [&] { detail::parse_tsd(common::YamlDoc::open(path), out); });
}

}  // namespace plcfi::campaign
