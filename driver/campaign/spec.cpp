// Loading and validation of campaign, TSD, FMEA and fault-class files.
#include "spec.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "runtime/schedule.hpp"

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

namespace {

// Loader errors unwind to the public entry points, which turn them into messages.
struct SpecError {
  std::string message;
};

struct YamlFile {
  std::string path;
  YAML::Node root;

  Loc loc(const YAML::Node& n) const {
    return Loc{path, static_cast<uint32_t>(n.Mark().line + 1), static_cast<uint32_t>(n.Mark().column + 1)};
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& msg) const { throw SpecError{loc(n).str() + ": " + msg}; }

  std::string scalar(const YAML::Node& n, const std::string& what) const {
    if (!n.IsScalar()) fail(n, what + " must be a single value");
    return n.Scalar();
  }
  int64_t duration(const YAML::Node& n, const std::string& what) const {
    std::string e;
    int64_t ns = 0;
    if (!rt::parse_duration(scalar(n, what), &ns, &e)) fail(n, what + ": " + e);
    if (ns < 0) fail(n, what + " must not be negative");
    return ns;
  }
  double number(const YAML::Node& n, const std::string& what) const {
    std::string s = scalar(n, what);
    try {
      size_t used = 0;
      double v = std::stod(s, &used);
      if (used != s.size()) throw std::invalid_argument(s);
      return v;
    } catch (const std::exception&) {
      fail(n, what + ": '" + s + "' is not a number");
    }
  }
  int64_t integer(const YAML::Node& n, const std::string& what) const {
    std::string s = scalar(n, what);
    try {
      size_t used = 0;
      long long v = std::stoll(s, &used);
      if (used != s.size()) throw std::invalid_argument(s);
      return v;
    } catch (const std::exception&) {
      fail(n, what + ": '" + s + "' is not an integer");
    }
  }
  monitor::FormulaSource formula(const YAML::Node& n, const std::string& what) const {
    monitor::FormulaSource f;
    f.text = scalar(n, what + " (an ST expression)");
    f.line = static_cast<uint32_t>(n.Mark().line + 1);
    f.col = static_cast<uint32_t>(n.Mark().column + 1);
    if (n.Tag() == "!") f.col += 1;  // quoted: the text starts after the quote
    return f;
  }
  // Rejects keys outside `allowed` (a misspelt key would otherwise be ignored silently).
  void keys(const YAML::Node& map, std::initializer_list<const char*> allowed, const std::string& what) const {
    if (!map.IsMap()) fail(map, what + " must be a map");
    for (const auto& kv : map) {
      std::string k = kv.first.Scalar();
      bool ok = false;
      for (const char* a : allowed) ok = ok || k == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(kv.first, fmt::format("unknown key '{}' in {} (expected one of: {})", k, what, list));
      }
    }
  }
  YAML::Node required(const YAML::Node& map, const char* key, const std::string& what) const {
    YAML::Node n = map[key];
    if (!n) fail(map, fmt::format("{} lacks '{}'", what, key));
    return n;
  }
};

YamlFile open_yaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SpecError{path + ": cannot open"};
  YamlFile f;
  f.path = path;
  try {
    f.root = YAML::Load(in);
  } catch (const YAML::Exception& e) {
    throw SpecError{fmt::format("{}:{}:{}: {}", path, e.mark.line + 1, e.mark.column + 1, e.msg)};
  }
  if (!f.root.IsMap()) throw SpecError{path + ":1:1: expected a map at the top level"};
  return f;
}

bool valid_name(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

LifelineKind parse_kind(const YamlFile& f, const YAML::Node& n) {
  std::string k = f.scalar(n, "kind");
  if (k == "sensor") return LifelineKind::Sensor;
  if (k == "actuator") return LifelineKind::Actuator;
  if (k == "analog") return LifelineKind::Analog;
  if (k == "mode") return LifelineKind::Mode;
  if (k == "interface") return LifelineKind::Interface;
  if (k == "variable") return LifelineKind::Variable;
  f.fail(n, "kind '" + k + "' is not one of sensor, actuator, analog, mode, interface, variable");
}

void parse_tsd(const YamlFile& f, Tsd* out) {
  f.keys(f.root, {"lifelines", "scenarios"}, "a TSD");
  out->path = f.path;
  YAML::Node ll = f.required(f.root, "lifelines", "the TSD");
  if (!ll.IsSequence() || ll.size() == 0) f.fail(ll, "'lifelines' must be a non-empty list");
  for (const auto& n : ll) {
    f.keys(n, {"name", "bind", "kind", "tolerance", "text"}, "a lifeline");
    Lifeline l;
    l.loc = f.loc(n);
    YAML::Node name = f.required(n, "name", "a lifeline");
    l.name = f.scalar(name, "name");
    if (!valid_name(l.name)) f.fail(name, "lifeline name '" + l.name + "' is not an identifier");
    if (out->find(l.name)) f.fail(name, "lifeline '" + l.name + "' is defined twice");
    YAML::Node bind = n["bind"];
    if (bind) {
      l.bind = f.scalar(bind, "bind");
      l.bind_loc = f.loc(bind);
    } else {
      l.bind = l.name;
      l.bind_loc = f.loc(name);
    }
    if (n["kind"]) l.kind = parse_kind(f, n["kind"]);
    if (n["tolerance"]) {
      l.tolerance = f.number(n["tolerance"], "tolerance");
      if (l.tolerance < 0) f.fail(n["tolerance"], "tolerance must not be negative");
    }
    out->lifelines.push_back(l);
  }
  YAML::Node sc = f.required(f.root, "scenarios", "the TSD");
  if (!sc.IsSequence() || sc.size() == 0) f.fail(sc, "'scenarios' must be a non-empty list");
  std::set<std::string> scenario_ids;
  for (const auto& sn : sc) {
    f.keys(sn, {"id", "text", "steps"}, "a scenario");
    Scenario s;
    s.loc = f.loc(sn);
    YAML::Node idn = f.required(sn, "id", "a scenario");
    s.id = f.scalar(idn, "id");
    if (!valid_name(s.id)) f.fail(idn, "scenario id '" + s.id + "' is not an identifier");
    if (!scenario_ids.insert(s.id).second) f.fail(idn, "scenario '" + s.id + "' is defined twice");
    if (sn["text"]) s.text = f.scalar(sn["text"], "text");
    YAML::Node steps = f.required(sn, "steps", "a scenario");
    if (!steps.IsSequence() || steps.size() == 0) f.fail(steps, "'steps' must be a non-empty list");
    std::set<std::string> step_ids;
    for (const auto& tn : steps) {
      f.keys(tn, {"id", "text", "precondition", "condition", "start", "transitions"}, "a step");
      Step st;
      st.loc = f.loc(tn);
      YAML::Node sid = f.required(tn, "id", "a step");
      st.id = f.scalar(sid, "id");
      if (!valid_name(st.id)) f.fail(sid, "step id '" + st.id + "' is not an identifier");
      if (!step_ids.insert(st.id).second) f.fail(sid, "step '" + st.id + "' is defined twice in scenario " + s.id);
      if (tn["text"]) st.text = f.scalar(tn["text"], "text");
      YAML::Node pre = f.required(tn, "precondition", "a step");
      if (!pre.IsMap() || pre.size() == 0) f.fail(pre, "'precondition' must map lifelines to their states");
      for (const auto& kv : pre) {
        LifelineState ls;
        ls.lifeline = kv.first.Scalar();
        ls.loc = f.loc(kv.first);
        if (!out->find(ls.lifeline)) f.fail(kv.first, "unknown lifeline '" + ls.lifeline + "'");
        ls.value = f.scalar(kv.second, "the state of " + ls.lifeline);
        st.pre.push_back(ls);
      }
      if (tn["condition"]) {
        auto c = f.formula(tn["condition"], "condition");
        st.condition = c.text;
        st.condition_loc = Loc{f.path, c.line, c.col};
      }
      YAML::Node start = f.required(tn, "start", "a step");
      auto sf = f.formula(start, "start");
      st.start_loc = Loc{f.path, sf.line, sf.col};
      if (sf.text != "previous") st.start = sf.text;
      YAML::Node tr = f.required(tn, "transitions", "a step");
      if (!tr.IsSequence() || tr.size() == 0) f.fail(tr, "'transitions' must be a non-empty list");
      for (const auto& xn : tr) {
        f.keys(xn, {"lifeline", "to", "max", "min", "tolerance"}, "a transition");
        Transition t;
        t.loc = f.loc(xn);
        YAML::Node ln = f.required(xn, "lifeline", "a transition");
        t.lifeline = f.scalar(ln, "lifeline");
        if (!out->find(t.lifeline)) f.fail(ln, "unknown lifeline '" + t.lifeline + "'");
        for (const auto& other : st.transitions)
          if (other.lifeline == t.lifeline) f.fail(ln, "lifeline '" + t.lifeline + "' has two transitions in step " + st.id);
        t.to = f.scalar(f.required(xn, "to", "a transition"), "to");
        YAML::Node mx = f.required(xn, "max", "a transition");
        t.max_ns = f.duration(mx, "max");
        if (t.max_ns == 0) f.fail(mx, "max must be positive");
        if (xn["min"]) {
          t.min_ns = f.duration(xn["min"], "min");
          if (t.min_ns > t.max_ns) f.fail(xn["min"], "min is above max");
        }
        if (xn["tolerance"]) {
          t.tolerance = f.number(xn["tolerance"], "tolerance");
          if (t.tolerance < 0) f.fail(xn["tolerance"], "tolerance must not be negative");
        }
        st.transitions.push_back(t);
      }
      s.steps.push_back(st);
    }
    out->scenarios.push_back(s);
  }
}

// ------------------------------------------------------------------ FMEA (CSV)

// RFC 4180 fields of one record; `line` advances over quoted line breaks. cols[i] is the
// 1-based column where field i starts.
bool read_record(std::istream& in, char sep, std::vector<std::string>* fields, std::vector<uint32_t>* cols, uint32_t* line,
                 std::string* err, const std::string& path) {
  fields->clear();
  cols->clear();
  std::string text;
  if (!std::getline(in, text)) return false;
  if (!text.empty() && text.back() == '\r') text.pop_back();
  std::string cur;
  bool quoted = false, was_quoted = false;
  uint32_t col = 1, start_col = 1;
  size_t i = 0;
  uint32_t start_line = *line;
  while (true) {
    if (i >= text.size()) {
      if (quoted) {
        std::string more;
        if (!std::getline(in, more)) {
          *err = fmt::format("{}:{}:{}: unterminated quoted field", path, start_line, start_col);
          return false;
        }
        if (!more.empty() && more.back() == '\r') more.pop_back();
        ++*line;
        cur += '\n';
        text = more;
        i = 0;
        col = 1;
        continue;
      }
      break;
    }
    char c = text[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          cur += '"';
          i += 2;
          col += 2;
          continue;
        }
        quoted = false;
      } else {
        cur += c;
      }
    } else if (c == '"' && cur.empty() && !was_quoted) {
      quoted = was_quoted = true;
    } else if (c == sep) {
      fields->push_back(cur);
      cols->push_back(start_col);
      cur.clear();
      was_quoted = false;
      start_col = col + 1;
    } else {
      cur += c;
    }
    ++i;
    ++col;
  }
  fields->push_back(cur);
  cols->push_back(start_col);
  return true;
}

std::string trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

void parse_fmea(const std::string& path, Fmea* out) {
  std::ifstream in(path);
  if (!in) throw SpecError{path + ": cannot open"};
  out->path = path;
  std::string first;
  std::streampos begin = in.tellg();
  std::getline(in, first);
  in.seekg(begin);
  // Spreadsheets in locales with a decimal comma export with ';'.
  char sep = first.find(';') != std::string::npos && first.find(',') == std::string::npos ? ';' : ',';
  std::vector<std::string> header, fields;
  std::vector<uint32_t> cols;
  uint32_t line = 1;
  std::string err;
  if (!read_record(in, sep, &header, &cols, &line, &err, path)) throw SpecError{err.empty() ? path + ":1:1: empty file" : err};
  // Column names as a spreadsheet may spell them.
  struct Column {
    const char* key;
    std::vector<std::string> names;
    bool required;
  };
  const std::vector<Column> columns = {
      {"id", {"id", "no", "nr"}, false},
      {"transition", {"tsd_transition", "transition", "information from tsd", "tsd"}, true},
      {"failure_mode", {"failure_mode", "failure mode"}, false},
      {"s", {"s", "severity"}, true},
      {"effect", {"effect"}, false},
      {"cause", {"cause"}, false},
      {"o", {"o", "occurrence"}, true},
      {"detection", {"detection"}, false},
      {"d", {"d", "detectability"}, true},
      {"rpn", {"rpn"}, true},
      {"fault_class", {"fault_class", "fault class", "class"}, true},
      {"alarm", {"alarm", "alarm message", "message", "msg"}, true},
      {"fault_model", {"fault_model", "fault model", "fault"}, false},
  };
  std::vector<int> index(columns.size(), -1);
  for (size_t h = 0; h < header.size(); ++h) {
    std::string name = lower(trim(header[h]));
    if (name.empty()) continue;
    bool known = false;
    for (size_t c = 0; c < columns.size(); ++c)
      for (const auto& n : columns[c].names)
        if (n == name) {
          if (index[c] >= 0)
            throw SpecError{fmt::format("{}:1:{}: column '{}' appears twice", path, cols[h], header[h])};
          index[c] = static_cast<int>(h);
          known = true;
        }
    if (!known)
      throw SpecError{fmt::format("{}:1:{}: unknown column '{}' (expected id, tsd_transition, failure_mode, S, effect, cause, O, "
                                  "detection, D, RPN, fault_class, alarm, fault_model)",
                                  path, cols[h], header[h])};
  }
  for (size_t c = 0; c < columns.size(); ++c)
    if (columns[c].required && index[c] < 0)
      throw SpecError{fmt::format("{}:1:1: the header lacks the column '{}'", path, columns[c].names.front())};
  std::set<std::string> ids;
  while (true) {
    ++line;
    uint32_t row_line = line;
    if (!read_record(in, sep, &fields, &cols, &line, &err, path)) {
      if (!err.empty()) throw SpecError{err};
      break;
    }
    if (fields.size() == 1 && trim(fields[0]).empty()) continue;  // blank line
    if (fields.size() != header.size())
      throw SpecError{fmt::format("{}:{}:1: {} fields, the header has {}", path, row_line, fields.size(), header.size())};
    auto get = [&](size_t c) { return index[c] < 0 ? std::string() : trim(fields[static_cast<size_t>(index[c])]); };
    auto at = [&](size_t c) { return Loc{path, row_line, index[c] < 0 ? 1 : cols[static_cast<size_t>(index[c])]}; };
    auto rating = [&](size_t c, const char* what, int lo, int hi) {
      std::string v = get(c);
      int n = 0;
      size_t used = 0;
      try {
        n = std::stoi(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (v.empty() || used != v.size()) throw SpecError{at(c).str() + ": " + what + " '" + v + "' is not a whole number"};
      if (n < lo || n > hi) throw SpecError{fmt::format("{}: {} {} is outside {}..{}", at(c).str(), what, n, lo, hi)};
      return n;
    };
    FmeaRow r;
    r.line = row_line;
    r.id = get(0).empty() ? fmt::format("row{}", row_line) : get(0);
    if (!ids.insert(r.id).second) throw SpecError{at(0).str() + ": FMEA id '" + r.id + "' appears twice"};
    r.transition = get(1);
    r.transition_loc = at(1);
    r.failure_mode = get(2);
    r.s = rating(3, "S", 1, 10);
    r.effect = get(4);
    r.cause = get(5);
    r.o = rating(6, "O", 1, 10);
    r.detection = get(7);
    r.d = rating(8, "D", 1, 10);
    r.rpn = rating(9, "RPN", 1, 1000);
    if (r.rpn != r.s * r.o * r.d)
      throw SpecError{fmt::format("{}: RPN {} is not S x O x D = {} x {} x {} = {}", at(9).str(), r.rpn, r.s, r.o, r.d,
                                  r.s * r.o * r.d)};
    r.fault_class = get(10);
    r.class_loc = at(10);
    if (r.fault_class.empty()) throw SpecError{at(10).str() + ": the fault class is empty"};
    r.alarm = get(11);
    r.alarm_loc = at(11);
    if (r.alarm.empty()) throw SpecError{at(11).str() + ": the alarm variable is empty"};
    r.fault_model = get(12);
    r.fault_loc = at(12);
    out->rows.push_back(r);
  }
  if (out->rows.empty()) throw SpecError{path + ":2:1: the FMEA has no rows"};
}

// ------------------------------------------------------------------ fault classes

void parse_classes(const YamlFile& f, FaultClasses* out) {
  f.keys(f.root, {"fault_classes"}, "a fault-class file");
  out->path = f.path;
  YAML::Node list = f.required(f.root, "fault_classes", "the fault-class file");
  if (!list.IsSequence() || list.size() == 0) f.fail(list, "'fault_classes' must be a non-empty list");
  for (const auto& n : list) {
    f.keys(n, {"id", "name", "text", "reaction_time", "max_duration", "requirements", "forbidden"}, "a fault class");
    FaultClass c;
    c.loc = f.loc(n);
    YAML::Node idn = f.required(n, "id", "a fault class");
    c.id = f.scalar(idn, "id");
    if (out->find(c.id)) f.fail(idn, "fault class '" + c.id + "' is defined twice");
    if (n["name"]) c.name = f.scalar(n["name"], "name");
    if (n["text"]) c.text = f.scalar(n["text"], "text");
    if (n["reaction_time"]) c.reaction_time_ns = f.duration(n["reaction_time"], "reaction_time");
    if (n["max_duration"]) {
      c.max_duration_ns = f.duration(n["max_duration"], "max_duration");
      if (c.max_duration_ns == 0) f.fail(n["max_duration"], "max_duration must be positive");
    }
    YAML::Node reqs = f.required(n, "requirements", "a fault class");
    if (!reqs.IsSequence() || reqs.size() == 0) f.fail(reqs, "'requirements' must be a non-empty list");
    std::set<std::string> ids;
    for (const auto& rn : reqs) {
      f.keys(rn, {"id", "text", "trigger", "invariant", "final", "delay", "reaction", "release"}, "a class requirement");
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
        if (rn[key]) *dst = f.formula(rn[key], key);
      c.requirements.push_back(r);
    }
    if (YAML::Node fb = n["forbidden"]) {
      if (!fb.IsSequence()) f.fail(fb, "'forbidden' must be a list of formulas");
      for (const auto& x : fb) {
        Forbidden fo;
        if (x.IsMap()) {
          f.keys(x, {"formula", "text"}, "a forbidden reaction");
          fo.formula = f.formula(f.required(x, "formula", "a forbidden reaction"), "formula");
          if (x["text"]) fo.text = f.scalar(x["text"], "text");
        } else {
          fo.formula = f.formula(x, "a forbidden reaction");
        }
        c.forbidden.push_back(fo);
      }
    }
    out->classes.push_back(c);
  }
}

// ------------------------------------------------------------------ campaign

std::string relative_to(const std::string& base_file, const std::string& p) {
  std::filesystem::path path(p);
  if (path.is_absolute()) return p;
  return (std::filesystem::path(base_file).parent_path() / path).lexically_normal().string();
}

void parse_campaign(const YamlFile& f, Campaign* c) {
  f.keys(f.root,
         {"campaign", "text", "program", "plant", "plant_config", "cycle", "tsd", "fmea", "fault_classes", "seed", "budget",
          "max_paths", "search_window", "restart", "io"},
         "a campaign file");
  c->path = f.path;
  c->name = f.scalar(f.required(f.root, "campaign", "the campaign file"), "campaign");
  if (f.root["text"]) c->text = f.scalar(f.root["text"], "text");
  YAML::Node prog = f.required(f.root, "program", "the campaign file");
  if (prog.IsScalar()) {
    c->programs.push_back(relative_to(f.path, prog.Scalar()));
  } else if (prog.IsSequence() && prog.size() > 0) {
    for (const auto& p : prog) c->programs.push_back(relative_to(f.path, f.scalar(p, "a program file")));
  } else {
    f.fail(prog, "'program' must be a file or a list of files");
  }
  c->plant = f.scalar(f.required(f.root, "plant", "the campaign file"), "plant");
  if (f.root["plant_config"]) c->plant_config = relative_to(f.path, f.scalar(f.root["plant_config"], "plant_config"));
  if (f.root["cycle"]) {
    c->cycle_ns = f.duration(f.root["cycle"], "cycle");
    if (c->cycle_ns == 0) f.fail(f.root["cycle"], "cycle must be positive");
  }
  if (f.root["seed"]) {
    int64_t s = f.integer(f.root["seed"], "seed");
    if (s < 0) f.fail(f.root["seed"], "seed must not be negative");
    c->seed = static_cast<uint64_t>(s);
  }
  if (f.root["budget"]) {
    c->budget_ns = f.duration(f.root["budget"], "budget");
    if (c->budget_ns == 0) f.fail(f.root["budget"], "budget must be positive");
  }
  if (f.root["max_paths"]) {
    int64_t m = f.integer(f.root["max_paths"], "max_paths");
    if (m < 1 || m > 64) f.fail(f.root["max_paths"], "max_paths must be 1..64");
    c->max_paths = static_cast<int>(m);
  }
  if (f.root["search_window"]) {
    c->search_window_ns = f.duration(f.root["search_window"], "search_window");
    if (c->search_window_ns == 0) f.fail(f.root["search_window"], "search_window must be positive");
  }
  if (f.root["restart"]) {
    std::string r = f.scalar(f.root["restart"], "restart");
    if (r == "cold") c->restart = RestartKind::Cold;
    else if (r == "warm") c->restart = RestartKind::Warm;
    else f.fail(f.root["restart"], "restart must be 'cold' or 'warm'");
  }
  if (f.root["io"]) c->io = relative_to(f.path, f.scalar(f.root["io"], "io"));
  std::string tsd = relative_to(f.path, f.scalar(f.required(f.root, "tsd", "the campaign file"), "tsd"));
  std::string fmea = relative_to(f.path, f.scalar(f.required(f.root, "fmea", "the campaign file"), "fmea"));
  std::string classes =
      relative_to(f.path, f.scalar(f.required(f.root, "fault_classes", "the campaign file"), "fault_classes"));
  parse_tsd(open_yaml(tsd), &c->tsd);
  parse_fmea(fmea, &c->fmea);
  parse_classes(open_yaml(classes), &c->classes);
}

template <class F>
bool guarded(std::string* err, F&& f) {
  try {
    f();
    return true;
  } catch (const SpecError& e) {
    *err = e.message;
    return false;
  }
}

}  // namespace

bool load_tsd(const std::string& path, Tsd* out, std::string* err) {
  return guarded(err, [&] { parse_tsd(open_yaml(path), out); });
}

bool load_fmea(const std::string& path, Fmea* out, std::string* err) {
  return guarded(err, [&] { parse_fmea(path, out); });
}

bool load_fault_classes(const std::string& path, FaultClasses* out, std::string* err) {
  return guarded(err, [&] { parse_classes(open_yaml(path), out); });
}

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

bool load_campaign(const std::string& path, Campaign* out, std::string* err) {
  if (!guarded(err, [&] { parse_campaign(open_yaml(path), out); })) return false;
  return check_references(*out, err);
}

}  // namespace plcfi::campaign
