// The fault classes of a campaign: per class the reaction time and the EDTL requirements
// (with {alarm}, {start}, {deadline}, {signal} placeholders), forbidden reactions, the
// recovery and the safety time the safety evidence measures reactions against.
#include <set>

#include "campaign/spec_internal.hpp"

namespace plcfi::campaign {

namespace detail {

void parse_classes(const common::YamlDoc& f, FaultClasses* out) {
  f.check_keys(f.root(), {"fault_classes"}, "a fault-class file");
  out->path = f.path();
  for (const auto& n : f.list(f.required(f.root(), "fault_classes", "a fault-class file"), "fault_classes")) {
    f.check_keys(n, {"id", "name", "text", "reaction_time", "max_duration", "safety_time", "requirements", "forbidden",
                  "recovery"},
                 "a fault class");
    FaultClass c;
    c.loc = loc_of(f, n);
    YAML::Node idn = f.required(n, "id", "a fault class");
    c.id = f.scalar(idn, "id");
    if (out->find(c.id)) f.fail(idn, "fault class '" + c.id + "' is defined twice");
    if (n["name"]) c.name = f.scalar(n["name"], "name");
    if (n["text"]) c.text = f.scalar(n["text"], "text");
    if (n["reaction_time"]) c.reaction_time_ns = f.duration(n["reaction_time"], "reaction_time");
    if (n["max_duration"]) c.max_duration_ns = f.duration(n["max_duration"], "max_duration", 1);
    if (n["safety_time"]) c.safety_time_ns = f.duration(n["safety_time"], "safety_time", 1);
    std::set<std::string> ids;
    for (const auto& rn : f.list(f.required(n, "requirements", "a fault class"), "requirements")) {
      f.check_keys(rn, {"id", "text", "trigger", "invariant", "final", "delay", "reaction", "release"}, "a class requirement");
      ClassRequirement r;
      YAML::Node rid = f.required(rn, "id", "a class requirement");
      r.id = f.scalar(rid, "id");
      if (!valid_name(r.id)) f.fail(rid, "requirement id '" + r.id + "' is not an identifier");
      if (!ids.insert(r.id).second) f.fail(rid, "requirement '" + r.id + "' is defined twice in class " + c.id);
      if (rn["text"]) r.text = f.scalar(rn["text"], "text");
      r.trigger.text = "{start}";
      r.invariant.text = "TRUE";
      r.final.text = "TRUE";
      r.delay.text = "PASSED({deadline})";
      r.reaction.text = "TRUE";
      r.release.text = "FALSE";
      std::pair<const char*, monitor::FormulaSource*> fs[] = {{"trigger", &r.trigger},   {"invariant", &r.invariant},
                                                               {"final", &r.final},       {"delay", &r.delay},
                                                               {"reaction", &r.reaction}, {"release", &r.release}};
      for (auto& [key, dst] : fs)
        if (rn[key]) *dst = formula(f, rn[key], key);
      c.requirements.push_back(r);
    }
    if (YAML::Node fb = n["forbidden"]) {
      for (const auto& x : f.list(fb, "forbidden (formulas)", true)) {
        Forbidden fo;
        if (x.IsMap()) {
          f.check_keys(x, {"formula", "text"}, "a forbidden reaction");
          fo.formula = formula(f, f.required(x, "formula", "a forbidden reaction"), "formula");
          if (x["text"]) fo.text = f.scalar(x["text"], "text");
        } else {
          fo.formula = formula(f, x, "a forbidden reaction");
        }
        c.forbidden.push_back(fo);
      }
    }
    if (YAML::Node rn = n["recovery"]) {
      f.check_keys(rn, {"acknowledge", "hold", "press", "within", "cleared"}, "a class's recovery");
      Recovery& rc = c.recovery;
      rc.enabled = true;
      rc.loc = loc_of(f, rn);
      rc.acknowledge = f.scalar(f.required(rn, "acknowledge", "a class's recovery"), "acknowledge");
      if (rn["hold"]) rc.hold_ns = f.duration(rn["hold"], "hold");
      if (rn["press"]) rc.press_ns = f.duration(rn["press"], "press", 1);
      if (rn["within"]) rc.within_ns = f.duration(rn["within"], "within", 1);
      if (YAML::Node cn = rn["cleared"])
        for (const auto& x : f.list(cn, "cleared (variables)", true)) rc.cleared.push_back(f.scalar(x, "cleared"));
    }
    out->classes.push_back(c);
  }
}

}  // namespace detail

bool load_fault_classes(const std::string& path, FaultClasses* out, std::string* err) {
  return common::catch_input_error(err, [&] { detail::parse_classes(common::YamlDoc::open(path), out); });
}

}  // namespace plcfi::campaign
