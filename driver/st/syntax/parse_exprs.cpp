// Expressions: precedence climbing over the binary operators, unary and postfix chains,
// primaries and typed literals, call arguments, and initializers (array, structure).
#include "parser_impl.hpp"

namespace plcfi::st::detail {

// ================================================================ expressions

// expr := or_expr   (precedence climbing over the binary levels below)
ExprPtr Parser::parse_expr() {
  DepthGuard guard(*this);
  if (guard.exceeded) return too_deep_expr();
  return parse_binary(1);
}

namespace {
// Binding power of a binary operator token, 0 when the token is not one.
int binary_prec(Tok k, BinaryOp* op) {
  switch (k) {
    case Tok::Or: *op = BinaryOp::Or; return 1;
    case Tok::OrElse: *op = BinaryOp::OrElse; return 1;
    case Tok::Xor: *op = BinaryOp::Xor; return 2;
    case Tok::And: *op = BinaryOp::And; return 3;
    case Tok::AndThen: *op = BinaryOp::AndThen; return 3;
    case Tok::Amp: *op = BinaryOp::And; return 3;
    case Tok::Eq: *op = BinaryOp::Eq; return 4;
    case Tok::Ne: *op = BinaryOp::Ne; return 4;
    case Tok::Lt: *op = BinaryOp::Lt; return 5;
    case Tok::Gt: *op = BinaryOp::Gt; return 5;
    case Tok::Le: *op = BinaryOp::Le; return 5;
    case Tok::Ge: *op = BinaryOp::Ge; return 5;
    case Tok::Plus: *op = BinaryOp::Add; return 6;
    case Tok::Minus: *op = BinaryOp::Sub; return 6;
    case Tok::Star: *op = BinaryOp::Mul; return 7;
    case Tok::Slash: *op = BinaryOp::Div; return 7;
    case Tok::Mod: *op = BinaryOp::Mod; return 7;
    default: return 0;
  }
}
}  // namespace

// or_expr := xor_expr {OR xor_expr}; xor_expr := and_expr {XOR and_expr};
// and_expr := eq_expr {(AND | '&') eq_expr}; eq_expr := cmp_expr {('=' | '<>') cmp_expr};
// cmp_expr := add_expr {('<' | '>' | '<=' | '>=') add_expr}; add_expr := mul_expr {('+' | '-') mul_expr};
// mul_expr := unary {('*' | '/' | MOD) unary}
ExprPtr Parser::parse_binary(int min_prec) {
  ExprPtr lhs = parse_unary();
  for (;;) {
    BinaryOp op{};
    const int prec = binary_prec(cur().kind, &op);
    if (prec == 0 || prec < min_prec) return lhs;
    advance();
    ExprPtr rhs = parse_binary(prec + 1);
    auto bin = std::make_unique<BinaryExpr>(lhs->loc);
    bin->op = op;
    bin->lhs = std::move(lhs);
    bin->rhs = std::move(rhs);
    lhs = std::move(bin);
  }
}

// unary := ('-' | '+' | NOT) unary | power
ExprPtr Parser::parse_unary() {
  if (!at(Tok::Minus) && !at(Tok::Plus) && !at(Tok::Not)) return parse_power();
  DepthGuard guard(*this);
  if (guard.exceeded) return too_deep_expr();  // `2 ** -2 ** -2 ...` nests through here
  const Token& t = advance();
  auto u = std::make_unique<UnaryExpr>(t.loc);
  u->op = t.kind == Tok::Minus ? UnaryOp::Neg : t.kind == Tok::Plus ? UnaryOp::Plus : UnaryOp::Not;
  u->operand = parse_unary();
  return u;
}

// power := postfix {'**' (postfix | unary)}   (left-associative; a signed exponent is accepted)
ExprPtr Parser::parse_power() {
  ExprPtr lhs = parse_postfix();
  while (at(Tok::Power)) {
    advance();
    ExprPtr rhs = (at(Tok::Minus) || at(Tok::Plus) || at(Tok::Not)) ? parse_unary() : parse_postfix();
    auto bin = std::make_unique<BinaryExpr>(lhs->loc);
    bin->op = BinaryOp::Pow;
    bin->lhs = std::move(lhs);
    bin->rhs = std::move(rhs);
    lhs = std::move(bin);
  }
  return lhs;
}

// postfix := primary {'.' name | '.' int | '[' expr {',' expr} ']' | '^' | '(' call_args ')'}
ExprPtr Parser::parse_postfix() {
  const size_t start = pos_;
  ExprPtr e = parse_primary();
  // Each suffix nests the expression one level (p^^^ is three dereferences); a chain longer
  // than any type could nest is an error, and the rest of it is read but not kept, so that
  // no later stage walks a chain thousands deep.
  int links = 0;
  ExprPtr kept;  // the chain up to the limit, while the rest is read into e and dropped
  for (;;) {
    if (!kept && (at(Tok::Dot) || at(Tok::LBracket) || at(Tok::Caret) || at(Tok::LParen)) && ++links > kMaxDepth) {
      report_too_deep();
      kept = error_expr(e->loc);
    }
    if (kept) e = error_expr(kept->loc);  // drop the suffix read last
    if (at(Tok::Dot)) {
      advance();
      // Keywords are fine as member names after '.' (fb.METHOD, s.TYPE), except block words,
      // which more likely mean the member name is missing.
      const Tok k = cur().kind;
      const bool keyword_member = k > Tok::Ge && k < Tok::Count && cur().loc.line == prev().end.line &&
                                  !is_unit_end(k) && !is_strayable(k) && !is_stmt_keyword(k) &&
                                  k != Tok::To && k != Tok::By;
      if (at(Tok::Ident) || keyword_member) {
        const Token& t = advance();
        if (e->kind == ExprKind::This || e->kind == ExprKind::Super) {
          // THIS.x and SUPER.M(): the reference dereferenced, as if written THIS^.x
          // (several tools accept the member access without the '^').
          auto d = std::make_unique<DerefExpr>(e->loc);
          d->base = std::move(e);
          e = std::move(d);
        }
        auto m = std::make_unique<MemberExpr>(e->loc);
        m->base = std::move(e);
        m->member = Ident{std::string(t.text), t.loc};
        e = std::move(m);
      } else if (at(Tok::IntLit)) {
        const Token& t = advance();
        auto b = std::make_unique<BitAccessExpr>(e->loc);
        if (t.int_value > 63 && !t.bad)
          error("ST133", t.loc, "bit number " + std::to_string(t.int_value) + " is out of range (0..63)");
        b->bit = static_cast<uint32_t>(std::min<uint64_t>(t.int_value, UINT32_MAX));
        b->base = std::move(e);
        e = std::move(b);
      } else {
        error("ST133", missing_loc(), "expected a member name or bit number after '.', found " + describe(cur()));
        return kept ? std::move(kept) : std::move(e);
      }
    } else if (at(Tok::LBracket)) {
      advance();
      auto idx = std::make_unique<IndexExpr>(e->loc);
      idx->base = std::move(e);
      do {
        idx->indices.push_back(parse_expr());
      } while (accept(Tok::Comma));
      expect(Tok::RBracket, "ST116", "to close the index list");
      e = std::move(idx);
    } else if (at(Tok::Caret)) {
      advance();
      auto d = std::make_unique<DerefExpr>(e->loc);
      d->base = std::move(e);
      e = std::move(d);
    } else if (at(Tok::LParen)) {
      const std::string callee = source_text(start, pos_);
      auto call = std::make_unique<CallExpr>(e->loc);
      call->callee = std::move(e);
      parse_call_args(call->args, callee);
      e = std::move(call);
    } else {
      return kept ? std::move(kept) : std::move(e);
    }
  }
}

// call_args := '(' [arg {',' arg}] ')'
// arg := [NOT] name '=>' [expr] | name ':=' expr | expr
void Parser::parse_call_args(std::vector<CallArg>& args, const std::string& callee) {
  DepthGuard guard(*this);
  if (guard.exceeded) {
    report_too_deep();
    skip_nested();
    return;
  }
  advance();  // '('
  if (accept(Tok::RParen)) return;
  do {
    if (at(Tok::RParen) && !args.empty()) break;  // `f(a, b, )`: a trailing comma, as CODESYS accepts
    CallArg arg;
    arg.loc = cur().loc;
    if (at(Tok::Not) && la(1).kind == Tok::Ident && la(2).kind == Tok::Arrow) {
      advance();
      arg.negate = true;
    }
    if (at(Tok::Ident) && (la(1).kind == Tok::Assign || la(1).kind == Tok::Arrow)) {
      const Token& name = advance();
      arg.name = Ident{std::string(name.text), name.loc};
      arg.is_output = advance().kind == Tok::Arrow;
      if (arg.is_output && (at(Tok::Comma) || at(Tok::RParen))) {
        args.push_back(std::move(arg));  // empty output capture `Q =>`
        continue;
      }
    }
    arg.value = parse_expr();
    args.push_back(std::move(arg));
  } while (accept(Tok::Comma));
  args.shrink_to_fit();  // the tree lives through compilation: no growth slack
  if (!accept(Tok::RParen)) {
    error("ST116", missing_loc(), "expected ',' or ')' in the argument list of '" + callee + "', found " +
                                      describe(cur()));
    // Skip the rest of a garbled argument list on this line.
    int level = 0;
    const uint32_t line = prev().end.line;
    while (!at(Tok::Eof) && !at(Tok::Semi) && cur().loc.line == line && !at_terminator()) {
      if (at(Tok::LParen)) ++level;
      if (at(Tok::RParen) && level-- == 0) {
        advance();
        break;
      }
      advance();
    }
  }
}

std::unique_ptr<LiteralExpr> Parser::literal_from(const Token& t) {
  auto lit = std::make_unique<LiteralExpr>(t.loc);
  switch (t.kind) {
    case Tok::IntLit: lit->lit = LiteralKind::Int; lit->int_value = t.int_value; break;
    case Tok::RealLit: lit->lit = LiteralKind::Real; lit->real_value = t.real_value; break;
    case Tok::StringLit: lit->lit = LiteralKind::String; lit->str_value = t.str_value; break;
    case Tok::WStringLit: lit->lit = LiteralKind::WString; lit->str_value = t.str_value; break;
    case Tok::True: lit->lit = LiteralKind::Bool; lit->int_value = 1; break;
    case Tok::False: lit->lit = LiteralKind::Bool; lit->int_value = 0; break;
    case Tok::TimeLit:
      lit->lit = t.lit;
      lit->time_ns = t.time_ns;
      lit->is_long = t.is_long;
      lit->beyond_signed = t.beyond_signed;
      lit->type_prefix = std::string(t.prefix);
      break;
    default: break;
  }
  return lit;
}

// typed_literal := type_name '#' (['-' | '+'] number | TRUE | FALSE | string) | enum_type '#' name
// INT#-5 becomes Unary Neg over the typed literal INT#5 (the sign is not folded), so that
// literal magnitudes stay unsigned everywhere and sema range-checks negation uniformly.
ExprPtr Parser::parse_typed_literal() {
  const Token& type_tok = advance();
  advance();  // '#'
  const std::string prefix(type_tok.text);
  if (at(Tok::Ident)) {
    const Token& v = advance();
    auto e = std::make_unique<EnumLiteralExpr>(type_tok.loc);
    e->type_name = Ident{prefix, type_tok.loc};
    e->value = Ident{std::string(v.text), v.loc};
    return e;
  }
  std::optional<UnaryOp> sign;
  if ((at(Tok::Minus) || at(Tok::Plus)) && (la(1).kind == Tok::IntLit || la(1).kind == Tok::RealLit)) {
    sign = advance().kind == Tok::Minus ? UnaryOp::Neg : UnaryOp::Plus;
  }
  const Tok k = cur().kind;
  if (k != Tok::IntLit && k != Tok::RealLit && k != Tok::True && k != Tok::False && k != Tok::StringLit &&
      k != Tok::WStringLit) {
    error("ST132", missing_loc(), "expected a literal or enum value after '" + prefix + "#', found " + describe(cur()));
    return error_expr(type_tok.loc);
  }
  const Token& v = advance();
  auto lit = literal_from(v);
  lit->loc = type_tok.loc;
  lit->type_prefix = prefix;
  if (iequals(prefix, "BOOL") && v.kind == Tok::IntLit) {
    if (v.int_value > 1 && !v.bad)
      error("ST132", v.loc, "BOOL#" + std::string(v.text) + " is not a valid BOOL literal (use 0, 1, TRUE or FALSE)");
    lit->lit = LiteralKind::Bool;
  }
  if (sign) {
    auto u = std::make_unique<UnaryExpr>(type_tok.loc);
    u->op = *sign;
    u->operand = std::move(lit);
    return u;
  }
  return lit;
}

// primary := literal | typed_literal | name | direct_address | THIS | SUPER | '(' expr ')'
ExprPtr Parser::parse_primary() {
  const Token& t = cur();
  switch (t.kind) {
    case Tok::IntLit: case Tok::RealLit: case Tok::StringLit: case Tok::WStringLit: case Tok::TimeLit:
    case Tok::True: case Tok::False:
      return literal_from(advance());
    case Tok::Ident: {
      if (la(1).kind == Tok::Hash) return parse_typed_literal();
      advance();
      auto n = std::make_unique<NameExpr>(t.loc);
      n->name = Ident{iequals(t.text, "NULL") ? std::string("NULL") : std::string(t.text), t.loc};
      return n;
    }
    case Tok::DirectAddr: {
      advance();
      auto d = std::make_unique<DirectAddrExpr>(t.loc);
      d->text = std::string(t.text);
      d->area = t.area;
      d->size = t.size;
      d->parts = t.parts;
      return d;
    }
    case Tok::And: case Tok::Or: case Tok::Xor: case Tok::Mod:
      if (la(1).kind == Tok::LParen) {
        // The functional form of an operator, AND(a, b, c): a call of the standard
        // function of that name (where an operand starts, the word cannot be the operator).
        advance();
        auto n = std::make_unique<NameExpr>(t.loc);
        n->name = Ident{canon(t.text), t.loc};
        return n;
      }
      error("ST115", missing_loc(), "expected an expression, found " + describe(t));
      return error_expr(t.loc);
    case Tok::This: advance(); return std::make_unique<ThisExpr>(t.loc);
    case Tok::Super: advance(); return std::make_unique<SuperExpr>(t.loc);
    case Tok::LParen: {
      advance();
      ExprPtr inner = parse_expr();
      expect(Tok::RParen, "ST116", "to close '(' at line " + std::to_string(t.loc.line));
      return inner;
    }
    default:
      error("ST115", missing_loc(), "expected an expression, found " + describe(t));
      return error_expr(t.loc);
  }
}

// initializer := '[' array_item {',' array_item} ']' | '(' name ':=' initializer {',' name ':=' initializer} ')' | expr
// array_item := int_literal '(' [initializer] ')' | initializer
ExprPtr Parser::parse_initializer() {
  DepthGuard guard(*this);
  if (guard.exceeded) return too_deep_expr();
  const Token& t = cur();
  if (at(Tok::LBracket)) {
    advance();
    auto arr = std::make_unique<ArrayInitExpr>(t.loc);
    if (!at(Tok::RBracket)) {
      do {
        ArrayInitExpr::Item item;
        if (at(Tok::IntLit) && la(1).kind == Tok::LParen) {
          item.repeat = literal_from(advance());
          advance();  // '('
          if (!at(Tok::RParen)) item.value = parse_initializer();
          expect(Tok::RParen, "ST116", "to close the repeated initializer");
        } else {
          item.value = parse_initializer();
        }
        arr->items.push_back(std::move(item));
      } while (accept(Tok::Comma));
    }
    expect(Tok::RBracket, "ST116", "to close the array initializer");
    return arr;
  }
  if (at(Tok::LParen) && la(1).kind == Tok::Ident && la(2).kind == Tok::Assign) {
    advance();
    auto st = std::make_unique<StructInitExpr>(t.loc);
    do {
      StructInitExpr::Item item;
      if (!expect_ident(&item.field, "ST100", "a member name in the structure initializer")) break;
      expect(Tok::Assign, "ST100", "after '" + item.field.text + "' in the structure initializer");
      item.value = parse_initializer();
      st->items.push_back(std::move(item));
    } while (accept(Tok::Comma));
    expect(Tok::RParen, "ST116", "to close the structure initializer");
    return st;
  }
  return parse_expr();
}

}  // namespace plcfi::st::detail
