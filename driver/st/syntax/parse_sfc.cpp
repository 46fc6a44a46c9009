// Textual Sequential Function Chart elements (IEC 61131-3, the textual form of SFC):
//
//   INITIAL_STEP name ':' {association ';'} END_STEP
//   STEP name ':' {association ';'} END_STEP
//   association := action '(' [qualifier [',' duration]] {',' indicator} ')'
//   TRANSITION [name] ['(' PRIORITY ':=' integer ')'] FROM steps TO steps
//     (':=' expr ';' | ':' IL instructions) END_TRANSITION
//   (an importer's line may give a named transition ':' ST statements that set its name)
//   steps := name | '(' name {',' name} ')'
//   ACTION name ':' (stmt_list | IL instructions) END_ACTION
//
// The words are not reserved in ST: they are recognised by what follows them. The chart
// is lowered into ST when its POU ends (sfc_lower.hpp).
#include "parser_impl.hpp"
#include "sfc_lower.hpp"

namespace plcfi::st::detail {

namespace {

bool is_qualifier(std::string_view q) {
  for (const char* k : {"N", "R", "S", "P", "P1", "P0", "L", "D", "SD", "DS", "SL"})
    if (iequals(q, k)) return true;
  return false;
}

bool is_timed(std::string_view q) {
  for (const char* k : {"L", "D", "SD", "DS", "SL"})
    if (iequals(q, k)) return true;
  return false;
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

bool Parser::at_sfc_start() const {
  if (cur().kind != Tok::Ident) return false;
  if (at_word("INITIAL_STEP") || at_word("STEP") || at_word("ACTION"))
    return la(1).kind == Tok::Ident && la(2).kind == Tok::Colon;
  if (!at_word("TRANSITION")) return false;
  const auto is_from = [&](size_t i) { return la(i).kind == Tok::Ident && iequals(la(i).text, "FROM"); };
  const auto is_priority = [&](size_t i) {
    return la(i).kind == Tok::LParen && la(i + 1).kind == Tok::Ident && iequals(la(i + 1).text, "PRIORITY");
  };
  return is_from(1) || is_priority(1) || (la(1).kind == Tok::Ident && (is_from(2) || is_priority(2)));
}

// One SFC element of a POU body. The chart is the POU's whole body: no ST statements beside it.
void Parser::parse_sfc_element(Pou& pou) {
  if (!pou.sfc) {
    pou.sfc = std::make_unique<SfcChart>();
    pou.sfc->loc = cur().loc;
    if (pou.kind != PouKind::Program && pou.kind != PouKind::FunctionBlock)
      error("ST141", cur().loc, std::string("an SFC body needs a PROGRAM or FUNCTION_BLOCK (it keeps its steps between "
                                            "calls), not ") + pou_keyword(pou.kind) + " '" + pou.name.text + "'");
    if (!pou.body.empty())
      error("ST141", cur().loc, std::string(pou_keyword(pou.kind)) + " '" + pou.name.text +
                                    "' mixes ST statements and SFC elements: its body is either a statement list "
                                    "or a chart (put the statements into an ACTION)");
  }
  if (at_word("ACTION")) parse_sfc_action(*pou.sfc);
  else if (at_word("TRANSITION")) parse_sfc_transition(*pou.sfc);
  else parse_sfc_step(*pou.sfc);
}

void Parser::expect_sfc_end(std::string_view end, const std::string& what, SourceLoc open_loc) {
  if (at_word(end)) {
    advance();
    accept(Tok::Semi);
    return;
  }
  Diagnostic* d = error("ST140", missing_loc(), "expected " + std::string(end) + " to close " + what + " (line " +
                                                    std::to_string(open_loc.line) + "), found " + describe(cur()),
                        true);
  if (d) d->notes.emplace_back(open_loc, what + " starts here");
}

// [INITIAL_]STEP name ':' {association ';'} END_STEP
void Parser::parse_sfc_step(SfcChart& chart) {
  const Token& kw = advance();
  SfcStep step;
  step.loc = kw.loc;
  step.initial = iequals(kw.text, "INITIAL_STEP");
  expect_ident(&step.name, "ST140", "a step name after " + upper(std::string(kw.text)));
  expect(Tok::Colon, "ST140", "after the step name");
  const std::string what = std::string(step.initial ? "INITIAL_STEP" : "STEP") + " '" + step.name.text + "'";
  while (at(Tok::Ident) && !at_word("END_STEP") && !at_sfc_start()) {
    const size_t before = pos_;
    parse_sfc_association(step);
    if (pos_ == before) break;
  }
  expect_sfc_end("END_STEP", what, kw.loc);
  chart.steps.push_back(std::move(step));
}

// action '(' [qualifier [',' duration]] {',' indicator} ')' ';'
void Parser::parse_sfc_association(SfcStep& step) {
  SfcAssociation a;
  a.loc = cur().loc;
  expect_ident(&a.action, "ST140", "an action name");
  a.qualifier_loc = cur().loc;
  if (!expect(Tok::LParen, "ST140", "after the action name '" + a.action.text + "' (e.g. " + a.action.text + "(N);)")) {
    sync_statement();
    return;
  }
  if (at(Tok::Ident) && is_qualifier(cur().text)) {
    a.qualifier_loc = cur().loc;
    a.qualifier = upper(std::string(advance().text));
    if (is_timed(a.qualifier)) {
      if (!accept(Tok::Comma)) {
        error("ST142", missing_loc(), "qualifier " + a.qualifier + " of action '" + a.action.text +
                                          "' needs a duration (e.g. " + a.action.text + "(" + a.qualifier +
                                          ", T#5s);), found " + describe(cur()));
      } else {
        a.time = parse_expr();
      }
    }
  } else if (at(Tok::Ident)) {
    error("ST142", cur().loc, describe(cur()) + " is not an action qualifier (N, R, S, P, P1, P0, L, D, SD, DS, SL)");
    advance();
  } else if (!at(Tok::RParen)) {
    error("ST142", cur().loc, "expected an action qualifier (N, R, S, P, P1, P0, L, D, SD, DS, SL), found " +
                                  describe(cur()));
  }
  // Indicator variables: names the action sets to show its state (no effect on evolution).
  while (accept(Tok::Comma)) {
    Ident ind;
    if (!expect_ident(&ind, "ST140", "an indicator variable name")) break;
    a.indicators.push_back(std::move(ind));
  }
  if (!expect(Tok::RParen, "ST140", "to close the association of action '" + a.action.text + "'")) {
    sync_statement();
    return;
  }
  expect_semi("an action association");
  step.actions.push_back(std::move(a));
}

// name | '(' name {',' name} ')'
bool Parser::parse_sfc_step_list(std::vector<Ident>& out, const char* what) {
  if (accept(Tok::LParen)) {
    do {
      Ident s;
      if (!expect_ident(&s, "ST140", std::string("a step name ") + what)) return false;
      out.push_back(std::move(s));
    } while (accept(Tok::Comma));
    return expect(Tok::RParen, "ST140", std::string("to close the steps ") + what);
  }
  Ident s;
  if (!expect_ident(&s, "ST140", std::string("a step name (or a parenthesised list) ") + what)) return false;
  out.push_back(std::move(s));
  return true;
}

// TRANSITION [name] ['(' PRIORITY ':=' n ')'] FROM steps TO steps ':=' expr ';' END_TRANSITION
void Parser::parse_sfc_transition(SfcChart& chart) {
  const Token& kw = advance();
  SfcTransition t;
  t.loc = kw.loc;
  if (at(Tok::Ident) && !at_word("FROM")) {
    t.name = Ident{std::string(cur().text), cur().loc};
    advance();
  }
  const std::string what = t.name ? "TRANSITION '" + t.name->text + "'" : "TRANSITION";
  if (accept(Tok::LParen)) {
    advance();  // PRIORITY (at_sfc_start saw it)
    expect(Tok::Assign, "ST140", "after PRIORITY");
    if (at(Tok::IntLit)) {
      t.priority = static_cast<int64_t>(literal_from(advance())->int_value);
    } else {
      error("ST140", cur().loc, "expected an integer priority after PRIORITY :=, found " + describe(cur()));
    }
    expect(Tok::RParen, "ST140", "after the priority");
  }
  bool ok = false;
  if (at_word("FROM")) {
    advance();
    ok = parse_sfc_step_list(t.from, "after FROM") && expect(Tok::To, "ST140", "after the steps a transition comes FROM") &&
         parse_sfc_step_list(t.to, "after TO");
  } else {
    error("ST140", cur().loc, "expected FROM after " + what + ", found " + describe(cur()));
  }
  if (ok && accept(Tok::Assign)) {
    t.condition = parse_expr();
    expect_semi("the transition condition");
  } else if (ok && accept(Tok::Colon)) {
    // The condition in IL: its final current result, kept in a BOOL of the chart.
    const std::string var = "__sfc_c" + std::to_string(chart.transitions.size());
    if (t.name && !at_il_body() && synthesized_line(t.loc.line)) {
      // An importer's condition drawn in LD or FBD (import/sfc.cpp): ST statements that set
      // the transition's (hidden) name, which holds the condition.
      const std::string_view outer = sfc_end_;
      sfc_end_ = "END_TRANSITION";
      parse_stmt_list(t.condition_body, false);
      sfc_end_ = outer;
      auto n = std::make_unique<NameExpr>(t.loc);
      n->name = *t.name;
      t.condition = std::move(n);
      t.name.reset();
    } else if (!at_il_body()) {
      error("ST140", cur().loc, what + ": after ':' the condition is Instruction List (e.g. LD x  AND y), found " +
                                    describe(cur()) + "; an ST condition is written ':= expression;'");
    } else {
      Pou holder;
      holder.loc = cur().loc;
      const std::string_view outer = sfc_end_;
      sfc_end_ = "END_TRANSITION";
      parse_il_into(holder, var);
      sfc_end_ = outer;
      t.condition_body = std::move(holder.body);
      auto n = std::make_unique<NameExpr>(t.loc);
      n->name = Ident{var, t.loc};
      t.condition = std::move(n);
    }
  } else if (ok) {
    error("ST140", missing_loc(), "expected ':=' and the condition of " + what + ", found " + describe(cur()));
  }
  if (!t.condition) {  // skip what is left of the broken transition
    while (!at(Tok::Eof) && !at_word("END_TRANSITION") && !at_sfc_start() && !is_unit_end(cur().kind)) advance();
  }
  expect_sfc_end("END_TRANSITION", what, kw.loc);
  chart.transitions.push_back(std::move(t));
}

// ACTION name ':' stmt_list END_ACTION
void Parser::parse_sfc_action(SfcChart& chart) {
  const Token& kw = advance();
  SfcAction a;
  a.loc = kw.loc;
  expect_ident(&a.name, "ST140", "an action name after ACTION");
  expect(Tok::Colon, "ST140", "after the action name");
  {
    const std::string_view outer = sfc_end_;
    sfc_end_ = "END_ACTION";
    if (at_il_body()) {  // an action body in Instruction List
      Pou holder;
      holder.loc = a.loc;
      parse_il_into(holder, "");
      a.body = std::move(holder.body);
    } else {
      parse_stmt_list(a.body, false);
    }
    sfc_end_ = outer;
  }
  expect_sfc_end("END_ACTION", "ACTION '" + a.name.text + "'", kw.loc);
  chart.actions.push_back(std::move(a));
}

}  // namespace plcfi::st::detail
