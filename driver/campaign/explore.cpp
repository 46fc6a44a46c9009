// Fault-space exploration: explored cases, the explore program, the oracle, FMEA suggestions.
#include "explore.hpp"

#include <algorithm>
#include <cctype>
#include <set>

#include <fmt/format.h>

#include "common/csv.hpp"

namespace plcfi::campaign {

namespace {

using common::csv_field;

constexpr const char* kExploreProgram = "__FI_EXPLORE";
constexpr size_t kExploreHeaderLines = 2;  // PROGRAM and VAR_OUTPUT lines
// The FAIL reason's part that names alarms that rose without the class's reaction.
constexpr const char* kAlarmsUp = "; alarms up, not the class's reaction: ";

bool is_bool(const st::Type* t) { return t && t->kind == st::TypeKind::Bool; }

// Does the program's code load (reads) or store (!reads) the bytes [addr, addr + size),
// bit `bit` of a bit location? Direct global accesses only (LDG*, LDBIT, STG*, STBIT).
bool program_accesses(const st::Application& app, uint32_t addr, uint32_t size, bool is_bit, uint8_t bit, bool reads) {
  auto overlaps = [&](uint32_t a, uint32_t n) { return a < addr + size && addr < a + n; };
  const std::vector<uint32_t>& code = app.code;
  for (size_t pc = 0; pc < code.size();) {
    const uint32_t* w = &code[pc];
    auto op = static_cast<st::Op>(w[0]);
    size_t len = st::op_length(w);  // the opcode word included
    if (pc + len > code.size()) break;
    switch (op) {
      case st::Op::LDG1: if (reads && overlaps(w[2], 1)) return true; break;
      case st::Op::LDG2: if (reads && overlaps(w[2], 2)) return true; break;
      case st::Op::LDG4: if (reads && overlaps(w[2], 4)) return true; break;
      case st::Op::LDG8: if (reads && overlaps(w[2], 8)) return true; break;
      case st::Op::LDGN: if (reads && overlaps(w[2], w[3])) return true; break;
      case st::Op::LDBIT: if (reads && overlaps(w[2], 1) && (!is_bit || w[3] == bit)) return true; break;
      case st::Op::STG1: if (!reads && overlaps(w[1], 1)) return true; break;
      case st::Op::STG2: if (!reads && overlaps(w[1], 2)) return true; break;
      case st::Op::STG4: if (!reads && overlaps(w[1], 4)) return true; break;
      case st::Op::STG8: if (!reads && overlaps(w[1], 8)) return true; break;
      case st::Op::STGN: if (!reads && overlaps(w[1], w[3])) return true; break;
      case st::Op::STBIT: if (!reads && overlaps(w[1], 1) && (!is_bit || w[2] == bit)) return true; break;
      default: break;
    }
    pc += len;
  }
  return false;
}

// The identifiers of an ST expression (enough to see which lifelines it names).
std::set<std::string> identifiers(const std::string& text) {
  std::set<std::string> out;
  for (size_t i = 0; i < text.size();) {
    unsigned char ch = static_cast<unsigned char>(text[i]);
    if (std::isalpha(ch) || ch == '_') {
      size_t j = i;
      while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_' || text[j] == '.')) ++j;
      out.insert(st::canon(text.substr(i, j - i)));
      i = j;
    } else {
      ++i;
    }
  }
  return out;
}

bool parse_model(const std::string& text, faults::FaultSpec* f) {
  std::string e;
  uint32_t col = 0;
  return faults::parse_fault(text, f, &e, &col);
}

std::string substitute(std::string text, const std::map<std::string, std::string>& vars) {
  for (const auto& [k, v] : vars) {
    std::string key = "{" + k + "}";
    for (size_t p = text.find(key); p != std::string::npos; p = text.find(key, p + v.size())) text.replace(p, key.size(), v);
  }
  return text;
}

}  // namespace

std::vector<const Lifeline*> explore_signals(const Campaign& c, const st::Application& program, const Step& step) {
  std::set<std::string> named;
  for (const auto& ps : step.pre) named.insert(ps.lifeline);
  for (const auto& t : step.transitions) named.insert(t.lifeline);
  std::set<std::string> ids = identifiers(step.start + " " + step.condition);
  std::vector<const Lifeline*> out;
  for (const auto& l : c.tsd.lifelines) {
    if (l.kind != LifelineKind::Sensor && l.kind != LifelineKind::Actuator && l.kind != LifelineKind::Analog) continue;
    rt::ImageRef ref;
    std::string e;
    if (!rt::parse_image_ref(program, l.bind, &ref, &e)) continue;  // not I/O: no fault can act on it
    const st::ImageArea* area = program.image(ref.area);
    if (!area) continue;
    uint32_t addr = area->addr + ref.offset;
    if (ref.area == 'I') {
      bool in_step = named.count(l.name) || ids.count(st::canon(l.name)) || ids.count(st::canon(l.bind));
      if (in_step && program_accesses(program, addr, ref.size, ref.is_bit, ref.bit, true)) out.push_back(&l);
    } else if (program_accesses(program, addr, ref.size, ref.is_bit, ref.bit, false)) {
      out.push_back(&l);
    }
  }
  return out;
}

std::vector<std::string> explore_fault_models(const Lifeline& l, const rt::ImageRef& ref) {
  bool b = is_bool(ref.type) || ref.is_bit;
  if (ref.area == 'I') {
    if (b) return {"stuck_at(0)", "stuck_at(1)"};
    int64_t d = l.tolerance > 0 ? static_cast<int64_t>(l.tolerance * 10) : 100;
    return {"frozen", fmt::format("offset({})", d), "stuck_at(0)"};
  }
  if (b) return {"no_effect", "stuck_on", "stuck_off"};
  return {"no_effect", "stuck_off"};
}

std::string equivalent_fault(const Step& step, const Lifeline& l, const rt::ImageRef& ref, const faults::FaultSpec& f) {
  bool b = is_bool(ref.type) || ref.is_bit;
  if (f.kind == faults::Kind::StuckCurrent || f.kind == faults::Kind::Frozen) {
    if (!b) return "frozen";
    // The value the lifeline has when the step's precondition holds.
    for (const auto& ps : step.pre)
      if (ps.lifeline == l.name) {
        std::string v = st::canon(ps.value);
        if (v == "TRUE" || v == "1") return "stuck_at(1)";
        if (v == "FALSE" || v == "0") return "stuck_at(0)";
      }
    for (const auto& t : step.transitions)
      if (t.lifeline == l.name) {
        std::string v = st::canon(t.to);
        if (v == "TRUE" || v == "1") return "stuck_at(0)";
        if (v == "FALSE" || v == "0") return "stuck_at(1)";
      }
  }
  if (f.kind == faults::Kind::OpenWire && b) return "stuck_at(0)";
  faults::FaultSpec canon;
  return parse_model(f.text, &canon) ? canon.text : f.text;
}

bool add_explored_cases(CampaignBuild* cb, const st::Application& program, const std::map<std::string, st::VarHandle>& binds,
                        std::vector<TestCase>* cases, std::string* err) {
  const Campaign& c = cb->spec;
  ExplorePlan& plan = cb->explore;

  // The step table and, per step, its precondition and start as ST.
  std::vector<std::string> pre_text, start_text, tr_text;
  std::vector<const Loc*> pre_loc, start_loc, tr_loc;
  for (const auto& sc : c.tsd.scenarios) {
    size_t first = plan.steps.size();
    for (const auto& s : sc.steps) {
      ExploreStep es;
      es.scenario = &sc;
      es.step = &s;
      es.first_transition = tr_text.size();
      std::string expr, human;
      for (const auto& ps : s.pre) {
        const Lifeline* l = c.tsd.find(ps.lifeline);
        expr += (expr.empty() ? "" : " AND ") + lifeline_state(*l, binds.at(l->name), ps.value, l->tolerance, &human);
      }
      if (!s.condition.empty()) expr += " AND (" + s.condition + ")";
      pre_text.push_back(expr.empty() ? "TRUE" : expr);
      pre_loc.push_back(s.pre.empty() ? &s.loc : &s.pre.front().loc);
      start_text.push_back(s.start.empty() ? "TRUE" : "(" + s.start + ")");
      start_loc.push_back(s.start.empty() ? &s.loc : &s.start_loc);
      for (const auto& t : s.transitions) {
        const Lifeline* l = c.tsd.find(t.lifeline);
        tr_text.push_back(lifeline_state(*l, binds.at(l->name), t.to, t.tolerance >= 0 ? t.tolerance : l->tolerance, &human));
        tr_loc.push_back(&t.loc);
        es.window_ns = std::max(es.window_ns, t.max_ns);
      }
      plan.steps.push_back(es);
    }
    for (size_t k = first; k < plan.steps.size(); ++k) plan.steps[k].last_of_scenario = plan.steps.size() - 1;
  }

  // The FMEA's cases, for deduplication and the classes of lifelines.
  std::set<std::string> known;  // "scenario.step|lifeline|fault"
  // lifeline -> class and alarm of the first FMEA row (file order) faulting it (values:
  // *cases grows below)
  std::map<std::string, std::pair<const FaultClass*, std::string>> class_of;
  for (const auto& tc : *cases)
    known.insert(tc.scenario->id + "." + tc.step->id + "|" + tc.target->name + "|" +
                 equivalent_fault(*tc.step, *tc.target, tc.target_ref, tc.fault));
  for (const auto& r : c.fmea.rows)
    for (const auto& tc : *cases)
      if (tc.row == &r && !class_of.count(tc.target->name)) class_of[tc.target->name] = {tc.cls, r.alarm};
  std::string any_alarm;
  std::set<std::string> alarms_seen;
  for (const auto& r : c.fmea.rows)
    if (alarms_seen.insert(r.alarm).second) {
      any_alarm += (any_alarm.empty() ? "" : " OR ") + r.alarm;
      std::string e;
      if (auto h = st::resolve(program, r.alarm, &e)) {
        h->path = r.alarm;
        plan.alarms.push_back(*h);
      }
    }
  if (alarms_seen.size() > 1) any_alarm = "(" + any_alarm + ")";

  // The explored cases.
  std::vector<std::string> det_text;
  size_t n = 0;
  for (size_t si = 0; si < plan.steps.size(); ++si) {
    const ExploreStep& es = plan.steps[si];
    if (es.step->transitions.empty()) continue;  // nothing expected: nothing to test
    for (const Lifeline* l : explore_signals(c, program, *es.step)) {
      rt::ImageRef ref;
      std::string e;
      rt::parse_image_ref(program, l->bind, &ref, &e);  // explore_signals took only I/O lifelines
      ref.text = address_text(ref);
      const FaultClass* cls = nullptr;
      std::string alarm;
      auto it = class_of.find(l->name);
      if (it != class_of.end()) {
        cls = it->second.first;
        alarm = it->second.second;
      } else if (!c.explore.default_class.empty()) {
        cls = c.classes.find(c.explore.default_class);
        alarm = any_alarm;
        if (alarm.empty()) {
          *err = c.explore.loc.str() + ": explore: the FMEA names no alarm, so a detection of a failure of " + l->name +
                 " cannot be checked";
          return false;
        }
      }
      if (!cls) {
        *err = c.explore.loc.str() + ": explore: no FMEA row gives a fault class to lifeline " + l->name + " (faulted in " +
               es.scenario->id + "." + es.step->id + "); name one with explore: {default_class: ID}";
        return false;
      }
      for (const std::string& model : explore_fault_models(*l, ref)) {
        TestCase tc;
        tc.explored = true;
        tc.explore_step = si;
        tc.scenario = es.scenario;
        tc.step = es.step;
        tc.transition = &es.step->transitions.front();
        for (const auto& t : es.step->transitions)
          if (t.lifeline == l->name) tc.transition = &t;
        tc.cls = cls;
        tc.precondition = pre_text[si];
        tc.start = es.step->start.empty() ? "TRUE" : es.step->start;
        tc.target = l;
        tc.target_ref = ref;
        uint32_t col = 0;
        if (!faults::parse_fault(model, &tc.fault, &e, &col)) {
          *err = "internal: explored fault model '" + model + "': " + e;
          return false;
        }
        faults::InjectionContext ctx;
        ctx.ref = ref;
        ctx.tick_ns = 10'000'000;
        if (!faults::make_rule(tc.fault, ctx, &e)) continue;  // the model does not fit this location
        std::string key = es.scenario->id + "." + es.step->id + "|" + l->name + "|" + equivalent_fault(*es.step, *l, ref, tc.fault);
        if (!known.insert(key).second) continue;
        FmeaRow row;
        row.transition = es.scenario->id + "." + es.step->id + "." + tc.transition->lifeline;
        row.failure_mode = l->name + " " + tc.fault.text;
        row.fault_class = cls->id;
        row.alarm = alarm;
        row.fault_model = l->name + ": " + tc.fault.text;
        cb->explored_rows.push_back(row);
        tc.row = &cb->explored_rows.back();
        tc.deadline_ns = es.window_ns + cls->reaction_time_ns;
        tc.max_duration_ns = cls->max_duration_ns;
        tc.id = fmt::format("X{}", ++n);
        // Detection: the class's reaction formulas, ANDed (the alarm itself when none).
        std::map<std::string, std::string> vars = {{"alarm", alarm},
                                                   {"start", tc.start},
                                                   {"deadline", st_duration(tc.deadline_ns)},
                                                   {"signal", l->bind}};
        std::string det;
        for (const auto& cr : cls->requirements)
          if (!cr.reaction.text.empty() && cr.reaction.text != "TRUE")
            det += (det.empty() ? "" : " AND ") + ("(" + substitute(cr.reaction.text, vars) + ")");
        det_text.push_back(det.empty() ? alarm : det);
        cases->push_back(std::move(tc));
      }
    }
  }

  // The program the oracle reads after each scan.
  auto dim = [](size_t k) { return k == 0 ? size_t{0} : k - 1; };
  std::string src = fmt::format("PROGRAM {}\nVAR_OUTPUT pre : ARRAY[0..{}] OF BOOL; start : ARRAY[0..{}] OF BOOL; "
                                "tr : ARRAY[0..{}] OF BOOL; det : ARRAY[0..{}] OF BOOL; END_VAR\n",
                                kExploreProgram, dim(pre_text.size()), dim(start_text.size()), dim(tr_text.size()),
                                dim(det_text.size()));
  std::vector<st::LineOrigin> origins(kExploreHeaderLines);
  auto line = [&](const std::string& text, const Loc* at, const std::string& context) {
    src += text + "\n";
    st::LineOrigin o;
    if (at) {
      o.path = at->file;
      o.line = at->line;
      o.col = at->col;
    }
    o.exact_columns = false;
    o.context = context;
    origins.push_back(std::move(o));
  };
  for (size_t k = 0; k < pre_text.size(); ++k) {
    const ExploreStep& es = plan.steps[k];
    std::string where = es.scenario->id + "." + es.step->id;
    line(fmt::format("pre[{}] := {};", k, pre_text[k]), pre_loc[k], "in the precondition of " + where + " (explored)");
    line(fmt::format("start[{}] := {};", k, start_text[k]), start_loc[k], "in the start of " + where + " (explored)");
  }
  for (size_t k = 0; k < tr_text.size(); ++k) line(fmt::format("tr[{}] := {};", k, tr_text[k]), tr_loc[k], "in a transition (explored)");
  const Loc* classes_loc = c.explore.class_loc.line ? &c.explore.class_loc : &c.explore.loc;
  for (size_t k = 0; k < det_text.size(); ++k)
    line(fmt::format("det[{}] := {};", k, det_text[k]), classes_loc, "in the reaction of an explored case's fault class");
  src += "END_PROGRAM\n";
  plan.source = std::move(src);
  plan.origins = std::move(origins);
  return true;
}

bool bind_explore(CampaignBuild* cb, std::string* err) {
  const st::Application& app = *cb->build->app;
  for (const auto& o : app.observers)
    if (o.name == kExploreProgram) {
      ExplorePlan& p = cb->explore;
      p.entry = o.pou->entry;
      p.addr = o.addr;
      const st::Symbol* syms[4] = {o.pou->find_var("pre"), o.pou->find_var("start"), o.pou->find_var("tr"), o.pou->find_var("det")};
      uint32_t* dst[4] = {&p.pre, &p.start, &p.tr, &p.det};
      for (int k = 0; k < 4; ++k) {
        if (!syms[k]) break;
        *dst[k] = o.addr + syms[k]->offset;
      }
      if (syms[0] && syms[1] && syms[2] && syms[3]) return true;
    }
  *err = "internal: the explore program is missing from the build";
  return false;
}

ExploreOracle::ExploreOracle(const CampaignBuild& cb, size_t case_index, int64_t inject_ns)
    : cb_(cb), tc_(cb.cases[case_index]), inject_ns_(inject_ns), step_(tc_.explore_step) {
  size_t first = 0;
  while (first < cb.cases.size() && !cb.cases[first].explored) ++first;
  det_ = case_index - first;
  due_ns_ = inject_ns;
  phase_ = Phase::AwaitStart;  // the faulted step's precondition held at the injection
}

std::string ExploreOracle::rel(int64_t t) const { return human_duration(t - inject_ns_); }

void ExploreOracle::deviate(int64_t bound_ns, std::string what) {
  if (deviation_ns_ >= 0) return;
  deviation_ns_ = bound_ns;
  detect_by_ns_ = bound_ns + tc_.cls->reaction_time_ns;
  deviation_ = std::move(what);
}

ExploreOracle::State ExploreOracle::tolerated(int64_t now) {
  const ExploreStep& first = cb_.explore.steps[tc_.explore_step];
  state_ = State::Tolerated;
  reason_ = fmt::format("tolerated: every transition of {}.{} and of the scenario's later steps in time (scenario done at +{})",
                        first.scenario->id, first.step->id, rel(now));
  verdict_ns_ = now;
  return state_;
}

ExploreOracle::State ExploreOracle::step(st::Machine& m, int64_t now) {
  if (state_ != State::Open) return state_;
  const ExplorePlan& plan = cb_.explore;
  if (!m.call(plan.entry, plan.addr)) {
    state_ = State::Failed;
    reason_ = "the oracle's program trapped: " + m.trap().message;
    return state_;
  }
  const uint8_t* mem = m.mem();
  if (mem[plan.det + det_]) {
    if (deviation_ns_ < 0 || now <= detect_by_ns_) {
      state_ = State::Detected;
      reason_ = deviation_ns_ < 0 ? fmt::format("detected: {} at +{}, before any deviation from the TSD", tc_.row->alarm, rel(now))
                                  : fmt::format("detected: {} at +{}, within {} of the deviation ({})", tc_.row->alarm,
                                                rel(now), human_duration(tc_.cls->reaction_time_ns), deviation_);
      verdict_ns_ = now;
      return state_;
    }
  }
  if (deviation_ns_ >= 0) {
    if (now > detect_by_ns_) {
      std::string up;
      for (const auto& h : plan.alarms)
        if (st::read_bool(m, h)) up += (up.empty() ? "" : ", ") + h.path;
      state_ = State::Failed;
      reason_ = deviation_ + (up.empty() ? "; no alarm" : kAlarmsUp + up);
      verdict_ns_ = now;
    }
    return state_;
  }
  // Follow the TSD from the faulted step on.
  while (true) {
    const ExploreStep& es = plan.steps[step_];
    const std::string where = es.scenario->id + "." + es.step->id;
    if (phase_ == Phase::AwaitPre && es.step->transitions.empty()) {
      // A later step that expects nothing has nothing to check: as if it ran.
      if (step_ == es.last_of_scenario) {
        return tolerated(now);
      }
      ++step_;
      continue;
    }
    if (phase_ == Phase::AwaitPre) {
      if (!mem[plan.pre + step_]) break;
      phase_ = Phase::AwaitStart;
    }
    if (phase_ == Phase::AwaitStart) {
      if (!mem[plan.start + step_]) break;
      phase_ = Phase::Running;
      start_ns_ = now;
      reached_.assign(es.step->transitions.size(), -1);
    }
    bool all = true;
    for (size_t k = 0; k < es.step->transitions.size(); ++k) {
      const Transition& t = es.step->transitions[k];
      if (reached_[k] < 0 && mem[plan.tr + es.first_transition + k]) {
        reached_[k] = now;
        if (t.min_ns >= 0 && now - start_ns_ < t.min_ns) {
          deviate(start_ns_ + t.max_ns, fmt::format("transition {}.{} too early: after {} of its min {} (at +{})", where, t.lifeline,
                                                    human_duration(now - start_ns_), human_duration(t.min_ns), rel(now)));
          return state_;
        }
      }
      all = all && reached_[k] >= 0;
    }
    if (!all) break;
    if (step_ == es.last_of_scenario) {
      return tolerated(now);
    }
    ++step_;
    phase_ = Phase::AwaitPre;
    due_ns_ = now;
  }
  // Bounds of the step under way.
  const ExploreStep& es = plan.steps[step_];
  const std::string where = es.scenario->id + "." + es.step->id;
  if (phase_ != Phase::Running) {
    if (now - due_ns_ > es.window_ns)
      deviate(due_ns_ + es.window_ns,
              fmt::format("step {} not begun within {} ({} never held)", where, human_duration(es.window_ns),
                          phase_ == Phase::AwaitPre ? "its precondition" : "its start condition"));
    return state_;
  }
  for (size_t k = 0; k < es.step->transitions.size(); ++k) {
    const Transition& t = es.step->transitions[k];
    if (reached_[k] < 0 && now - start_ns_ > t.max_ns) {
      deviate(start_ns_ + t.max_ns,
              fmt::format("transition {}.{} not within {} (to {})", where, t.lifeline, human_duration(t.max_ns), t.to));
      break;
    }
  }
  return state_;
}

std::vector<FmeaSuggestion> fmea_suggestions(const CampaignBuild& cb, const std::vector<Execution>& executions) {
  std::vector<FmeaSuggestion> out;
  std::set<size_t> seen;
  std::vector<const Execution*> fails;
  for (const auto& e : executions)
    if (e.outcome == Outcome::Fail && e.case_index < cb.cases.size() && cb.cases[e.case_index].explored &&
        seen.insert(e.case_index).second)
      fails.push_back(&e);
  std::sort(fails.begin(), fails.end(), [](const Execution* a, const Execution* b) { return a->case_index < b->case_index; });
  for (const Execution* e : fails) {
    const TestCase& tc = cb.cases[e->case_index];
    FmeaSuggestion s;
    s.case_id = tc.id;
    s.component = tc.target->name;
    s.transition = tc.row->transition;
    s.failure_mode = tc.row->failure_mode;
    s.effect = e->reason;
    s.detection = "none";
    size_t p = e->reason.find(kAlarmsUp);
    if (p != std::string::npos) {
      s.detection = e->reason.substr(p + std::string(kAlarmsUp).size());
      s.effect = e->reason.substr(0, p);
    } else if (s.effect.size() > 10 && s.effect.compare(s.effect.size() - 10, 10, "; no alarm") == 0) {
      s.effect.resize(s.effect.size() - 10);
    }
    s.fault_class = tc.cls->id;
    // A default class's "any alarm" is no variable: the user names the alarm to raise.
    s.alarm = tc.row->alarm.find(' ') == std::string::npos ? tc.row->alarm : "";
    s.fault_model = tc.row->fault_model;
    out.push_back(std::move(s));
  }
  return out;
}

std::string fmea_suggestions_csv(const std::vector<FmeaSuggestion>& s) {
  std::string o = "id,tsd_transition,failure_mode,S,effect,cause,O,detection,D,RPN,fault_class,alarm,fault_model\n";
  for (const auto& x : s)
    o += fmt::format("{},{},{},,{},{},,{},,,{},{},{}\n", csv_field(x.case_id), csv_field(x.transition), csv_field(x.failure_mode),
                     csv_field(x.effect), csv_field("found by plcfi campaign --explore"), csv_field(x.detection),
                     csv_field(x.fault_class), csv_field(x.alarm), csv_field(x.fault_model));
  return o;
}

}  // namespace plcfi::campaign
