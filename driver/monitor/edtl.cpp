// EDTL requirements: loading, translation to monitor programs, and the checking procedure.
#include "edtl.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>

#include <fmt/format.h>

#include "common/duration.hpp"
#include "common/yaml.hpp"

#include "trace_reader.hpp"

namespace plcfi::monitor {

// ------------------------------------------------------------------ loading

namespace {

FormulaSource read_formula(const common::YamlDoc& doc, const YAML::Node& node, std::string_view key) {
  FormulaSource f;
  f.text = doc.scalar(node, std::string(key) + " (an ST expression)");
  f.line = doc.line(node);
  f.col = doc.text_col(node);  // quoted: the formula starts after the quote
  return f;
}

void read_requirements(const common::YamlDoc& doc, RequirementsFile* out) {
  const YAML::Node& root = doc.root();
  YAML::Node list = root;
  if (root.IsMap()) {
    doc.check_keys(root, {"requirements"}, "a requirements file");
    list = doc.required(root, "requirements", "a requirements file");
  } else if (!root.IsSequence()) {
    doc.fail(root, "a requirements file: expected a list of requirements (or a map with the key 'requirements'), got " +
                       common::YamlDoc::describe(root));
  }
  for (const auto& item : doc.list(list, "requirements")) {
    doc.check_keys(item, {"id", "text", "severity", "trigger", "invariant", "final", "delay", "reaction", "release"},
                   "a requirement");
    RequirementSpec r;
    r.line = doc.line(item);
    r.id = doc.scalar(doc.required(item, "id", "a requirement"), "id");
    if (r.id.empty()) doc.fail(item["id"], "id: expected a name, got nothing");
    for (const auto& other : out->requirements)
      if (other.id == r.id) doc.fail(item["id"], "requirement id '" + r.id + "' is used twice");
    if (item["text"]) r.text = doc.scalar(item["text"], "text");
    if (item["severity"]) r.severity = doc.scalar(item["severity"], "severity");
    r.trigger = read_formula(doc, doc.required(item, "trigger", "requirement '" + r.id + "'"), "trigger");
    r.invariant.text = "TRUE";
    r.final.text = "TRUE";
    r.delay.text = "TRUE";
    r.reaction.text = "TRUE";
    r.release.text = "FALSE";
    const std::pair<const char*, FormulaSource*> optional[] = {{"invariant", &r.invariant}, {"final", &r.final},
                                                                {"delay", &r.delay},         {"reaction", &r.reaction},
                                                                {"release", &r.release}};
    for (const auto& [key, dst] : optional)
      if (item[key]) *dst = read_formula(doc, item[key], key);
    out->requirements.push_back(std::move(r));
  }
}

}  // namespace

bool load_requirements(const std::string& path, RequirementsFile* out, std::string* err) {
  out->path = path;
  return common::catch_input_error(err, [&] { read_requirements(common::YamlDoc::open(path), out); });
}

// ------------------------------------------------------------------ translation

std::string expand_symbols(const std::string& text, std::vector<uint32_t>* pos_map) {
  std::string out;
  pos_map->clear();
  auto emit = [&](const std::string& s, uint32_t src) {
    for (char c : s) {
      out += c;
      pos_map->push_back(src);
    }
  };
  // Prefix position: at the start, after '(' ',' an operator, or a keyword operator.
  auto prefix_position = [&]() {
    size_t i = out.size();
    while (i > 0 && std::isspace(static_cast<unsigned char>(out[i - 1]))) --i;
    if (i == 0) return true;
    char c = out[i - 1];
    if (std::string("(,+-*/=<>&").find(c) != std::string::npos) return true;
    size_t j = i;
    while (j > 0 && (std::isalnum(static_cast<unsigned char>(out[j - 1])) || out[j - 1] == '_')) --j;
    std::string word = out.substr(j, i - j);
    for (auto& ch : word) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    return word == "AND" || word == "OR" || word == "XOR" || word == "NOT" || word == "MOD";
  };
  // The operand of a symbolic form: a parenthesized group or a path (a.b[1].c, %IX0.1).
  auto operand_end = [&](size_t i) {
    if (i < text.size() && text[i] == '(') {
      int depth = 0;
      for (size_t k = i; k < text.size(); ++k) {
        if (text[k] == '(') ++depth;
        if (text[k] == ')' && --depth == 0) return k + 1;
      }
      return text.size();
    }
    size_t k = i;
    int bracket = 0;
    while (k < text.size()) {
      char c = text[k];
      if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '%' || c == '#') ++k;
      else if (c == '[') ++bracket, ++k;
      else if (c == ']' && bracket > 0) --bracket, ++k;
      else if (bracket > 0) ++k;
      else break;
    }
    return k;
  };
  size_t i = 0;
  while (i < text.size()) {
    char c = text[i];
    bool sym = (c == '/' || c == '\\' || c == '~' || c == '_') && i + 1 < text.size() &&
               (std::isalpha(static_cast<unsigned char>(text[i + 1])) || text[i + 1] == '(' || text[i + 1] == '%' ||
                (c != '_' && text[i + 1] == '_'));
    if (sym && c == '_' && i > 0 && (std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_')) sym = false;
    if (sym && prefix_position()) {
      const char* fn = c == '/' ? "RISING(" : c == '\\' ? "FALLING(" : c == '~' ? "HIGH(" : "LOW(";
      emit(fn, static_cast<uint32_t>(i));
      size_t end = operand_end(i + 1);
      for (size_t k = i + 1; k < end; ++k) {
        out += text[k];
        pos_map->push_back(static_cast<uint32_t>(k));
      }
      emit(")", static_cast<uint32_t>(end > 0 ? end - 1 : 0));
      i = end;
      continue;
    }
    out += c;
    pos_map->push_back(static_cast<uint32_t>(i));
    ++i;
  }
  return out;
}

namespace {
const char* kOutputs[] = {"__o_trig", "__o_inv", "__o_fin", "__o_del", "__o_react", "__o_rel"};

std::string program_name(size_t i) { return "__EDTL_" + std::to_string(i + 1); }
}  // namespace

namespace {

// A temporal operator call cut out of a formula: its text and source columns.
struct Hoisted {
  std::string text;
  std::vector<uint32_t> map;
};

bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Finds the temporal operator call (RISING ... DECREASES, not PASSED) that starts last in
// `t`: it contains no other one. Returns its [begin, end) or false.
bool last_temporal_call(const std::string& t, size_t* begin, size_t* end) {
  static const char* kOps[] = {"RISING", "FALLING", "HIGH", "LOW", "CHANGES", "INCREASES", "DECREASES"};
  bool found = false;
  for (size_t i = 0; i < t.size(); ++i) {
    if (!std::isalpha(static_cast<unsigned char>(t[i])) || (i > 0 && (ident_char(t[i - 1]) || t[i - 1] == '.'))) continue;
    size_t j = i;
    while (j < t.size() && ident_char(t[j])) ++j;
    std::string word = st::canon(t.substr(i, j - i));
    bool op = false;
    for (const char* k : kOps) op = op || word == k;
    size_t k = j;
    while (k < t.size() && std::isspace(static_cast<unsigned char>(t[k]))) ++k;
    if (op && k < t.size() && t[k] == '(') {
      // The matching parenthesis, skipping string literals.
      int depth = 0;
      size_t e = k;
      for (; e < t.size(); ++e) {
        if (t[e] == '\'') {
          for (++e; e < t.size() && t[e] != '\''; ++e)
            if (t[e] == '$') ++e;
          continue;
        }
        if (t[e] == '(') ++depth;
        if (t[e] == ')' && --depth == 0) break;
      }
      if (e < t.size()) {
        *begin = i;
        *end = e + 1;
        found = true;
      }
    }
    i = j - 1;
  }
  return found;
}

}  // namespace

MonitorSource generate_monitors(const RequirementsFile& reqs) {
  MonitorSource src;
  src.name = "<monitors:" + reqs.path + ">";
  auto line = [&](const std::string& s) {
    src.text += s + "\n";
    src.lines.emplace_back();
  };
  auto mapped = [&](const std::string& s, const FormulaSource* f, std::vector<uint32_t> map) {
    line(s);
    src.lines.back().formula = f;
    src.lines.back().pos_map = std::move(map);
  };
  for (size_t i = 0; i < reqs.requirements.size(); ++i) {
    const auto& r = reqs.requirements[i];
    const FormulaSource* fs[] = {&r.trigger, &r.invariant, &r.final, &r.delay, &r.reaction, &r.release};
    // Temporal operators keep per-state history, so they are computed every state in a
    // prologue; the formulas read their results. That lets a step evaluate the trigger
    // alone while no instance is open (__full = FALSE) without losing history.
    std::string body[6];
    std::vector<uint32_t> maps[6];
    std::vector<std::pair<Hoisted, const FormulaSource*>> hoisted;
    for (int k = 0; k < 6; ++k) {
      body[k] = expand_symbols(fs[k]->text, &maps[k]);
      // A formula spans one generated line; newlines inside it are spaces.
      for (char& c : body[k])
        if (c == '\n' || c == '\r') c = ' ';
      size_t b = 0, e = 0;
      while (last_temporal_call(body[k], &b, &e)) {
        Hoisted h{body[k].substr(b, e - b), std::vector<uint32_t>(maps[k].begin() + static_cast<long>(b), maps[k].begin() + static_cast<long>(e))};
        std::string var = fmt::format("__e{}", hoisted.size() + 1);
        uint32_t at = maps[k][b];
        body[k].replace(b, e - b, var);
        maps[k].erase(maps[k].begin() + static_cast<long>(b), maps[k].begin() + static_cast<long>(e));
        maps[k].insert(maps[k].begin() + static_cast<long>(b), var.size(), at);
        hoisted.emplace_back(std::move(h), fs[k]);
      }
    }
    line("PROGRAM " + program_name(i));
    line("VAR_INPUT __elapsed : LTIME; __state : LINT; __full : BOOL; END_VAR");
    line("VAR_OUTPUT __o_trig, __o_inv, __o_fin, __o_del, __o_react, __o_rel : BOOL; END_VAR");
    if (!hoisted.empty()) {
      std::string vars;
      for (size_t h = 0; h < hoisted.size(); ++h) vars += fmt::format("{}__e{}", h ? ", " : "", h + 1);
      line("VAR " + vars + " : BOOL; END_VAR");
    }
    for (size_t h = 0; h < hoisted.size(); ++h) {
      line(fmt::format("__e{} :=", h + 1));
      mapped(hoisted[h].first.text, hoisted[h].second, hoisted[h].first.map);
      line(";");
    }
    for (int k = 0; k < 6; ++k) {
      if (k == 1) line("IF __full THEN");
      line(std::string(kOutputs[k]) + " := (");
      mapped(body[k], fs[k], maps[k]);
      line(");");
    }
    line("END_IF;");
    line("END_PROGRAM");
  }
  return src;
}

st::GeneratedSource MonitorSource::source(const std::string& reqs_path, bool exact_columns) const {
  std::vector<st::LineOrigin> origins(lines.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    const LineInfo& li = lines[i];
    st::LineOrigin& o = origins[i];
    if (!li.formula || li.formula->line == 0) {
      o.context = "in a default formula";
      continue;
    }
    o.path = reqs_path;
    o.line = li.formula->line;
    o.col = li.formula->col;
    o.prefix = li.prefix;
    o.col_map = li.pos_map;
    o.exact_columns = exact_columns;
  }
  return st::GeneratedSource(name, text, std::move(origins));
}

// ------------------------------------------------------------------ checking

namespace {

// The durations of every PASSED(<literal>) in `up` (upper case, as st::canon gives it)
// into *out; false when a PASSED takes anything but one duration literal (a variable, an
// expression): then the elapsed time matters in ways the cache cannot know.
bool passed_literals(const std::string& up, std::vector<int64_t>* out) {
  for (size_t at = up.find("PASSED"); at != std::string::npos; at = up.find("PASSED", at + 6)) {
    // Only the operator: a name that merely contains the word (MYPASSED, PASSED_X) is not.
    auto ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    if ((at > 0 && ident(up[at - 1])) || (at + 6 < up.size() && ident(up[at + 6]))) continue;
    size_t p = up.find_first_not_of(" \t", at + 6);
    if (p == std::string::npos || up[p] != '(') return false;
    const size_t close = up.find(')', p);
    if (close == std::string::npos) return false;
    std::string arg = up.substr(p + 1, close - p - 1);
    while (!arg.empty() && std::isspace(static_cast<unsigned char>(arg.back()))) arg.pop_back();
    while (!arg.empty() && std::isspace(static_cast<unsigned char>(arg.front()))) arg.erase(arg.begin());
    if (arg.find('#') == std::string::npos) return false;
    const common::DurationParse d = common::parse_duration(arg);
    if (!d.error.empty()) return false;
    out->push_back(d.ns);
  }
  return true;
}

}  // namespace

std::unique_ptr<MonitorSet> MonitorSet::create(const st::Application& app, const RequirementsFile& reqs, std::string* err) {
  return create(app, reqs, 0, reqs.requirements.size(), err);
}

std::unique_ptr<MonitorSet> MonitorSet::create(const st::Application& app, const RequirementsFile& reqs, size_t first,
                                               size_t count, std::string* err) {
  auto set = std::make_unique<MonitorSet>();
  if (first + count > reqs.requirements.size()) {
    *err = "monitor range beyond the requirements";
    return nullptr;
  }
  for (size_t i = first; i < first + count; ++i) {
    const auto& spec = reqs.requirements[i];
    std::string name = program_name(i);
    const st::ProgramInstance* inst = nullptr;
    for (const auto& o : app.observers)
      if (o.name == name) inst = &o;
    if (!inst) {
      *err = "monitor for requirement " + spec.id + " is missing from the build";
      return nullptr;
    }
    Req r;
    r.spec = &spec;
    r.entry = inst->pou->entry;
    r.addr = inst->addr;
    for (int k = 0; k < 6; ++k) {
      const st::Symbol* s = inst->pou->find_var(kOutputs[k]);
      if (!s) {
        *err = "monitor " + name + " lacks " + kOutputs[k];
        return nullptr;
      }
      r.out[k].type = s->type;
      r.out[k].addr = inst->addr + s->offset;
      r.out[k].path = name + "." + kOutputs[k];
    }
    const st::Symbol* el = inst->pou->find_var("__elapsed");
    const st::Symbol* sn = inst->pou->find_var("__state");
    const st::Symbol* fu = inst->pou->find_var("__full");
    if (!el || !sn || !fu || el->type->size != 8 || sn->type->size != 8) {
      *err = "monitor " + name + " lacks its inputs";
      return nullptr;
    }
    r.shift = inst->pou->shift.present ? &inst->pou->shift : nullptr;
    r.full.type = fu->type;
    r.full.addr = inst->addr + fu->offset;
    r.elapsed.type = el->type;
    r.elapsed.addr = inst->addr + el->offset;
    r.state.type = sn->type;
    r.state.addr = inst->addr + sn->offset;
    const FormulaSource* fs[] = {&spec.trigger, &spec.invariant, &spec.final, &spec.delay, &spec.reaction, &spec.release};
    r.passed_known = true;
    for (const auto* f : fs) {
      std::string up = st::canon(f->text);
      if (up.find("PASSED") != std::string::npos) r.uses_passed = true;
      if (!passed_literals(up, &r.thresholds)) r.passed_known = false;
    }
    std::sort(r.thresholds.begin(), r.thresholds.end());
    r.thresholds.erase(std::unique(r.thresholds.begin(), r.thresholds.end()), r.thresholds.end());
    r.cached.assign(r.thresholds.size() + 1, {});
    r.cached_ok.assign(r.thresholds.size() + 1, 0);
    r.verdict.id = spec.id;
    r.verdict.text = spec.text;
    r.verdict.severity = spec.severity;
    set->reqs_.push_back(std::move(r));
  }
  return set;
}

bool MonitorSet::eval(st::Machine& m, Req& r, int64_t elapsed, bool v[6], bool full) {
  // __elapsed (LTIME) and __state (LINT) are 8-byte slots, __full a BOOL byte.
  int64_t st = static_cast<int64_t>(state_);
  if (r.shift) {
    // The shift to a new state, natively (the program would do the same in bytecode).
    uint8_t* base = m.mem() + r.addr;
    int64_t seen;
    std::memcpy(&seen, base + r.shift->seen, 8);
    if (seen != st) {
      if (seen >= 0 && r.shift->started >= 0) base[r.shift->started] = 1;
      for (const auto& mv : r.shift->moves) {
        switch (mv[2]) {  // fixed sizes inline to single moves
          case 1: base[mv[1]] = base[mv[0]]; break;
          case 2: std::memcpy(base + mv[1], base + mv[0], 2); break;
          case 4: std::memcpy(base + mv[1], base + mv[0], 4); break;
          case 8: std::memcpy(base + mv[1], base + mv[0], 8); break;
          default: std::memmove(base + mv[1], base + mv[0], mv[2]); break;
        }
      }
      std::memcpy(base + r.shift->seen, &st, 8);
    }
  }
  std::memcpy(m.mem() + r.elapsed.addr, &elapsed, 8);
  std::memcpy(m.mem() + r.state.addr, &st, 8);
  m.mem()[r.full.addr] = full ? 1 : 0;
  bool ok = m.call(r.entry, r.addr);
  const uint8_t* mem = m.mem();
  for (int k = 0; k < (full ? 6 : 1); ++k) v[k] = ok && mem[r.out[k].addr] != 0;
  return ok;
}

bool MonitorSet::step(st::Machine& m, uint64_t state, int64_t t) {
  newly_.clear();
  state_ = state;
  for (size_t ri = 0; ri < reqs_.size(); ++ri) {
    Req& r = reqs_[ri];
    bool base[6] = {};
    // While no instance is open only the trigger matters; a trigger (or an open instance)
    // needs every formula at this state.
    eval(m, r, 0, base, !r.groups.empty());
    if (base[0] && r.groups.empty()) eval(m, r, 0, base, true);
    bool was_violated = r.verdict.violated();
    std::fill(r.cached_ok.begin(), r.cached_ok.end(), 0);  // a new state: nothing cached
    if (base[0]) {
      ++r.verdict.triggers;
      r.groups.push_back(Group{false, state, t, state, t, 1});
    }
    auto violate = [&](const Group& g, Cause c) {
      r.verdict.violated_instances += g.count;
      if (r.verdict.violations.size() < Verdict::kMaxListed)
        r.verdict.violations.push_back(Violation{g.first_trigger, g.first_trigger_time, state, t, c, g.count});
    };
    for (size_t gi = 0; gi < r.groups.size();) {
      Group& g = r.groups[gi];
      bool v[6];
      bool done = false;
      const bool* val = base;
      if (r.uses_passed && !(g.timer_time == t)) {
        const int64_t elapsed = t - g.timer_time;
        if (r.passed_known) {
          const size_t k = static_cast<size_t>(std::upper_bound(r.thresholds.begin(), r.thresholds.end(), elapsed) -
                                               r.thresholds.begin());
          if (!r.cached_ok[k]) {
            eval(m, r, elapsed, r.cached[k].data(), true);
            r.cached_ok[k] = 1;
          }
          val = r.cached[k].data();
        } else {
          eval(m, r, elapsed, v, true);
          val = v;
        }
      }
      if (!g.phase_b) {
        if (val[5]) {
          r.verdict.holds += g.count;
          done = true;
        } else if (val[2]) {
          g.phase_b = true;
          g.timer_state = state;
          g.timer_time = t;
          val = base;  // the timer point is now: elapsed 0
        } else if (!val[1]) {
          violate(g, Cause::Invariant);
          done = true;
        }
      }
      if (!done && g.phase_b) {
        if (val[5] || val[4]) {
          r.verdict.holds += g.count;
          done = true;
        } else if (!val[1]) {
          violate(g, Cause::Invariant);
          done = true;
        } else if (val[3]) {
          violate(g, Cause::Delay);
          done = true;
        }
      }
      if (done) r.groups.erase(r.groups.begin() + static_cast<long>(gi));
      else ++gi;
    }
    // Instances that behave identically from now on are one group: without PASSED all
    // instances of a phase; with PASSED those sharing their timer point. (In place: the
    // vector's capacity is reused, no allocation per state.)
    if (r.groups.size() > 1 && !r.uses_passed) {
      size_t kept = 0;  // at most two: one per phase
      for (size_t gi = 0; gi < r.groups.size(); ++gi) {
        const Group& g = r.groups[gi];
        size_t k = 0;
        while (k < kept && r.groups[k].phase_b != g.phase_b) ++k;
        if (k < kept) r.groups[k].count += g.count;
        else r.groups[kept++] = g;
      }
      r.groups.resize(kept);
    } else if (r.groups.size() > 1) {
      // Keys (phase, timer point) were unique after the last state; only a group whose
      // timer point is this state (a new trigger, or one that entered phase b now) can
      // share its key, so one pass merges (linear, where comparing all pairs was
      // quadratic in the open instances of a long deadline).
      size_t kept = 0, now_a = SIZE_MAX, now_b = SIZE_MAX;
      for (size_t gi = 0; gi < r.groups.size(); ++gi) {
        const Group& g = r.groups[gi];
        size_t* slot = g.timer_time == t ? (g.phase_b ? &now_b : &now_a) : nullptr;
        if (slot && *slot != SIZE_MAX) {
          r.groups[*slot].count += g.count;
          continue;
        }
        if (slot) *slot = kept;
        r.groups[kept++] = g;
      }
      r.groups.resize(kept);
    }
    if (!was_violated && r.verdict.violated()) newly_.push_back(ri);
  }
  return !newly_.empty();
}

std::vector<Verdict> MonitorSet::verdicts() const {
  std::vector<Verdict> out;
  for (const auto& r : reqs_) {
    Verdict v = r.verdict;
    v.pending = 0;
    for (const auto& g : r.groups) v.pending += g.count;
    out.push_back(std::move(v));
  }
  return out;
}

std::string cause_text(Cause c) {
  return c == Cause::Invariant ? "invariant broken" : "no reaction within the delay";
}

bool check_trace(const RequirementsFile& reqs, const std::string& trace_path, int64_t cycle_ns, TraceCheck* out,
                 std::string* error) {
  bool is_vcd = trace_path.size() > 4 && trace_path.substr(trace_path.size() - 4) == ".vcd";
  auto reader = TraceReader::open(trace_path, cycle_ns ? cycle_ns : (is_vcd ? 0 : 1'000'000'000), error);
  if (!reader) return false;
  std::string program;
  if (!trace_program(reader->columns(), &program, error)) {
    *error = trace_path + ": " + *error;
    return false;
  }
  auto mon = generate_monitors(reqs);
  st::CompileOptions opt;
  opt.warnings = false;
  auto b = st::build_sources({{"<trace:" + trace_path + ">", program}}, opt, {mon.source(reqs.path)});
  if (!b->ok()) {
    *error = b->diags.render_all();
    return false;
  }
  auto set = MonitorSet::create(*b->app, reqs, error);
  if (!set) return false;
  st::Machine m(*b->app);
  std::vector<st::VarHandle> handles;
  if (!resolve_trace_columns(*b->app, reader->columns(), &handles, error)) {
    *error = trace_path + ": " + *error;
    return false;
  }
  std::vector<double> values;
  int64_t t = 0;
  uint64_t state = 0;
  error->clear();
  while (reader->next(&t, &values, error)) {
    const std::vector<int64_t>& times = reader->time_values();
    for (size_t i = 0; i < handles.size(); ++i) {
      if (handles[i].type->is_real()) st::write_real(m, handles[i], values[i]);
      else if (i < times.size() && reader->columns()[i].is_time()) st::write_int(m, handles[i], times[i]);
      else st::write_int(m, handles[i], static_cast<int64_t>(values[i]));
    }
    m.set_now(t);
    set->step(m, state++, t);
  }
  if (!error->empty()) return false;
  out->verdicts = set->verdicts();
  out->states = state;
  return true;
}

}  // namespace plcfi::monitor
