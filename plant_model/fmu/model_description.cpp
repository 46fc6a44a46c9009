// Reader of modelDescription.xml (FMI 2.0): strict where plcfi depends on a value (version,
// co-simulation, value references, types, causality), lenient about the rest (units,
// type definitions, log categories: read by other tools, not needed to step a plant).
#include "plant_model/fmu/model_description.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string_view>

#include <fmt/format.h>
#include <pugixml.hpp>

#include "common/yaml.hpp"

namespace plcfi::plant::fmu {

namespace {

// A bound far above any real model; keeps a generated or hostile file from costing
// minutes (each variable is checked against the others by name and reference).
constexpr size_t kMaxVariables = 100'000;

class Reader {
 public:
  Reader(const std::string& text, std::string where) : text_(text), where_(std::move(where)) {}

  // 1-based line and column of a byte offset (a UTF-8 continuation byte is no column).
  // Variables come in file order: the count goes on from the last offset asked for, so
  // positioning every variable of a large file stays linear.
  void line_col(ptrdiff_t offset, uint32_t* line, uint32_t* col) const {
    const size_t end = offset < 0 ? 0 : std::min(static_cast<size_t>(offset), text_.size());
    if (end < at_) at_ = 0, line_ = 1, col_ = 1;
    for (; at_ < end; ++at_) {
      if (text_[at_] == '\n') {
        ++line_;
        col_ = 1;
      } else if ((static_cast<unsigned char>(text_[at_]) & 0xC0) != 0x80) {
        ++col_;
      }
    }
    *line = line_;
    *col = col_;
  }
  [[noreturn]] void fail_at(ptrdiff_t offset, const std::string& message) const {
    uint32_t line = 0, col = 0;
    line_col(offset, &line, &col);
    throw common::InputError(fmt::format("{}:{}:{}: {}", where_, line, col, message));
  }
  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& message) const { fail_at(start_of(n), message); }
  // pugixml's offset of an element is its name: the element starts at the '<' before it.
  ptrdiff_t start_of(const pugi::xml_node& n) const {
    ptrdiff_t o = n.offset_debug();
    if (o > 0 && static_cast<size_t>(o) <= text_.size() && text_[static_cast<size_t>(o) - 1] == '<') --o;
    return o;
  }
  void position(const pugi::xml_node& n, uint32_t* line, uint32_t* col) const { line_col(start_of(n), line, col); }

  std::string required(const pugi::xml_node& n, const char* attr) const {
    pugi::xml_attribute a = n.attribute(attr);
    if (!a) fail(n, fmt::format("<{}> has no attribute '{}'", n.name(), attr));
    return a.value();
  }

  bool boolean(const pugi::xml_node& n, const char* attr, bool dflt) const {
    pugi::xml_attribute a = n.attribute(attr);
    if (!a) return dflt;
    std::string_view v = a.value();
    if (v == "true" || v == "1") return true;
    if (v == "false" || v == "0") return false;
    fail(n, fmt::format("<{}> attribute {}: expected true or false, got '{}'", n.name(), attr, v));
  }

  std::optional<double> number(const pugi::xml_node& n, const char* attr) const {
    pugi::xml_attribute a = n.attribute(attr);
    if (!a) return std::nullopt;
    return real_text(n, attr, a.value());
  }

  double real_text(const pugi::xml_node& n, const char* what, const std::string& v) const {
    char* end = nullptr;
    double d = std::strtod(v.c_str(), &end);
    if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d))
      fail(n, fmt::format("<{}> {}: expected a number, got '{}'", n.name(), what, v));
    return d;
  }

  const std::string& text() const { return text_; }

 private:
  const std::string& text_;
  std::string where_;
  mutable size_t at_ = 0;  // line_col's position: offset, line and column
  mutable uint32_t line_ = 1, col_ = 1;
};

// An enumerated attribute: one of `names` (with `dflt` when absent), else an error listing them.
template <class E, size_t N>
E parse_choice(const Reader& r, const pugi::xml_node& n, const char* attr, const char* dflt,
               const std::pair<const char*, E> (&names)[N]) {
  std::string_view v = n.attribute(attr) ? n.attribute(attr).value() : dflt;
  std::string list;
  for (size_t i = 0; i < N; ++i) {
    if (v == names[i].first) return names[i].second;
    list += std::string(i == 0 ? "" : i + 1 == N ? " or " : ", ") + names[i].first;
  }
  r.fail(n, fmt::format("ScalarVariable {}: expected {}, got '{}'", attr, list, v));
}

Causality parse_causality(const Reader& r, const pugi::xml_node& n) {
  static constexpr std::pair<const char*, Causality> kNames[] = {
      {"parameter", Causality::Parameter}, {"calculatedParameter", Causality::CalculatedParameter},
      {"input", Causality::Input},         {"output", Causality::Output},
      {"local", Causality::Local},         {"independent", Causality::Independent}};
  return parse_choice(r, n, "causality", "local", kNames);
}

Variability parse_variability(const Reader& r, const pugi::xml_node& n) {
  static constexpr std::pair<const char*, Variability> kNames[] = {
      {"constant", Variability::Constant}, {"fixed", Variability::Fixed},         {"tunable", Variability::Tunable},
      {"discrete", Variability::Discrete}, {"continuous", Variability::Continuous}};
  return parse_choice(r, n, "variability", "continuous", kNames);
}

void check_start(const Reader& r, const pugi::xml_node& n, const ScalarVariable& v) {
  if (!v.start) return;
  const std::string& s = *v.start;
  switch (v.type) {
    case VarType::Real:
      r.real_text(n, "start", s);
      break;
    case VarType::Integer:
    case VarType::Enumeration: {
      int64_t x = 0;
      auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), x);
      if (ec != std::errc() || p != s.data() + s.size() || x < INT32_MIN || x > INT32_MAX)
        r.fail(n, fmt::format("variable '{}': start: expected a 32-bit integer, got '{}'", v.name, s));
      break;
    }
    case VarType::Boolean:
      if (s != "true" && s != "false" && s != "1" && s != "0")
        r.fail(n, fmt::format("variable '{}': start: expected true or false, got '{}'", v.name, s));
      break;
    case VarType::String:
      break;
  }
}

}  // namespace

const char* type_name(VarType t) {
  switch (t) {
    case VarType::Real: return "Real";
    case VarType::Integer: return "Integer";
    case VarType::Boolean: return "Boolean";
    case VarType::String: return "String";
    case VarType::Enumeration: return "Enumeration";
  }
  return "?";
}

const char* causality_name(Causality c) {
  switch (c) {
    case Causality::Parameter: return "parameter";
    case Causality::CalculatedParameter: return "calculatedParameter";
    case Causality::Input: return "input";
    case Causality::Output: return "output";
    case Causality::Local: return "local";
    case Causality::Independent: return "independent";
  }
  return "?";
}

const ScalarVariable* ModelDescription::find(const std::string& name) const {
  for (const auto& v : variables)
    if (v.name == name) return &v;
  return nullptr;
}

ModelDescription parse_model_description(const std::string& text, const std::string& where) {
  Reader r(text, where);
  pugi::xml_document doc;
  pugi::xml_parse_result res = doc.load_buffer(text.data(), text.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!res) r.fail_at(res.offset, std::string("XML error: ") + res.description());

  pugi::xml_node root = doc.document_element();
  if (std::string_view(root.name()) != "fmiModelDescription")
    r.fail(root, fmt::format("expected the root element <fmiModelDescription>, got <{}>", root.name()));

  ModelDescription md;
  md.fmi_version = r.required(root, "fmiVersion");
  if (md.fmi_version.rfind("2.", 0) != 0 && md.fmi_version != "2") {
    const char* hint = md.fmi_version.rfind("1.", 0) == 0   ? " (FMI 1.0 is not supported: export the model as FMI 2.0)"
                       : md.fmi_version.rfind("3.", 0) == 0 ? " (FMI 3.0 is not supported yet: export the model as FMI 2.0)"
                                                            : "";
    r.fail(root, fmt::format("fmiVersion '{}': plcfi loads FMI 2.0 co-simulation FMUs{}", md.fmi_version, hint));
  }
  md.model_name = r.required(root, "modelName");
  md.guid = r.required(root, "guid");
  md.description = root.attribute("description").value();
  md.generation_tool = root.attribute("generationTool").value();

  pugi::xml_node cs = root.child("CoSimulation");
  if (!cs) {
    if (root.child("ModelExchange"))
      r.fail(root, "a Model Exchange FMU (no <CoSimulation> element): plcfi steps co-simulation FMUs, which bring "
                   "their own solver; export the model for co-simulation");
    r.fail(root, "no <CoSimulation> element: not a co-simulation FMU");
  }
  md.model_identifier = r.required(cs, "modelIdentifier");
  // The identifier names the shared library: a path in it would leave the archive.
  if (md.model_identifier.empty() ||
      md.model_identifier.find_first_of("/\\") != std::string::npos || md.model_identifier == "." ||
      md.model_identifier == "..")
    r.fail(cs, fmt::format("modelIdentifier '{}' is not a valid file name", md.model_identifier));
  md.can_handle_variable_step = r.boolean(cs, "canHandleVariableCommunicationStepSize", false);
  md.can_interpolate_inputs = r.boolean(cs, "canInterpolateInputs", false);
  md.needs_execution_tool = r.boolean(cs, "needsExecutionTool", false);

  if (pugi::xml_node de = root.child("DefaultExperiment")) {
    md.default_start = r.number(de, "startTime");
    md.default_stop = r.number(de, "stopTime");
    md.default_step = r.number(de, "stepSize");
    if (md.default_step && *md.default_step <= 0.0) r.fail(de, "DefaultExperiment stepSize must be greater than 0");
  }

  pugi::xml_node vars = root.child("ModelVariables");
  if (!vars) r.fail(root, "no <ModelVariables> element");
  std::map<std::string, size_t> by_name;
  for (pugi::xml_node sv = vars.child("ScalarVariable"); sv; sv = sv.next_sibling("ScalarVariable")) {
    if (md.variables.size() >= kMaxVariables) r.fail(sv, fmt::format("more than {} variables", kMaxVariables));
    ScalarVariable v;
    v.name = r.required(sv, "name");
    if (v.name.empty()) r.fail(sv, "a ScalarVariable with an empty name");
    const std::string ref = r.required(sv, "valueReference");
    uint32_t vr = 0;
    auto [p, ec] = std::from_chars(ref.data(), ref.data() + ref.size(), vr);
    if (ref.empty() || ec != std::errc() || p != ref.data() + ref.size())
      r.fail(sv, fmt::format("variable '{}': valueReference: expected an unsigned integer, got '{}'", v.name, ref));
    v.value_reference = vr;
    v.description = sv.attribute("description").value();
    v.causality = parse_causality(r, sv);
    v.variability = parse_variability(r, sv);
    r.position(sv, &v.line, &v.col);

    pugi::xml_node t = sv.first_child();
    while (t && t.type() != pugi::node_element) t = t.next_sibling();
    if (!t) r.fail(sv, fmt::format("variable '{}' has no type element (Real, Integer, Boolean, String)", v.name));
    std::string_view tn = t.name();
    if (tn == "Real") v.type = VarType::Real;
    else if (tn == "Integer") v.type = VarType::Integer;
    else if (tn == "Boolean") v.type = VarType::Boolean;
    else if (tn == "String") v.type = VarType::String;
    else if (tn == "Enumeration") v.type = VarType::Enumeration;
    else r.fail(t, fmt::format("variable '{}': unknown type element <{}>", v.name, tn));
    if (pugi::xml_attribute s = t.attribute("start")) v.start = s.value();
    check_start(r, t, v);

    if (!by_name.emplace(v.name, md.variables.size()).second)
      r.fail(sv, fmt::format("a second variable named '{}'", v.name));
    md.variables.push_back(std::move(v));
  }
  return md;
}

}  // namespace plcfi::plant::fmu
