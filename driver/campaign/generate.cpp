// Test-case generation and the one compilation of program, preconditions and monitors.
#include "generate.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include <fmt/format.h>

#include "explore.hpp"

namespace plcfi::campaign {

std::string TestCase::transition_ref() const {
  return scenario->id + "." + step->id + "." + (explored ? target->name : transition->lifeline);
}

std::string st_duration(int64_t ns) {
  if (ns % 1'000'000 == 0) return fmt::format("T#{}ms", ns / 1'000'000);
  if (ns % 1'000 == 0) return fmt::format("T#{}us", ns / 1'000);
  return fmt::format("T#{}ns", ns);
}

std::string human_duration(int64_t ns) {
  if (ns >= 1'000'000'000 && ns % 10'000'000 == 0) return fmt::format("{:g} s", static_cast<double>(ns) * 1e-9);
  if (ns % 1'000'000 == 0) return fmt::format("{} ms", ns / 1'000'000);
  return fmt::format("{:g} ms", static_cast<double>(ns) * 1e-6);
}

std::string address_text(const rt::ImageRef& r) {
  if (r.is_bit) return fmt::format("%{}X{}.{}", r.area, r.offset, r.bit);
  char size = r.size == 1 ? 'B' : r.size == 2 ? 'W' : r.size == 4 ? 'D' : 'L';
  return fmt::format("%{}{}{}", r.area, size, r.offset / r.size);
}

namespace {

constexpr const char* kPreProgram = "__FI_PRECONDITIONS";
constexpr size_t kPreconditionFirstLine = 4;  // of the precondition program

bool is_bool(const st::Type* t) { return t && t->kind == st::TypeKind::Bool; }

// Integer range of a location type (analog comparisons clamp their bounds to it).
std::pair<double, double> type_range(const st::Type* t) {
  if (!t || (!t->is_integer() && !t->is_bitstring())) return {-1e300, 1e300};
  double bits = 8.0 * t->size;
  if (t->is_signed()) return {-std::pow(2.0, bits - 1), std::pow(2.0, bits - 1) - 1};
  return {0, std::pow(2.0, bits) - 1};
}

bool parse_number(const std::string& s, double* v) {
  try {
    size_t used = 0;
    *v = std::stod(s, &used);
    return used == s.size();
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

std::string lifeline_state(const Lifeline& l, const st::VarHandle& h, const std::string& value, double tol,
                           std::string* human) {
  double v = 0;
  if (tol > 0 && !is_bool(h.type) && parse_number(value, &v) && h.type && (h.type->is_integer() || h.type->is_bitstring())) {
    auto [lo, hi] = type_range(h.type);
    double a = std::max(lo, std::ceil(v - tol)), b = std::min(hi, std::floor(v + tol));
    *human = fmt::format("{} = {} +/- {}", l.name, value, tol);
    return fmt::format("({} >= {} AND {} <= {})", l.bind, static_cast<int64_t>(a), l.bind, static_cast<int64_t>(b));
  }
  if (tol > 0 && h.type && h.type->is_real() && parse_number(value, &v)) {
    *human = fmt::format("{} = {} +/- {}", l.name, value, tol);
    return fmt::format("({} >= {} AND {} <= {})", l.bind, v - tol, l.bind, v + tol);
  }
  if (is_bool(h.type)) {
    std::string up = st::canon(value);
    if (up == "TRUE" || up == "1") {
      *human = l.name;
      return "(" + l.bind + ")";
    }
    if (up == "FALSE" || up == "0") {
      *human = "NOT " + l.name;
      return "(NOT " + l.bind + ")";
    }
  }
  *human = l.name + " = " + value;
  return "(" + l.bind + " = " + value + ")";
}

namespace {

std::string substitute(std::string text, const std::map<std::string, std::string>& vars) {
  for (const auto& [k, v] : vars) {
    std::string key = "{" + k + "}";
    for (size_t p = text.find(key); p != std::string::npos; p = text.find(key, p + v.size())) text.replace(p, key.size(), v);
  }
  return text;
}

// Where each line of the precondition program comes from: one line per case, pointing
// at the TSD step's precondition (the text is assembled from its entries, so a message
// points at the step's first entry, whatever the column).
std::vector<st::LineOrigin> precondition_origins(const std::vector<TestCase>& cases, const std::string& tsd_path) {
  std::vector<st::LineOrigin> origins(kPreconditionFirstLine - 1);
  for (const TestCase& c : cases) {
    const Loc& at = c.step->pre.empty() ? c.step->loc : c.step->pre.front().loc;
    st::LineOrigin o;
    o.path = tsd_path;
    o.line = at.line;
    o.col = at.col;
    o.exact_columns = false;
    o.context = "in the precondition of " + c.scenario->id + "." + c.step->id + ": " + c.precondition;
    origins.push_back(std::move(o));
  }
  return origins;
}

}  // namespace

std::string precondition_program(const std::vector<TestCase>& cases) {
  // kPreconditionFirstLine - 1 lines before the first case's.
  std::string s = fmt::format("PROGRAM {}\nVAR_OUTPUT pre : ARRAY[0..{}] OF BOOL; END_VAR\n(* one line per test case *)\n",
                              kPreProgram, cases.empty() ? 0 : cases.size() - 1);
  for (size_t i = 0; i < cases.size(); ++i) s += fmt::format("pre[{}] := {};\n", i, cases[i].precondition);
  s += "END_PROGRAM\n";
  return s;
}

bool prepare_campaign(Campaign spec, CampaignBuild* out, std::string* err) {
  out->spec = std::move(spec);
  const Campaign& c = out->spec;
  st::CompileOptions opt;
  opt.warnings = false;
  opt.condition_jumps = !c.for_mutation;
  opt.loop_tails = !c.for_mutation;
  opt.if_selects = !c.for_mutation;
  opt.elsif_reuse = !c.for_mutation;
  opt.cold_arms = !c.for_mutation;
  st::parse_dialect(c.dialect, &opt.dialect);  // checked when the file was read

  // 1. The program alone: bindings, alarms and fault targets are checked against it.
  auto prog = st::build_files(c.programs, opt);
  if (!prog->ok()) {
    *err = "";
    for (const auto& e : prog->io_errors) *err += e + "\n";
    *err += prog->diags.render_all();
    return false;
  }
  const st::Application& papp = *prog->app;
  std::map<std::string, st::VarHandle> binds;
  for (const auto& l : c.tsd.lifelines) {
    std::string e;
    auto h = st::resolve(papp, l.bind, &e);
    if (!h) {
      *err = l.bind_loc.str() + ": lifeline " + l.name + ": " + e;
      return false;
    }
    if (!h->type || !h->type->is_elementary()) {
      *err = l.bind_loc.str() + ": lifeline " + l.name + ": '" + l.bind + "' is not an elementary value";
      return false;
    }
    binds[l.name] = *h;
  }
  std::set<std::string> alarm_paths;
  for (const auto& r : c.fmea.rows) {
    std::string e;
    auto h = st::resolve(papp, r.alarm, &e);
    if (!h) {
      *err = r.alarm_loc.str() + ": alarm: " + e;
      return false;
    }
    if (!is_bool(h->type)) {
      *err = r.alarm_loc.str() + ": alarm '" + r.alarm + "' is not a BOOL";
      return false;
    }
    alarm_paths.insert(r.alarm);
  }

  // The campaign's requirements (explored cases only), checked against the program alone
  // so that a message points into their own file.
  monitor::RequirementsFile campaign_reqs;
  if (c.explore.enabled && !c.requirements.empty()) {
    if (!monitor::load_requirements(c.requirements, &campaign_reqs, err)) return false;
    auto mon = monitor::generate_monitors(campaign_reqs);
    auto check = st::build_files(c.programs, opt, {mon.source(campaign_reqs.path)});
    if (!check->ok()) {
      *err = check->diags.render_all();
      return false;
    }
  }

  // 2. One case per FMEA row, on the transition it names.
  std::vector<TestCase> cases;
  for (const auto& r : c.fmea.rows) {
    TestCase tc;
    tc.row = &r;
    tc.rpn = r.rpn;
    std::string sc, stp, ll;
    split_transition_ref(r.transition, &sc, &stp, &ll);  // checked by check_references
    for (const auto& s : c.tsd.scenarios)
      if (s.id == sc) tc.scenario = &s;
    for (const auto& s : tc.scenario->steps)
      if (s.id == stp) tc.step = &s;
    for (const auto& t : tc.step->transitions)
      if (t.lifeline == ll) tc.transition = &t;
    tc.cls = c.classes.find(r.fault_class);

    // Precondition: the lifeline states, and the step's condition.
    std::string expr, human;
    for (const auto& ps : tc.step->pre) {
      const Lifeline* l = c.tsd.find(ps.lifeline);
      std::string h;
      expr += (expr.empty() ? "" : " AND ") + lifeline_state(*l, binds[l->name], ps.value, l->tolerance, &h);
    }
    if (!tc.step->condition.empty()) expr += " AND (" + tc.step->condition + ")";
    tc.precondition = expr;
    tc.start = tc.step->start.empty() ? "TRUE" : tc.step->start;

    // Fault: the transition's lifeline, or "Lifeline: model" for another one.
    std::string model = r.fault_model;
    uint32_t model_col = r.fault_loc.col;
    tc.target = c.tsd.find(tc.transition->lifeline);
    size_t colon = model.find(':');
    if (colon != std::string::npos) {
      std::string name = model.substr(0, colon);
      name.erase(name.find_last_not_of(' ') + 1);
      tc.target = c.tsd.find(name);
      if (!tc.target) {
        *err = r.fault_loc.str() + ": unknown lifeline '" + name + "' in the fault model";
        return false;
      }
      size_t b = model.find_first_not_of(' ', colon + 1);
      model_col += static_cast<uint32_t>(b == std::string::npos ? model.size() : b);
      model = b == std::string::npos ? "" : model.substr(b);
    }
    std::string e;
    if (!rt::parse_image_ref(papp, tc.target->bind, &tc.target_ref, &e)) {
      *err = r.fault_loc.str() + ": lifeline " + tc.target->name + " (" + tc.target->bind +
             ") is not an I/O address, so no fault can act on it: " + e;
      return false;
    }
    tc.target_ref.text = address_text(tc.target_ref);
    if (model.empty()) model = is_bool(tc.target_ref.type) ? "stuck" : "frozen";
    uint32_t ecol = 0;
    if (!faults::parse_fault(model, &tc.fault, &e, &ecol)) {
      *err = fmt::format("{}:{}:{}: {}", r.fault_loc.file, r.fault_loc.line, model_col + ecol, e);
      return false;
    }
    faults::InjectionContext ctx;
    ctx.ref = tc.target_ref;
    ctx.tick_ns = 10'000'000;
    if (!faults::make_rule(tc.fault, ctx, &e)) {
      *err = r.fault_loc.str() + ": " + e;
      return false;
    }
    tc.deadline_ns = tc.transition->max_ns + tc.cls->reaction_time_ns;
    tc.max_duration_ns = tc.cls->max_duration_ns;
    cases.push_back(std::move(tc));
  }
  std::stable_sort(cases.begin(), cases.end(), [](const TestCase& a, const TestCase& b) { return a.rpn > b.rpn; });
  for (size_t i = 0; i < cases.size(); ++i) cases[i].id = fmt::format("TC{}", i + 1);
  // Fault-space exploration: more cases after the FMEA's (explore.hpp).
  if (c.explore.enabled && !add_explored_cases(out, papp, binds, &cases, err)) return false;

  // 3. Monitors: the class requirements with this case's values, then the forbidden
  // reactions (an invariant that must hold for the whole test).
  out->monitors.path = c.classes.path;
  for (size_t i = 0; i < cases.size(); ++i) {
    TestCase& tc = cases[i];
    std::map<std::string, std::string> vars = {{"alarm", tc.row->alarm},
                                               {"start", tc.start},
                                               {"deadline", st_duration(tc.deadline_ns)},
                                               {"signal", tc.target->bind}};
    tc.first_req = out->monitors.requirements.size();
    std::string reaction;
    // An explored case's detection is the oracle's (explore.hpp): only its forbidden
    // reactions are monitors.
    for (const auto& cr : tc.cls->requirements) {
      if (tc.explored) break;
      monitor::RequirementSpec r;
      r.id = tc.id + "." + cr.id;
      r.text = substitute(cr.text, vars);
      r.severity = "class " + tc.cls->id;
      std::pair<const monitor::FormulaSource*, monitor::FormulaSource*> fs[] = {
          {&cr.trigger, &r.trigger}, {&cr.invariant, &r.invariant}, {&cr.final, &r.final},
          {&cr.delay, &r.delay},     {&cr.reaction, &r.reaction},   {&cr.release, &r.release}};
      for (auto& [src, dst] : fs) {
        *dst = *src;
        dst->text = substitute(src->text, vars);
      }
      if (r.reaction.text != "TRUE") reaction += (reaction.empty() ? "" : "; ") + r.reaction.text;
      out->monitors.requirements.push_back(r);
    }
    for (size_t k = 0; k < tc.cls->forbidden.size(); ++k) {
      const Forbidden& fb = tc.cls->forbidden[k];
      monitor::RequirementSpec r;
      r.id = fmt::format("{}.forbidden{}", tc.id, k + 1);
      r.text = fb.text.empty() ? "forbidden: " + fb.formula.text : substitute(fb.text, vars);
      r.severity = "forbidden";
      r.trigger.text = "TRUE";
      r.invariant = fb.formula;
      r.invariant.text = "NOT (" + substitute(fb.formula.text, vars) + ")";
      // "NOT (" shifts the formula by five columns in error messages; point at its start.
      r.final.text = "FALSE";
      r.delay.text = "TRUE";
      r.reaction.text = "TRUE";
      r.release.text = "FALSE";
      out->monitors.requirements.push_back(r);
      ++tc.forbidden;
    }
    if (tc.explored)
      for (const auto& cr : campaign_reqs.requirements) {
        monitor::RequirementSpec r = cr;
        r.id = tc.id + "." + cr.id;
        out->monitors.requirements.push_back(r);
      }
    tc.reqs = out->monitors.requirements.size() - tc.first_req;
    if (tc.explored) {
      tc.expected = fmt::format("detected ({}) before the TSD deviates, or by the deviation's bound + {}; or tolerated "
                                "(the transitions of {}.{} and of the scenario's later steps in time)",
                                tc.row->alarm, human_duration(tc.cls->reaction_time_ns), tc.scenario->id, tc.step->id);
      continue;
    }
    tc.expected = fmt::format("{} within {} of {}", reaction.empty() ? "(class requirements)" : reaction,
                              human_duration(tc.deadline_ns), tc.step->start.empty() ? "the precondition" : tc.start);
  }
  out->cases = std::move(cases);

  // 4. Preconditions and monitors linked onto the program of step 1 (compiled once).
  out->monitor_source = monitor::generate_monitors(out->monitors);
  out->preconditions_source = precondition_program(out->cases);
  // Class formulas are instantiated per case with other text in their placeholders:
  // their messages point at the formula's start.
  st::GeneratedSources late = {{"<preconditions>", out->preconditions_source, precondition_origins(out->cases, c.tsd.path)},
                               out->monitor_source.source(out->monitors.path, false)};
  if (c.explore.enabled) late.emplace_back("<explore>", out->explore.source, out->explore.origins);
  if (!st::link_generated(*prog, late, opt)) {
    *err = prog->diags.render_all();
    return false;
  }
  out->build = std::move(prog);
  const st::Application& app = *out->build->app;
  const st::Symbol* pre = nullptr;
  for (const auto& o : app.observers)
    if (o.name == kPreProgram) {
      out->preconditions_entry = o.pou->entry;
      out->preconditions_addr = o.addr;
      pre = o.pou->find_var("pre");
    }
  if (!pre) {
    *err = "internal: the precondition program is missing from the build";
    return false;
  }
  out->preconditions.path = std::string(kPreProgram) + ".pre";
  out->preconditions.type = pre->type;
  out->preconditions.addr = out->preconditions_addr + pre->offset;
  if (c.explore.enabled && !bind_explore(out, err)) return false;
  std::string e;

  bool ok = app.has_configuration ? out->schedule.from_configuration(app, &e)
                                  : out->schedule.single_program(app, "", c.cycle_ns ? c.cycle_ns : 10'000'000, &e);
  if (!ok) {
    *err = c.path + ": " + e;
    return false;
  }
  if (c.cycle_ns && app.has_configuration && c.cycle_ns != out->schedule.tick_ns()) {
    *err = fmt::format("{}: cycle {} differs from the base tick {} of the program's CONFIGURATION", c.path,
                       human_duration(c.cycle_ns), human_duration(out->schedule.tick_ns()));
    return false;
  }

  // The program's own files (branch points elsewhere, e.g. in the standard library, do
  // not define a control-flow path of the program).
  for (uint32_t f = 0; f < app.file_paths.size(); ++f)
    for (const auto& p : c.programs)
      if (std::filesystem::path(app.file_paths[f]).lexically_normal() == std::filesystem::path(p).lexically_normal())
        out->program_files.push_back(f);

  for (const auto& l : c.tsd.lifelines) {
    auto h = st::resolve(app, l.bind, &e);
    if (h) {
      h->path = l.name;
      out->watch.push_back(*h);
    }
  }
  for (const auto& a : alarm_paths) {
    auto h = st::resolve(app, a, &e);
    if (h) out->watch.push_back(*h);
  }

  // Recovery after the reaction: the acknowledgement input and the variables it clears.
  for (auto& tc : out->cases) {
    const Recovery& rc = tc.cls->recovery;
    if (!rc.enabled || tc.explored || !tc.row) continue;
    const std::string where = rc.loc.str() + ": class " + tc.cls->id + ": recovery: ";
    const Lifeline* l = c.tsd.find(rc.acknowledge);
    const std::string ack = l ? l->bind : rc.acknowledge;
    if (!rt::parse_image_ref(app, ack, &tc.ack_ref, &e)) {
      *err = where + "acknowledge: " + e;
      return false;
    }
    if (tc.ack_ref.area != 'I' || !is_bool(tc.ack_ref.type)) {
      *err = where + "acknowledge: '" + rc.acknowledge + "' is not a BOOL input (%IX): the test presses it like a push-button";
      return false;
    }
    tc.ack_ref.text = address_text(tc.ack_ref);
    tc.cleared.clear();
    std::vector<std::string> names{tc.row->alarm};
    names.insert(names.end(), rc.cleared.begin(), rc.cleared.end());
    for (const auto& v : names) {
      auto h = st::resolve(app, v, &e);
      if (!h || !is_bool(h->type)) {
        *err = where + "cleared: " + (h ? "'" + v + "' is not a BOOL" : e);
        return false;
      }
      h->path = v;
      tc.cleared.push_back(*h);
    }
    tc.recovery = true;
  }
  return true;
}

}  // namespace plcfi::campaign
