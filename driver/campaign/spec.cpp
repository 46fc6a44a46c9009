// The campaign specification's shared parts: locations, look-ups, the helpers of the
// per-format loaders (spec_campaign.cpp, spec_tsd.cpp, spec_fmea.cpp, spec_classes.cpp)
// and the cross-file reference checks.
#include "campaign/spec.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "campaign/spec_internal.hpp"

namespace plcfi::campaign {

std::string Loc::str() const {
  if (line == 0) return file;
  return fmt::format("{}:{}:{}", file, line, col);
}

const Lifeline* Tsd::find(const std::string& name) const {
  for (const auto& l : lifelines)
    if (l.name == name) return &l;
  return nullptr;
}

const FaultClass* FaultClasses::find(const std::string& id) const {
  for (const auto& c : classes)
    if (c.id == id) return &c;
  return nullptr;
}

const char* kind_name(LifelineKind k) {
  switch (k) {
    case LifelineKind::Sensor: return "sensor";
    case LifelineKind::Actuator: return "actuator";
    case LifelineKind::Analog: return "analog";
    case LifelineKind::Mode: return "mode";
    case LifelineKind::Interface: return "interface";
    case LifelineKind::Variable: return "variable";
  }
  return "?";
}

bool split_transition_ref(const std::string& ref, std::string* scenario, std::string* step, std::string* lifeline) {
  size_t a = ref.find('.');
  if (a == std::string::npos) return false;
  size_t b = ref.find('.', a + 1);
  if (b == std::string::npos || ref.find('.', b + 1) != std::string::npos) return false;
  *scenario = ref.substr(0, a);
  *step = ref.substr(a + 1, b - a - 1);
  *lifeline = ref.substr(b + 1);
  return !scenario->empty() && !step->empty() && !lifeline->empty();
}

namespace detail {

Loc loc_of(const common::YamlDoc& doc, const YAML::Node& n) { return Loc{doc.path(), doc.line(n), doc.col(n)}; }

monitor::FormulaSource formula(const common::YamlDoc& doc, const YAML::Node& n, const std::string& what) {
  monitor::FormulaSource f;
  f.text = doc.scalar(n, what + " (an ST expression)");
  f.line = doc.line(n);
  f.col = doc.text_col(n);  // quoted: the text starts after the quote
  return f;
}

bool valid_name(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

}  // namespace detail

bool check_references(const Campaign& c, std::string* err) {
  for (const auto& r : c.fmea.rows) {
    std::string sc, st, ll;
    if (!split_transition_ref(r.transition, &sc, &st, &ll)) {
      *err = r.transition_loc.str() + ": '" + r.transition + "' is not a TSD transition (write scenario.step.lifeline)";
      return false;
    }
    const Scenario* scenario = nullptr;
    for (const auto& s : c.tsd.scenarios)
      if (s.id == sc) scenario = &s;
    if (!scenario) {
      *err = r.transition_loc.str() + ": the TSD (" + c.tsd.path + ") has no scenario '" + sc + "'";
      return false;
    }
    const Step* step = nullptr;
    for (const auto& s : scenario->steps)
      if (s.id == st) step = &s;
    if (!step) {
      *err = r.transition_loc.str() + ": scenario '" + sc + "' has no step '" + st + "'";
      return false;
    }
    bool found = false;
    for (const auto& t : step->transitions) found = found || t.lifeline == ll;
    if (!found) {
      *err = r.transition_loc.str() + ": step '" + sc + "." + st + "' expects no transition of '" + ll + "'";
      return false;
    }
    if (!c.classes.find(r.fault_class)) {
      *err = r.class_loc.str() + ": fault class '" + r.fault_class + "' is not defined in " + c.classes.path;
      return false;
    }
  }
  return true;
}

}  // namespace plcfi::campaign
