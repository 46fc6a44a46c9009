// Textual SFC to ST; the rules are in sfc_lower.hpp.
#include "sfc_lower.hpp"

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>

namespace plcfi::st {

namespace {

// AST builders, every node at one location (the SFC element it comes from).
struct At {
  SourceLoc l;

  ExprPtr name(const std::string& n) const {
    auto e = std::make_unique<NameExpr>(l);
    e->name = Ident{n, l};
    return e;
  }
  ExprPtr field(const std::string& var, const std::string& f) const {
    auto e = std::make_unique<MemberExpr>(l);
    e->base = name(var);
    e->member = Ident{f, l};
    return e;
  }
  ExprPtr bin(BinaryOp op, ExprPtr a, ExprPtr b) const {
    auto e = std::make_unique<BinaryExpr>(l);
    e->op = op;
    e->lhs = std::move(a);
    e->rhs = std::move(b);
    return e;
  }
  ExprPtr and_(ExprPtr a, ExprPtr b) const { return bin(BinaryOp::And, std::move(a), std::move(b)); }
  ExprPtr or_(ExprPtr a, ExprPtr b) const { return bin(BinaryOp::Or, std::move(a), std::move(b)); }
  ExprPtr not_(ExprPtr a) const {
    auto e = std::make_unique<UnaryExpr>(l);
    e->op = UnaryOp::Not;
    e->operand = std::move(a);
    return e;
  }
  ExprPtr boolean(bool v) const {
    auto e = std::make_unique<LiteralExpr>(l);
    e->lit = LiteralKind::Bool;
    e->int_value = v ? 1 : 0;
    return e;
  }
  ExprPtr zero_time() const {
    auto e = std::make_unique<LiteralExpr>(l);
    e->lit = LiteralKind::Time;
    e->type_prefix = "T";
    return e;
  }
  ExprPtr now() const {
    auto e = std::make_unique<CallExpr>(l);
    e->callee = name("__NOW");
    return e;
  }
  StmtPtr assign(ExprPtr lhs, ExprPtr rhs) const {
    auto s = std::make_unique<AssignStmt>(l);
    s->lhs = std::move(lhs);
    s->rhs = std::move(rhs);
    return s;
  }
  // IF cond THEN then [ELSE otherwise]; `label` names the arm in coverage reports.
  StmtPtr when(ExprPtr cond, StmtList then, std::optional<StmtList> otherwise = std::nullopt,
               std::string label = {}) const {
    auto s = std::make_unique<IfStmt>(l);
    IfStmt::Arm arm;
    arm.cond = std::move(cond);
    arm.body = std::move(then);
    arm.loc = l;
    arm.label = std::move(label);
    s->arms.push_back(std::move(arm));
    if (otherwise) {
      s->else_body = std::move(otherwise);
      s->else_loc = l;
    }
    return s;
  }
  VarDecl decl(const std::string& n, const std::string& type, VarSection section, ExprPtr init = nullptr) const {
    VarDecl d;
    d.names.push_back(Ident{n, l});
    d.type = std::make_unique<TypeSpec>();
    d.type->kind = TypeSpecKind::Named;
    d.type->name = Ident{type, l};
    d.type->loc = l;
    d.init = std::move(init);
    d.section = section;
    d.loc = l;
    return d;
  }
};

StmtList one(StmtPtr s) {
  StmtList list;
  list.push_back(std::move(s));
  return list;
}

// The literal TRUE (BOOL#TRUE included).
bool is_true(const Expr& e) {
  if (e.kind != ExprKind::Literal) return false;
  const auto& lit = static_cast<const LiteralExpr&>(e);
  return lit.lit == LiteralKind::Bool && lit.int_value == 1;
}

// OR of the activity flags of `steps` (at least one).
ExprPtr any_active(const At& at, const std::vector<std::string>& steps) {
  ExprPtr e = at.field(steps.front(), "X");
  for (size_t i = 1; i < steps.size(); ++i) e = at.or_(std::move(e), at.field(steps[i], "X"));
  return e;
}

constexpr const char* kChart = "__SFC";
constexpr const char* kDt = "__sfc_dt";
constexpr const char* kNow = "__sfc_now";  // the clock, read once per scan

// One action and what the steps associate with it.
struct ActionUse {
  std::string var;            // the __SFC_ACTION variable
  std::string bool_var;       // a Boolean action: the variable it drives ("" for an ACTION)
  SourceLoc loc;              // the ACTION, or the first association of a Boolean action
  std::map<std::string, std::vector<std::string>> steps;  // qualifier -> steps (untimed)
  SfcAssociation* timed = nullptr;
  std::string timed_step;
};

class Lowering {
 public:
  Lowering(Pou& pou, DiagEngine& diags) : pou_(pou), chart_(*pou.sfc), diags_(diags) {}

  void run() {
    bool ok = check_steps();
    ok = collect_actions() && ok;
    ok = check_transitions() && ok;
    if (!ok) return;
    const At at{chart_.loc};
    VarBlock vars, temps;
    vars.loc = temps.loc = chart_.loc;
    temps.section = VarSection::Temp;
    for (const SfcStep& s : chart_.steps) {
      ExprPtr init;
      if (s.initial) {
        auto si = std::make_unique<StructInitExpr>(s.loc);
        si->items.push_back({Ident{"X", s.loc}, At{s.loc}.boolean(true)});
        init = std::move(si);
      }
      vars.decls.push_back(At{s.name.loc}.decl(s.name.text, "__SFC_STEP", VarSection::Var, std::move(init)));
    }
    for (const ActionUse& a : actions_) vars.decls.push_back(At{a.loc}.decl(a.var, "__SFC_ACTION", VarSection::Var));
    vars.decls.push_back(at.decl(kChart, "__SFC_CHART", VarSection::Var));
    temps.decls.push_back(at.decl(kDt, "TIME", VarSection::Temp));
    temps.decls.push_back(at.decl(kNow, "TIME", VarSection::Temp));
    for (size_t i = 0; i < chart_.transitions.size(); ++i) {
      const SfcTransition& t = chart_.transitions[i];
      temps.decls.push_back(At{t.loc}.decl(fired(i), "BOOL", VarSection::Temp));
      if (!t.condition_body.empty())  // an IL condition's value (parse_sfc.cpp names it)
        temps.decls.push_back(At{t.loc}.decl(static_cast<const NameExpr&>(*t.condition).name.text, "BOOL", VarSection::Temp));
    }
    pou_.var_blocks.push_back(std::move(vars));
    pou_.var_blocks.push_back(std::move(temps));

    StmtList& body = pou_.body;
    body.push_back(at.assign(at.name(kNow), at.now()));
    body.push_back(at.assign(at.name(kDt), at.zero_time()));
    StmtList evolve;
    evolve.push_back(at.assign(at.name(kDt), at.bin(BinaryOp::Sub, at.name(kNow), at.field(kChart, "last"))));
    for (const SfcStep& s : chart_.steps) {
      const At st{s.loc};
      evolve.push_back(st.when(st.field(s.name.text, "X"),
                               one(st.assign(st.field(s.name.text, "T"),
                                             st.bin(BinaryOp::Add, st.field(s.name.text, "T"), st.name(kDt)))),
                               std::nullopt, "step " + s.name.text + " active"));
    }
    lower_transitions(evolve);
    body.push_back(at.when(at.field(kChart, "started"), std::move(evolve), std::nullopt, "chart evolves"));
    body.push_back(at.assign(at.field(kChart, "started"), at.boolean(true)));
    body.push_back(at.assign(at.field(kChart, "last"), at.name(kNow)));
    for (const ActionUse& a : actions_) lower_control(a, body);
    for (const ActionUse& a : actions_) {
      if (a.bool_var.empty()) continue;
      const At aa{a.loc};
      auto s = std::make_unique<IfStmt>(a.loc);
      IfStmt::Arm on{aa.field(a.var, "Q"), one(aa.assign(aa.name(a.bool_var), aa.boolean(true))), a.loc,
                     "action " + a.bool_var + " active"};
      IfStmt::Arm final_scan{aa.field(a.var, "A"), one(aa.assign(aa.name(a.bool_var), aa.boolean(false))), a.loc,
                             "action " + a.bool_var + " final scan"};
      s->arms.push_back(std::move(on));
      s->arms.push_back(std::move(final_scan));
      body.push_back(std::move(s));
    }
    for (SfcAction& act : chart_.actions) lower_body(act, body);
  }

 private:
  static std::string fired(size_t i) { return "__sfc_t" + std::to_string(i); }

  // "transition Fill -> (Heat, Mix)", "transition Full (Fill -> Heat)" in coverage reports.
  static std::string describe(const SfcTransition& t) {
    const auto list = [](const std::vector<Ident>& steps) {
      std::string s = steps.size() == 1 ? "" : "(";
      for (size_t i = 0; i < steps.size(); ++i) s += (i ? ", " : "") + steps[i].text;
      return steps.size() == 1 ? s : s + ")";
    };
    const std::string arrow = list(t.from) + " -> " + list(t.to);
    return "transition " + (t.name ? t.name->text + " (" + arrow + ")" : arrow);
  }

  // An ACTION's body runs inline in the chart's call when the action is active. A RETURN
  // in it ends the action, not the chart, and its labels (IL) are its own: then the body
  // is entered past a jump to its end, RETURN becomes that jump, and its labels get the
  // action's name as a prefix.
  void lower_body(SfcAction& act, StmtList& out) {
    const At at{act.loc};
    if (!needs_jumps(act.body)) {
      out.push_back(at.when(at.field(act.name.text, "A"), std::move(act.body), std::nullopt, "action " + act.name.text + " runs"));
      return;
    }
    const std::string end = "__sfc_end_" + act.name.text;
    rewrite(act.body, act.name.text, end);
    out.push_back(at.when(at.not_(at.field(act.name.text, "A")), one(jump(end, act.loc)), std::nullopt,
                          "action " + act.name.text + " skipped"));
    for (auto& s : act.body) out.push_back(std::move(s));
    auto label = std::make_unique<LabelStmt>(act.loc);
    label->name = Ident{end, act.loc};
    label->from_il = true;
    out.push_back(std::move(label));
  }

  static StmtPtr jump(const std::string& label, SourceLoc loc) {
    auto j = std::make_unique<JumpStmt>(loc);
    j->label = Ident{label, loc};
    j->from_il = true;  // generated: allowed in every dialect
    return j;
  }

  // The statement lists nested in s (IF arms, CASE arms, loop bodies).
  template <class F>
  static void for_each_list(Stmt& s, F&& f) {
    switch (s.kind) {
      case StmtKind::If: {
        auto& x = static_cast<IfStmt&>(s);
        for (auto& arm : x.arms) f(arm.body);
        if (x.else_body) f(*x.else_body);
        break;
      }
      case StmtKind::Case: {
        auto& x = static_cast<CaseStmt&>(s);
        for (auto& arm : x.arms) f(arm.body);
        if (x.else_body) f(*x.else_body);
        break;
      }
      case StmtKind::For: f(static_cast<ForStmt&>(s).body); break;
      case StmtKind::While: f(static_cast<WhileStmt&>(s).body); break;
      case StmtKind::Repeat: f(static_cast<RepeatStmt&>(s).body); break;
      default: break;
    }
  }

  static bool needs_jumps(StmtList& list) {
    for (auto& s : list) {
      if (s->kind == StmtKind::Return || s->kind == StmtKind::Label || s->kind == StmtKind::Jump) return true;
      bool nested = false;
      for_each_list(*s, [&](StmtList& l) { nested = nested || needs_jumps(l); });
      if (nested) return true;
    }
    return false;
  }

  static void rewrite(StmtList& list, const std::string& action, const std::string& end) {
    for (auto& s : list) {
      if (s->kind == StmtKind::Return) {
        s = jump(end, s->loc);
      } else if (s->kind == StmtKind::Label) {
        auto& l = static_cast<LabelStmt&>(*s);
        l.hidden_prefix = ("__sfc_" + action + "_").size();
        l.name.text = "__sfc_" + action + "_" + l.name.text;
      } else if (s->kind == StmtKind::Jump && static_cast<JumpStmt&>(*s).label.text != end) {
        auto& j = static_cast<JumpStmt&>(*s);
        j.hidden_prefix = ("__sfc_" + action + "_").size();
        j.label.text = "__sfc_" + action + "_" + j.label.text;
      }
      for_each_list(*s, [&](StmtList& l) { rewrite(l, action, end); });
    }
  }

  // A step or ACTION is a variable of the POU: its name cannot be one of the POU's own.
  bool clashes(const Ident& name, const char* kind) {
    for (const VarBlock& b : pou_.var_blocks)
      for (const VarDecl& d : b.decls)
        for (const Ident& n : d.names)
          if (iequals(n.text, name.text)) {
            Diagnostic& e = diags_.error("ST141", name.loc, std::string(kind) + " '" + name.text +
                                                                "' has the name of a variable of " + what() +
                                                                " (names are case-insensitive)");
            e.notes.emplace_back(n.loc, "the variable is declared here");
            return true;
          }
    return false;
  }

  bool check_steps() {
    bool ok = true, initial = false;
    for (const SfcStep& s : chart_.steps) {
      initial |= s.initial;
      if (clashes(s.name, "step")) ok = false;
      if (!steps_.emplace(canon(s.name.text), &s).second) {
        diags_.error("ST141", s.name.loc, "step '" + s.name.text + "' is declared twice in " + what());
        ok = false;
      }
    }
    if (!initial) {
      diags_.error("ST141", chart_.loc, what() + " has no INITIAL_STEP: the chart needs one to start from");
      ok = false;
    }
    return ok;
  }

  bool check_transitions() {
    bool ok = true;
    for (const SfcTransition& t : chart_.transitions) {
      for (const auto* list : {&t.from, &t.to})
        for (const Ident& s : *list)
          if (!steps_.count(canon(s.text))) {
            diags_.error("ST141", s.loc, "transition " + std::string(list == &t.from ? "from" : "to") +
                                             " an unknown step '" + s.text + "' in " + what());
            ok = false;
          }
      if (!t.condition) ok = false;  // reported by the parser
    }
    return ok;
  }

  // The ACTIONs in declaration order, then the Boolean actions in order of first use.
  bool collect_actions() {
    bool ok = true;
    std::map<std::string, size_t> index;
    for (const SfcAction& a : chart_.actions) {
      const std::string key = canon(a.name.text);
      if (steps_.count(key)) {
        diags_.error("ST141", a.name.loc, "action '" + a.name.text + "' has the name of a step of " + what());
        ok = false;
      } else if (clashes(a.name, "action")) {
        ok = false;
      } else if (!index.emplace(key, actions_.size()).second) {
        diags_.error("ST141", a.name.loc, "action '" + a.name.text + "' is declared twice in " + what());
        ok = false;
        continue;
      }
      actions_.push_back(ActionUse{a.name.text, "", a.loc, {}, nullptr, ""});
    }
    for (SfcStep& s : chart_.steps) {
      for (SfcAssociation& as : s.actions) {
        const std::string key = canon(as.action.text);
        auto it = index.find(key);
        if (it == index.end()) {
          it = index.emplace(key, actions_.size()).first;
          actions_.push_back(ActionUse{"__sfc_" + as.action.text, as.action.text, as.loc, {}, nullptr, ""});
        }
        ActionUse& use = actions_[it->second];
        const bool timed = as.qualifier == "L" || as.qualifier == "D" || as.qualifier == "SD" ||
                           as.qualifier == "DS" || as.qualifier == "SL";
        if (!timed) {
          use.steps[as.qualifier == "P1" ? "P" : as.qualifier].push_back(s.name.text);
          continue;
        }
        if (!as.time) {
          ok = false;  // reported by the parser
        } else if (use.timed) {
          Diagnostic& d = diags_.error(
              "ST142", as.qualifier_loc,
              "action '" + as.action.text + "' has a second timed association (" + as.qualifier + " in step '" +
                  s.name.text + "'): an action control has one timer, so an action takes one of L, D, SD, DS "
                                "and SL; give each a separate action");
          d.notes.emplace_back(use.timed->qualifier_loc, "the first timed association");
          ok = false;
        } else {
          use.timed = &as;
          use.timed_step = s.name.text;
        }
      }
    }
    return ok;
  }

  // Transitions in priority order; see sfc_lower.hpp.
  void lower_transitions(StmtList& out) {
    std::vector<size_t> order(chart_.transitions.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    const auto key = [&](size_t i) { return chart_.transitions[i].priority.value_or(INT64_MAX); };
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
    for (size_t i : order) {
      SfcTransition& t = chart_.transitions[i];
      const At at{t.loc};
      ExprPtr enabled;
      StmtList fire;
      fire.push_back(at.assign(at.name(fired(i)), at.boolean(true)));
      for (const Ident& s : t.from) {
        ExprPtr x = at.field(s.text, "X");
        enabled = enabled ? at.and_(std::move(enabled), std::move(x)) : std::move(x);
        fire.push_back(at.assign(at.field(s.text, "X"), at.boolean(false)));
      }
      out.push_back(at.assign(at.name(fired(i)), at.boolean(false)));
      // `:= TRUE` (an unconditional transition, e.g. after a one-scan step) fires whenever
      // its steps are active: no IF on a constant condition (warning ST404).
      StmtList test = std::move(t.condition_body);  // an IL condition's instructions first
      const std::string name = describe(t);
      if (is_true(*t.condition)) {
        for (auto& f : fire) test.push_back(std::move(f));
      } else {
        test.push_back(at.when(std::move(t.condition), std::move(fire), std::nullopt, name + " fires"));
      }
      out.push_back(at.when(std::move(enabled), std::move(test), std::nullopt, name + " enabled"));
    }
    for (size_t i = 0; i < chart_.transitions.size(); ++i) {
      const SfcTransition& t = chart_.transitions[i];
      const At at{t.loc};
      StmtList enter;
      for (const Ident& s : t.to) {
        enter.push_back(at.assign(at.field(s.text, "X"), at.boolean(true)));
        enter.push_back(at.assign(at.field(s.text, "T"), at.zero_time()));
      }
      out.push_back(at.when(at.name(fired(i)), std::move(enter), std::nullopt, describe(t) + " enters its steps"));
    }
  }

  // The action control block of one action (IEC 61131-3), from the active steps.
  void lower_control(const ActionUse& a, StmtList& out) {
    const At at{a.loc};
    const auto f = [&](const char* name) { return at.field(a.var, name); };
    const auto steps = [&](const char* q) -> const std::vector<std::string>* {
      auto it = a.steps.find(q);
      return it == a.steps.end() ? nullptr : &it->second;
    };
    // Without an R association the reset is constant FALSE: no variable, no test.
    const bool has_r = steps("R") != nullptr;
    if (has_r) out.push_back(at.assign(f("__r"), any_active(at, *steps("R"))));
    const auto unreset = [&](ExprPtr e) { return has_r ? at.and_(at.not_(f("__r")), std::move(e)) : std::move(e); };
    ExprPtr q = steps("N") ? any_active(at, *steps("N")) : at.boolean(false);
    if (const auto* s = steps("S")) {  // S_FF: RS with the reset dominant
      out.push_back(at.assign(f("__s"), unreset(at.or_(f("__s"), any_active(at, *s)))));
      q = at.or_(std::move(q), f("__s"));
    }
    if (const auto* p = steps("P")) {  // P_TRIG: the rising edge of the association
      out.push_back(at.assign(f("__p"), at.and_(any_active(at, *p), at.not_(f("__pm")))));
      out.push_back(at.assign(f("__pm"), any_active(at, *p)));
      q = at.or_(std::move(q), f("__p"));
    }
    if (const auto* p = steps("P0")) {  // the falling edge
      out.push_back(at.assign(f("__p0"), at.and_(at.not_(any_active(at, *p)), f("__p0m"))));
      out.push_back(at.assign(f("__p0m"), any_active(at, *p)));
      q = at.or_(std::move(q), f("__p0"));
    }
    if (a.timed) q = at.or_(std::move(q), lower_timed(a, out));
    out.push_back(at.assign(f("Q"), unreset(std::move(q))));
    out.push_back(at.assign(f("A"), at.or_(f("Q"), f("__qprev"))));
    out.push_back(at.assign(f("__qprev"), f("Q")));
  }

  // The timer of an L, D, SD, DS or SL association (a TON counted in the chart's clock)
  // and its flip-flop; returns the association's share of Q.
  ExprPtr lower_timed(const ActionUse& a, StmtList& out) {
    SfcAssociation& as = *a.timed;
    const At at{as.loc};
    const auto f = [&](const char* name) { return at.field(a.var, name); };
    const std::string& q = as.qualifier;
    const bool has_r = a.steps.count("R") > 0;
    const auto flip_flop = [&](ExprPtr set) {  // RS, reset dominant
      ExprPtr v = at.or_(f("__ff"), std::move(set));
      out.push_back(at.assign(f("__ff"), has_r ? at.and_(at.not_(f("__r")), std::move(v)) : std::move(v)));
    };
    // The timer's input.
    if (q == "SD" || q == "SL") flip_flop(at.field(a.timed_step, "X"));
    const auto timer_in = [&]() { return q == "SD" || q == "SL" ? f("__ff") : at.field(a.timed_step, "X"); };
    StmtList running;
    const std::string what = "action " + as.action.text + " " + q + " timer";
    running.push_back(at.when(f("__run"), one(at.assign(f("__et"), at.bin(BinaryOp::Add, f("__et"), at.name(kDt)))),
                              std::nullopt, what + " counts"));
    out.push_back(at.when(timer_in(), std::move(running), one(at.assign(f("__et"), at.zero_time())), what + " on"));
    out.push_back(at.assign(f("__run"), timer_in()));
    out.push_back(at.assign(f("__tq"), at.and_(timer_in(), at.bin(BinaryOp::Ge, f("__et"), std::move(as.time)))));
    if (q == "L") return at.and_(at.field(a.timed_step, "X"), at.not_(f("__tq")));
    if (q == "D" || q == "SD") return f("__tq");
    if (q == "DS") {
      flip_flop(f("__tq"));
      return f("__ff");
    }
    return at.and_(f("__ff"), at.not_(f("__tq")));  // SL
  }

  std::string what() const {
    return std::string(pou_.kind == PouKind::FunctionBlock ? "FUNCTION_BLOCK" : "PROGRAM") + " '" + pou_.name.text + "'";
  }

  Pou& pou_;
  SfcChart& chart_;
  DiagEngine& diags_;
  std::map<std::string, const SfcStep*> steps_;
  std::vector<ActionUse> actions_;
};

}  // namespace

void lower_sfc(Pou& pou, DiagEngine& diags) {
  if (!pou.sfc || (pou.kind != PouKind::Program && pou.kind != PouKind::FunctionBlock)) return;
  Lowering(pou, diags).run();
}

}  // namespace plcfi::st
