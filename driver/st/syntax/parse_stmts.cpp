// Statements: statement lists, assignments and calls, IF, CASE, FOR, WHILE, REPEAT, and
// the checks for a missing ';' or block end.
#include "parser_impl.hpp"

#include <cctype>

namespace plcfi::st::detail {

// ================================================================ statements

void Parser::expect_semi(const char* what) {
  if (accept(Tok::Semi)) return;
  // An unterminated string already swallowed the ';' and was reported.
  if (pos_ > 0 && prev().bad && (prev().kind == Tok::StringLit || prev().kind == Tok::WStringLit)) return;
  error("ST105", missing_loc(), std::string("expected ';' after ") + what + ", found " + describe(cur()));
  // Junk on the same line belongs to the broken statement; a new line probably starts the
  // next statement, so only the ';' was missing.
  if (pos_ > 0 && cur().loc.line == prev().end.line && !at_terminator()) sync_statement();
}

// stmt_list := {statement}
void Parser::parse_stmt_list(StmtList& out, bool case_arm) {
  for (;;) {
    if (case_arm && looks_like_case_label()) return;
    const Tok k = cur().kind;
    if (is_strayable(k) && !open_has(k)) {
      // A statement block end with no open construct: inside IF/FOR/... let that construct
      // treat it as its own misspelt end; elsewhere it is stray.
      const bool inner_stmt = !open_.empty() && open_.back().is_statement;
      if (inner_stmt && is_stmt_end(k)) return;
      if (k == Tok::Else || k == Tok::Elsif)
        error("ST118", cur().loc, describe(cur()) + " without a matching IF" + (k == Tok::Else ? " or CASE" : std::string()));
      else if (k == Tok::Then || k == Tok::Do || k == Tok::Of)
        error("ST104", cur().loc, "expected a statement, found " + describe(cur()));
      else
        error("ST118", cur().loc, describe(cur()) + " does not close any open block");
      advance();
      continue;
    }
    if (at_terminator()) return;
    const size_t before = pos_;
    StmtPtr s = parse_statement();
    if (s) out.push_back(std::move(s));
    for (auto& more : pending_) out.push_back(std::move(more));  // the rest of a chained assignment
    pending_.clear();
    if (pos_ == before) {
      error("ST104", cur().loc, "expected a statement, found " + describe(cur()));
      advance();
    }
  }
}

// statement := assignment | call ';' | if_stmt | case_stmt | for_stmt | while_stmt | repeat_stmt
//            | EXIT ';' | CONTINUE ';' | RETURN ';' | ';' | mock_stmt | mock_function_stmt
StmtPtr Parser::parse_statement() {
  const Token& t = cur();
  switch (t.kind) {
    case Tok::Semi:
      advance();
      return std::make_unique<SimpleStmt>(StmtKind::Empty, t.loc);
    case Tok::Exit: case Tok::Continue: case Tok::Return: {
      advance();
      const StmtKind kind = t.kind == Tok::Exit ? StmtKind::Exit : t.kind == Tok::Continue ? StmtKind::Continue : StmtKind::Return;
      auto s = std::make_unique<SimpleStmt>(kind, t.loc);
      expect_semi(t.kind == Tok::Exit ? "EXIT" : t.kind == Tok::Continue ? "CONTINUE" : "RETURN");
      return s;
    }
    case Tok::If: case Tok::Case: case Tok::For: case Tok::While: case Tok::Repeat: {
      DepthGuard guard(*this);
      if (guard.exceeded) {
        report_too_deep();
        skip_nested();
        accept(Tok::Semi);
        return std::make_unique<SimpleStmt>(StmtKind::Empty, t.loc);
      }
      switch (t.kind) {
        case Tok::If: return parse_if();
        case Tok::Case: return parse_case();
        case Tok::For: return parse_for();
        case Tok::While: return parse_while();
        default: return parse_repeat();
      }
    }
    case Tok::Ident:
      if (test_mode_ && iequals(t.text, "MOCK") && (la(1).kind == Tok::Ident || la(1).kind == Tok::This))
        return parse_mock();
      if (test_mode_ && iequals(t.text, "MOCK_FUNCTION") && la(1).kind == Tok::Ident) return parse_mock_function();
      // CODESYS ST: `JMP label;` and `label:` (the compiler rejects them under --dialect iec).
      if (iequals(t.text, "JMP") && la(1).kind == Tok::Ident && la(2).kind == Tok::Semi) {
        advance();
        auto j = std::make_unique<JumpStmt>(t.loc);
        j->from_il = synthesized_line(t.loc.line);
        j->label = Ident{std::string(advance().text), prev().loc};
        advance();  // ';'
        return j;
      }
      if (la(1).kind == Tok::Colon) {
        auto l = std::make_unique<LabelStmt>(t.loc);
        l->from_il = synthesized_line(t.loc.line);
        l->name = Ident{std::string(t.text), t.loc};
        advance();
        advance();  // ':'
        return l;
      }
      return parse_assign_or_call();
    case Tok::This: case Tok::Super: case Tok::DirectAddr:
      return parse_assign_or_call();
    default:
      error("ST104", t.loc, "expected a statement, found " + describe(t));
      sync_statement();
      return nullptr;
  }
}

namespace {
// A variable, element, member or dereference: what can stand left of ':='.
bool is_place(const Expr& e) {
  return e.kind == ExprKind::Name || e.kind == ExprKind::Member || e.kind == ExprKind::Index || e.kind == ExprKind::Deref;
}
}  // namespace

// chained := postfix ':=' postfix ':=' ... expr ';'   (CODESYS: a := b := c)
// The last target gets the value first, then each target the one to its right: the
// statements `b := c; a := b;`, the first returned and the others queued for the list.
// `first` is `a := b` with b parsed from the tokens at `b_start`.
StmtPtr Parser::parse_chained(std::unique_ptr<AssignStmt> first, size_t b_start) {
  std::vector<std::unique_ptr<AssignStmt>> chain;
  std::vector<size_t> starts{b_start};
  chain.push_back(std::move(first));
  while (at(Tok::Assign) && is_place(*chain.back()->rhs)) {
    const SourceLoc at_loc = chain.back()->rhs->loc;
    advance();  // ':='
    auto next = std::make_unique<AssignStmt>(at_loc);
    next->lhs = std::move(chain.back()->rhs);
    starts.push_back(pos_);
    next->rhs = parse_expr();
    chain.push_back(std::move(next));
  }
  expect_semi("assignment");
  const size_t end = pos_;
  // Each earlier statement reads the target to its right: parsed again from its tokens.
  for (size_t k = 0; k + 1 < chain.size(); ++k) {
    pos_ = starts[k];
    chain[k]->rhs = parse_postfix();
  }
  pos_ = end;
  chain.back()->chained = true;  // the dialect check reports the chain once
  for (size_t k = chain.size() - 1; k-- > 0;) pending_.push_back(std::move(chain[k]));
  return std::move(chain.back());
}

// assignment := postfix (':=' | 'REF=' | 'S=' | 'R=') expr ';'
// call := postfix '(' call_args ')' ';'
StmtPtr Parser::parse_assign_or_call() {
  const size_t start = pos_;
  const SourceLoc loc = cur().loc;
  ExprPtr target = parse_postfix();
  // CODESYS set/reset assignment: `x S= c;` sets x when c holds, `x R= c;` resets it.
  if (at(Tok::Ident) && (iequals(cur().text, "S") || iequals(cur().text, "R")) && la(1).kind == Tok::Eq &&
      la(1).loc.line == cur().loc.line && la(1).loc.col == cur().loc.col + 1) {
    auto s = std::make_unique<AssignStmt>(loc);
    s->set_reset = static_cast<char>(std::toupper(static_cast<unsigned char>(advance().text[0])));
    advance();  // '='
    s->lhs = std::move(target);
    s->rhs = parse_expr();
    expect_semi("assignment");
    return s;
  }
  if (at(Tok::Assign) || at(Tok::RefAssign)) {
    auto s = std::make_unique<AssignStmt>(loc);
    s->is_ref_assign = advance().kind == Tok::RefAssign;
    // An importer's hidden temporary (`_ldv<N> := F(EN := ...)`, an FBD function box with
    // EN whose value other boxes read): declared by this assignment with the type of its
    // value, which only the compiler knows.
    if (target->kind == ExprKind::Name && synthesized_line(loc.line) &&
        static_cast<const NameExpr&>(*target).name.text.rfind("_ldv", 0) == 0)
      s->declares_temp = true;
    s->lhs = std::move(target);
    size_t rhs_start = pos_;
    s->rhs = parse_expr();
    if (!s->is_ref_assign && at(Tok::Assign) && is_place(*s->rhs)) return parse_chained(std::move(s), rhs_start);
    expect_semi("assignment");
    return s;
  }
  if (target->kind == ExprKind::Call) {
    auto s = std::make_unique<CallStmt>(loc);
    s->call.reset(static_cast<CallExpr*>(target.release()));
    expect_semi("call");
    return s;
  }
  std::string msg = "expected ':=' or '(' after '" + source_text(start, pos_) + "', found " + describe(cur());
  if (at(Tok::Eq)) msg += " (assignment is written ':=')";
  error("ST106", missing_loc(), std::move(msg));
  sync_statement();
  return nullptr;
}

void Parser::expect_block_end(Tok end, const char* code, const char* opener, SourceLoc open_loc) {
  if (accept(end)) {
    accept(Tok::Semi);
    return;
  }
  Diagnostic* d = error(code, cur().loc,
                        "expected " + std::string(tok_name(end)) + " to close " + opener + " at line " +
                            std::to_string(open_loc.line) + ", found " + describe(cur()),
                        /*stack=*/true);
  if (d) d->notes.emplace_back(open_loc, std::string(opener) + " starts here");
  // A statement end that closes nothing else open is a misspelt end of this block.
  if (is_stmt_end(cur().kind) && !open_has(cur().kind)) {
    advance();
    accept(Tok::Semi);
  }
}

// if_stmt := IF expr THEN stmt_list {ELSIF expr THEN stmt_list} [ELSE stmt_list] END_IF [';']
StmtPtr Parser::parse_if() {
  const Token& kw = advance();
  auto s = std::make_unique<IfStmt>(kw.loc);
  {
    FrameGuard frame(*this, {Tok::Elsif, Tok::Else, Tok::EndIf}, true);
    SourceLoc arm_loc = kw.loc;
    bool first_arm = true;
    for (;;) {
      IfStmt::Arm arm;
      arm.loc = arm_loc;
      arm.cond = parse_expr();
      expect(Tok::Then, "ST107", first_arm ? "after the IF condition" : "after the ELSIF condition");
      first_arm = false;
      parse_stmt_list(arm.body, false);
      s->arms.push_back(std::move(arm));
      if (!at(Tok::Elsif)) break;
      arm_loc = advance().loc;
    }
    if (at(Tok::Else)) {
      s->else_loc = advance().loc;
      s->else_body.emplace();
      parse_stmt_list(*s->else_body, false);
      while (at(Tok::Elsif)) {
        // Parsed (and kept out of the AST) so that its own errors still show.
        error("ST118", cur().loc, "ELSIF after ELSE: ELSE must be the last branch of the IF at line " +
                                      std::to_string(kw.loc.line));
        advance();
        IfStmt::Arm late;
        late.cond = parse_expr();
        expect(Tok::Then, "ST107", "after the ELSIF condition");
        parse_stmt_list(late.body, false);
      }
    }
  }
  expect_block_end(Tok::EndIf, "ST110", "IF", kw.loc);
  return s;
}

// case_stmt := CASE expr OF {case_arm} [ELSE stmt_list] END_CASE [';']
// case_arm := case_label {',' case_label} ':' stmt_list
// case_label := expr ['..' expr]
StmtPtr Parser::parse_case() {
  const Token& kw = advance();
  auto s = std::make_unique<CaseStmt>(kw.loc);
  {
    FrameGuard frame(*this, {Tok::Else, Tok::EndCase, Tok::Eof}, true);
    s->selector = parse_expr();
    expect(Tok::Of, "ST109", "after the CASE selector");
    for (;;) {
      if (at(Tok::Else)) {
        s->else_loc = advance().loc;
        s->else_body.emplace();
        parse_stmt_list(*s->else_body, false);
        break;
      }
      if (at(Tok::EndCase) || at_terminator()) break;
      if (!looks_like_case_label()) {
        error("ST125", cur().loc, "expected a case label such as '1:', '2..5:' or 'Red:', found " + describe(cur()));
        StmtList orphan;  // still parsed, so its own errors are reported
        const size_t before = pos_;
        parse_stmt_list(orphan, true);
        if (pos_ == before) advance();
        continue;
      }
      CaseStmt::Arm arm;
      arm.loc = cur().loc;
      do {
        CaseLabel label;
        label.lo = parse_expr();
        if (accept(Tok::DotDot)) label.hi = parse_expr();
        arm.labels.push_back(std::move(label));
      } while (accept(Tok::Comma));
      if (!accept(Tok::Colon)) {
        error("ST125", missing_loc(), "expected ':' after the case label, found " + describe(cur()));
        if (at(Tok::Assign)) advance();  // `1 := ...` style typo
      }
      parse_stmt_list(arm.body, true);
      s->arms.push_back(std::move(arm));
    }
  }
  expect_block_end(Tok::EndCase, "ST111", "CASE", kw.loc);
  return s;
}

// for_stmt := FOR name ':=' expr TO expr [BY expr] DO stmt_list END_FOR [';']
StmtPtr Parser::parse_for() {
  const Token& kw = advance();
  auto s = std::make_unique<ForStmt>(kw.loc);
  {
    FrameGuard frame(*this, {Tok::EndFor, Tok::Eof, Tok::Eof}, true);
    Ident var;
    if (at(Tok::Ident) && (la(1).kind == Tok::Dot || la(1).kind == Tok::LBracket || la(1).kind == Tok::Caret)) {
      // `FOR st.nIndex := ...`, `FOR a[1] := ...`: TwinCAT takes any integer variable.
      var = Ident{std::string(cur().text), cur().loc};
      s->var = parse_postfix();
    } else if (expect_ident(&var, "ST122", "the FOR control variable")) {
      auto n = std::make_unique<NameExpr>(var.loc);
      n->name = var;
      s->var = std::move(n);
    } else {
      s->var = error_expr(cur().loc);
    }
    if (!accept(Tok::Assign)) {
      error("ST122", missing_loc(), "expected ':=' after the FOR control variable '" + var.text + "', found " +
                                        describe(cur()));
    }
    s->from = parse_expr();
    if (!accept(Tok::To)) {
      error("ST122", missing_loc(), "expected TO in the FOR statement, found " + describe(cur()));
      skip_misspelt_keyword();
    }
    s->to = parse_expr();
    if (accept(Tok::By)) s->by = parse_expr();
    expect(Tok::Do, "ST108", "after the FOR header");
    parse_stmt_list(s->body, false);
  }
  expect_block_end(Tok::EndFor, "ST112", "FOR", kw.loc);
  return s;
}

// while_stmt := WHILE expr DO stmt_list END_WHILE [';']
StmtPtr Parser::parse_while() {
  const Token& kw = advance();
  auto s = std::make_unique<WhileStmt>(kw.loc);
  {
    FrameGuard frame(*this, {Tok::EndWhile, Tok::Eof, Tok::Eof}, true);
    s->cond = parse_expr();
    expect(Tok::Do, "ST108", "after the WHILE condition");
    parse_stmt_list(s->body, false);
  }
  expect_block_end(Tok::EndWhile, "ST113", "WHILE", kw.loc);
  return s;
}

// repeat_stmt := REPEAT stmt_list UNTIL expr END_REPEAT [';']
StmtPtr Parser::parse_repeat() {
  const Token& kw = advance();
  auto s = std::make_unique<RepeatStmt>(kw.loc);
  {
    FrameGuard frame(*this, {Tok::Until, Tok::EndRepeat, Tok::Eof}, true);
    parse_stmt_list(s->body, false);
    if (accept(Tok::Until)) {
      s->until = parse_expr();
      accept(Tok::Semi);  // tolerated: `UNTIL cond; END_REPEAT`
    } else {
      Diagnostic* d = error("ST114", cur().loc, "expected UNTIL to end the REPEAT at line " +
                                                    std::to_string(kw.loc.line) + ", found " + describe(cur()), true);
      if (d) d->notes.emplace_back(kw.loc, "REPEAT starts here");
      s->until = error_expr(cur().loc);
      if (!at(Tok::EndRepeat)) return s;
    }
  }
  expect_block_end(Tok::EndRepeat, "ST114", "REPEAT", kw.loc);
  return s;
}

}  // namespace plcfi::st::detail
