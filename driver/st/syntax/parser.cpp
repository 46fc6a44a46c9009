// Recursive-descent parser for ST sources and STruC++ test files, with error recovery.
//
// Recovery model: errors never abort. Statements resynchronise at ';', statement keywords
// and block ends; declarations at ';' and END_VAR. A stack of open blocks tells a block end
// that closes an enclosing construct (report "missing END_IF", keep the token) from a stray
// or misspelt one (report it and consume it). At most one error is reported per token, so a
// single mistake does not cascade, and nesting is bounded so deep input cannot overflow the
// stack.
#include "parser.hpp"

#include <array>
#include <cstddef>
#include <deque>
#include <string>
#include <utility>

#include "lexer.hpp"

namespace plcfi::st {

namespace {

// Nesting limit for expressions, statements, types and initializers together.
constexpr int kMaxDepth = 128;

bool is_var_keyword(Tok k) {
  switch (k) {
    case Tok::Var: case Tok::VarInput: case Tok::VarOutput: case Tok::VarInOut: case Tok::VarTemp:
    case Tok::VarGlobal: case Tok::VarExternal: case Tok::VarStat: case Tok::VarConfig:
      return true;
    default:
      return false;
  }
}

bool is_top_level_start(Tok k) {
  return k == Tok::Program || k == Tok::Function || k == Tok::FunctionBlock || k == Tok::Interface ||
         k == Tok::Type || k == Tok::Configuration;
}

// Ends of POU-like blocks: never skipped inside statement lists; the POU decides.
bool is_unit_end(Tok k) {
  switch (k) {
    case Tok::EndProgram: case Tok::EndFunction: case Tok::EndFunctionBlock: case Tok::EndInterface:
    case Tok::EndMethod: case Tok::EndProperty: case Tok::EndGet: case Tok::EndSet:
    case Tok::EndConfiguration: case Tok::EndResource: case Tok::EndTest: case Tok::EndSetup:
    case Tok::EndTeardown:
      return true;
    default:
      return false;
  }
}

bool is_stmt_end(Tok k) {
  return k == Tok::EndIf || k == Tok::EndCase || k == Tok::EndFor || k == Tok::EndWhile || k == Tok::EndRepeat;
}

bool is_stmt_keyword(Tok k) {
  return k == Tok::If || k == Tok::Case || k == Tok::For || k == Tok::While || k == Tok::Repeat ||
         k == Tok::Exit || k == Tok::Continue || k == Tok::Return;
}

// Block keywords that only make sense inside a matching construct.
bool is_strayable(Tok k) {
  return is_stmt_end(k) || k == Tok::Else || k == Tok::Elsif || k == Tok::Until || k == Tok::EndVar ||
         k == Tok::EndStruct || k == Tok::EndType || k == Tok::Then || k == Tok::Do || k == Tok::Of;
}

const char* pou_keyword(PouKind k) {
  switch (k) {
    case PouKind::Program: return "PROGRAM";
    case PouKind::FunctionBlock: return "FUNCTION_BLOCK";
    case PouKind::Function: return "FUNCTION";
    case PouKind::Method: return "METHOD";
    case PouKind::Interface: return "INTERFACE";
  }
  return "POU";
}

ExprPtr error_expr(SourceLoc loc) {
  auto e = std::make_unique<NameExpr>(loc);
  e->name = Ident{"<error>", loc};
  return e;
}

TypeSpecPtr error_type(SourceLoc loc) {
  auto t = std::make_unique<TypeSpec>();
  t->kind = TypeSpecKind::Named;
  t->loc = loc;
  t->name = Ident{"<error>", loc};
  return t;
}

class Parser {
 public:
  Parser(const SourceManager& sm, uint32_t file, DiagEngine& diags, bool test_mode)
      : sm_(sm), file_(file), diags_(diags), test_mode_(test_mode), lexer_(sm, file, diags) {}

  std::unique_ptr<CompilationUnit> parse_unit();
  std::unique_ptr<TestFile> parse_test_file();
  ExprPtr parse_standalone_expression();

 private:
  // A construct whose end tokens may legitimately appear while it is open.
  struct Frame {
    std::array<Tok, 3> ends;
    bool is_statement;
  };
  struct FrameGuard {
    FrameGuard(Parser& p, std::array<Tok, 3> ends, bool is_statement) : p_(p) {
      p_.open_.push_back(Frame{ends, is_statement});
    }
    ~FrameGuard() { p_.open_.pop_back(); }
    FrameGuard(const FrameGuard&) = delete;
    FrameGuard& operator=(const FrameGuard&) = delete;
    Parser& p_;
  };
  struct DepthGuard {
    explicit DepthGuard(Parser& p) : p_(p) { exceeded = ++p_.depth_ > kMaxDepth; }
    ~DepthGuard() {
      // Once well out of the deep region, a later deep region is a new error.
      if (--p_.depth_ < kMaxDepth / 2) p_.too_deep_reported_ = false;
    }
    DepthGuard(const DepthGuard&) = delete;
    DepthGuard& operator=(const DepthGuard&) = delete;
    Parser& p_;
    bool exceeded;
  };

  // ------------------------------------------------------------ token access
  // Tokens are lexed on demand so lexical and syntax errors come out in source order; a
  // deque keeps references to earlier tokens valid while it grows.
  const Token& tok(size_t i) const {
    while (toks_.size() <= i && (toks_.empty() || toks_.back().kind != Tok::Eof)) toks_.push_back(lexer_.next());
    return toks_[std::min(i, toks_.size() - 1)];
  }
  const Token& cur() const { return tok(pos_); }
  const Token& la(size_t n) const { return tok(pos_ + n); }
  const Token& prev() const { return tok(pos_ == 0 ? 0 : pos_ - 1); }
  bool at(Tok k) const { return cur().kind == k; }
  bool at_word(std::string_view w) const { return cur().kind == Tok::Ident && iequals(cur().text, w); }
  const Token& advance() {
    const Token& t = cur();
    if (t.kind != Tok::Eof) ++pos_;
    return t;
  }
  bool accept(Tok k) {
    if (!at(k)) return false;
    advance();
    return true;
  }
  bool first_on_line(size_t i) const { return i == 0 || tok(i).loc.line != tok(i - 1).loc.line; }

  // ------------------------------------------------------------ diagnostics
  static std::string describe(const Token& t) {
    if (t.kind == Tok::Eof) return "end of file";
    std::string s(t.text);
    if (s.size() > 24) s = s.substr(0, 24) + "...";
    return "'" + s + "'";
  }
  // Where a missing token belongs: right after the previous token when the next one is on a
  // later line (so "missing ';'" points at the statement, not at the following line).
  SourceLoc missing_loc() const {
    if (pos_ > 0 && cur().loc.line != prev().end.line) return prev().end;
    return cur().loc;
  }
  Diagnostic* error(const char* code, SourceLoc loc, std::string message, bool stack = false) {
    // One error per token: later complaints about the same spot are consequences.
    if (pos_ == last_error_pos_ && !stack) return nullptr;
    last_error_pos_ = pos_;
    // Text the lexer skipped and reported right before this token explains the complaint.
    if (cur().after_junk) return nullptr;
    return &diags_.error(code, loc, std::move(message));
  }
  bool expect(Tok k, const char* code, const std::string& context) {
    if (accept(k)) return true;
    error(code, missing_loc(), "expected " + std::string(tok_name(k)) + " " + context + ", found " + describe(cur()));
    skip_misspelt_keyword();
    return false;
  }
  // After a missing THEN/DO/OF/TO: a name on the same line that cannot start a statement
  // (`IF a THN x := 1;`, `FOR i := 1 UPTO 3`) is the misspelt keyword; drop it so the rest
  // of the line parses.
  void skip_misspelt_keyword() {
    if (!at(Tok::Ident) || pos_ == 0 || cur().loc.line != prev().end.line) return;
    const Tok next = la(1).kind;
    if (next == Tok::Assign || next == Tok::LParen || next == Tok::Dot || next == Tok::LBracket ||
        next == Tok::Caret || next == Tok::RefAssign || next == Tok::Hash || next == Tok::Semi ||
        la(1).loc.line != cur().loc.line)
      return;
    advance();
  }
  std::string source_text(size_t from_tok, size_t to_tok) const {
    if (from_tok >= to_tok || to_tok > toks_.size()) return "";
    const auto& text = sm_.file(file_).text;
    const size_t begin = toks_[from_tok].offset;
    const size_t end = toks_[to_tok - 1].offset + toks_[to_tok - 1].text.size();
    std::string s = text.substr(begin, end - begin);
    for (char& c : s)
      if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    if (s.size() > 40) s = s.substr(0, 40) + "...";
    return s;
  }
  bool open_has(Tok k) const {
    for (const auto& f : open_)
      for (Tok e : f.ends)
        if (e == k) return true;
    return false;
  }

  // ------------------------------------------------------------ classification
  bool at_test_block_start() const {
    if (!test_mode_ || cur().kind != Tok::Ident) return false;
    const Tok next = la(1).kind;
    if (iequals(cur().text, "TEST")) return next == Tok::StringLit || next == Tok::WStringLit;
    if (iequals(cur().text, "SETUP") || iequals(cur().text, "TEARDOWN"))
      return next != Tok::Assign && next != Tok::LParen && next != Tok::Dot && next != Tok::LBracket &&
             next != Tok::Caret && next != Tok::RefAssign;
    return false;
  }
  // Tokens that end a statement list.
  bool at_terminator() const {
    const Tok k = cur().kind;
    if (k == Tok::Eof || is_unit_end(k) || is_stmt_end(k) || is_var_keyword(k) || is_top_level_start(k))
      return true;
    switch (k) {
      case Tok::Else: case Tok::Elsif: case Tok::Until: case Tok::EndVar: case Tok::EndStruct:
      case Tok::EndType: case Tok::Method: case Tok::Property: case Tok::Resource:
        return true;
      default:
        return at_test_block_start();
    }
  }
  bool looks_like_case_label() const {
    switch (cur().kind) {
      case Tok::IntLit: case Tok::RealLit: case Tok::Minus: case Tok::Plus: case Tok::StringLit:
      case Tok::WStringLit: case Tok::TimeLit: case Tok::True: case Tok::False:
        return true;
      case Tok::Ident: {
        if (la(1).kind == Tok::Hash) return true;
        size_t k = 1;
        while (la(k).kind == Tok::Dot && la(k + 1).kind == Tok::Ident) k += 2;
        const Tok next = la(k).kind;
        return next == Tok::Colon || next == Tok::Comma || next == Tok::DotDot;
      }
      default:
        return false;
    }
  }

  // ------------------------------------------------------------ recovery
  void sync_statement();
  void sync_decl();
  void skip_nested();
  void report_too_deep() {
    if (too_deep_reported_) return;
    too_deep_reported_ = true;
    error("ST117", cur().loc, "nesting too deep (more than " + std::to_string(kMaxDepth) +
                                  " levels of parentheses, blocks or types)");
  }

  // ------------------------------------------------------------ expressions
  ExprPtr parse_expr();
  ExprPtr parse_binary(int min_prec);
  ExprPtr parse_unary();
  ExprPtr parse_power();
  ExprPtr parse_postfix();
  ExprPtr parse_primary();
  ExprPtr parse_typed_literal();
  std::unique_ptr<LiteralExpr> literal_from(const Token& t);
  void parse_call_args(std::vector<CallArg>& args, const std::string& callee);
  ExprPtr parse_initializer();

  // ------------------------------------------------------------ statements
  void parse_stmt_list(StmtList& out, bool case_arm);
  StmtPtr parse_statement();
  StmtPtr parse_assign_or_call();
  StmtPtr parse_if();
  StmtPtr parse_case();
  StmtPtr parse_for();
  StmtPtr parse_while();
  StmtPtr parse_repeat();
  StmtPtr parse_mock();
  StmtPtr parse_mock_function();
  void expect_semi(const char* what);
  void expect_block_end(Tok end, const char* code, const char* opener, SourceLoc open_loc);

  // ------------------------------------------------------------ declarations
  void parse_top_level(CompilationUnit& unit);
  PouPtr parse_pou();
  void parse_pou_body(Pou& pou, bool allow_members);
  void expect_unit_end(Tok end, const std::string& what, SourceLoc open_loc, SourceLoc* end_loc);
  PouPtr parse_method(bool in_interface);
  std::unique_ptr<PropertyDecl> parse_property(bool in_interface);
  void parse_modifiers(Access* access, bool* is_abstract, bool* is_final);
  VarBlock parse_var_block();
  bool parse_var_decl(std::vector<VarDecl>& out, VarSection section, bool path_names);
  TypeSpecPtr parse_type_spec();
  TypeSpecPtr parse_return_type();
  void parse_enum_values(TypeSpec& spec);
  void parse_type_block(std::vector<TypeDecl>& out);
  ConfigDecl parse_configuration();
  void parse_resource_body(ResourceDecl& res, Tok end);
  TaskDecl parse_task();
  ProgramInstDecl parse_program_inst();
  void parse_test_case(TestCase& tc, Tok end, const char* what);
  bool expect_ident(Ident* out, const char* code, const std::string& what);

  const SourceManager& sm_;
  uint32_t file_;
  DiagEngine& diags_;
  bool test_mode_;
  mutable Lexer lexer_;
  mutable std::deque<Token> toks_;
  size_t pos_ = 0;
  size_t last_error_pos_ = SIZE_MAX;
  int depth_ = 0;
  bool too_deep_reported_ = false;
  std::vector<Frame> open_;
};

// ================================================================ recovery

void Parser::sync_statement() {
  const size_t start = pos_;
  while (!at(Tok::Eof)) {
    if (at(Tok::Semi)) {
      advance();
      return;
    }
    if (pos_ != start || !first_on_line(pos_)) {
      if (is_stmt_keyword(cur().kind) || at_terminator()) return;
      // A name at the start of a line most likely begins the next statement.
      if (pos_ != start && at(Tok::Ident) && first_on_line(pos_)) return;
    } else if (is_stmt_keyword(cur().kind) || at_terminator()) {
      return;
    }
    advance();
  }
}

void Parser::sync_decl() {
  const size_t start = pos_;
  while (!at(Tok::Eof)) {
    if (at(Tok::Semi)) {
      advance();
      return;
    }
    if (at(Tok::EndVar) || at(Tok::EndStruct) || at(Tok::EndType) || is_var_keyword(cur().kind) ||
        is_top_level_start(cur().kind) || is_unit_end(cur().kind) || at(Tok::Method) || at(Tok::Property) ||
        at(Tok::Resource))
      return;
    if (pos_ != start && at(Tok::Ident) && first_on_line(pos_)) return;
    advance();
  }
}

// Skips one balanced construct (parentheses, brackets, STRUCT, statement blocks) after a
// nesting overflow, so that the enclosing levels find their own closing tokens.
void Parser::skip_nested() {
  int level = 0;
  while (!at(Tok::Eof)) {
    const Tok k = cur().kind;
    const bool opens = k == Tok::LParen || k == Tok::LBracket || k == Tok::Struct || k == Tok::If ||
                       k == Tok::Case || k == Tok::For || k == Tok::While || k == Tok::Repeat;
    const bool closes = k == Tok::RParen || k == Tok::RBracket || k == Tok::EndStruct || is_stmt_end(k);
    if (opens) {
      ++level;
    } else if (closes) {
      if (level == 0) return;
      advance();
      if (--level == 0) return;
      continue;
    } else if (level == 0 && (k == Tok::Semi || k == Tok::Comma || k == Tok::Then || k == Tok::Do ||
                              k == Tok::Of || is_unit_end(k) || is_top_level_start(k))) {
      return;
    } else if (is_unit_end(k) || is_top_level_start(k)) {
      return;
    }
    advance();
  }
}

// ================================================================ expressions

// expr := or_expr   (precedence climbing over the binary levels below)
ExprPtr Parser::parse_expr() {
  DepthGuard guard(*this);
  if (guard.exceeded) {
    const SourceLoc loc = cur().loc;
    report_too_deep();
    skip_nested();
    return error_expr(loc);
  }
  return parse_binary(1);
}

namespace {
// Binding power of a binary operator token, 0 when the token is not one.
int binary_prec(Tok k, BinaryOp* op) {
  switch (k) {
    case Tok::Or: *op = BinaryOp::Or; return 1;
    case Tok::Xor: *op = BinaryOp::Xor; return 2;
    case Tok::And: *op = BinaryOp::And; return 3;
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
  if (guard.exceeded) {
    // Skip the rest of the operand without recursing (`2 ** -2 ** -2 ...` nests through here).
    const SourceLoc loc = cur().loc;
    report_too_deep();
    skip_nested();
    return error_expr(loc);
  }
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
  if (guard.exceeded) {
    const SourceLoc loc = cur().loc;
    report_too_deep();
    skip_nested();
    return error_expr(loc);
  }
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
      return parse_assign_or_call();
    case Tok::This: case Tok::Super: case Tok::DirectAddr:
      return parse_assign_or_call();
    default:
      error("ST104", t.loc, "expected a statement, found " + describe(t));
      sync_statement();
      return nullptr;
  }
}

// assignment := postfix (':=' | 'REF=') expr ';'
// call := postfix '(' call_args ')' ';'
StmtPtr Parser::parse_assign_or_call() {
  const size_t start = pos_;
  const SourceLoc loc = cur().loc;
  ExprPtr target = parse_postfix();
  if (at(Tok::Assign) || at(Tok::RefAssign)) {
    auto s = std::make_unique<AssignStmt>(loc);
    s->is_ref_assign = advance().kind == Tok::RefAssign;
    s->lhs = std::move(target);
    s->rhs = parse_expr();
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
    if (expect_ident(&var, "ST122", "the FOR control variable")) {
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

// mock_stmt := MOCK postfix ';'
StmtPtr Parser::parse_mock() {
  const Token& kw = advance();
  auto s = std::make_unique<MockStmt>(kw.loc);
  s->target = parse_postfix();
  expect_semi("MOCK");
  return s;
}

// mock_function_stmt := MOCK_FUNCTION name RETURNS expr ';'
StmtPtr Parser::parse_mock_function() {
  const Token& kw = advance();
  auto s = std::make_unique<MockFunctionStmt>(kw.loc);
  expect_ident(&s->function, "ST100", "the function name after MOCK_FUNCTION");
  if (at_word("RETURNS")) {
    advance();
  } else {
    error("ST100", missing_loc(), "expected RETURNS after 'MOCK_FUNCTION " + s->function.text + "', found " +
                                      describe(cur()));
  }
  s->value = parse_expr();
  expect_semi("MOCK_FUNCTION");
  return s;
}

// ================================================================ declarations

bool Parser::expect_ident(Ident* out, const char* code, const std::string& what) {
  if (at(Tok::Ident)) {
    const Token& t = advance();
    *out = Ident{std::string(t.text), t.loc};
    return true;
  }
  *out = Ident{"", cur().loc};
  std::string found = describe(cur());
  if (keyword_kind(cur().text) != Tok::Ident) found += " (a reserved word)";
  error(code, missing_loc(), "expected " + what + ", found " + found);
  return false;
}

// var_block := var_keyword {CONSTANT | RETAIN | NON_RETAIN | PERSISTENT} {var_decl} END_VAR
VarBlock Parser::parse_var_block() {
  const Token& kw = advance();
  VarBlock block;
  block.loc = kw.loc;
  switch (kw.kind) {
    case Tok::VarInput: block.section = VarSection::Input; break;
    case Tok::VarOutput: block.section = VarSection::Output; break;
    case Tok::VarInOut: block.section = VarSection::InOut; break;
    case Tok::VarTemp: block.section = VarSection::Temp; break;
    case Tok::VarGlobal: block.section = VarSection::Global; break;
    case Tok::VarExternal: block.section = VarSection::External; break;
    case Tok::VarStat: block.section = VarSection::Stat; break;
    case Tok::VarConfig: block.section = VarSection::Config; break;
    default: block.section = VarSection::Var; break;
  }
  for (;;) {
    if (accept(Tok::Constant)) block.constant = true;
    else if (accept(Tok::Retain) || accept(Tok::Persistent)) block.retain = true;
    else if (accept(Tok::NonRetain)) block.retain = false;
    else break;
  }
  const std::string opener(kw.text);
  for (;;) {
    if (accept(Tok::EndVar)) {
      accept(Tok::Semi);  // tolerated: `END_VAR;`
      break;
    }
    if (at(Tok::Ident)) {
      const Tok next = la(1).kind;
      const bool stmt_like = next == Tok::Assign || next == Tok::LParen || next == Tok::Caret ||
                             next == Tok::RefAssign ||
                             (block.section != VarSection::Config && (next == Tok::Dot || next == Tok::LBracket));
      if (!stmt_like) {
        const size_t before = pos_;
        parse_var_decl(block.decls, block.section, block.section == VarSection::Config);
        if (pos_ == before) advance();
        continue;
      }
    }
    if (at(Tok::Ident) || at_terminator() || is_stmt_keyword(cur().kind)) {
      Diagnostic* d = error("ST120", cur().loc, "expected END_VAR to close " + opener + " at line " +
                                                    std::to_string(kw.loc.line) + ", found " + describe(cur()));
      if (d) d->notes.emplace_back(kw.loc, opener + " starts here");
      break;
    }
    error("ST121", cur().loc, "expected a variable declaration such as 'x : INT;', found " + describe(cur()));
    const size_t before = pos_;
    sync_decl();
    if (pos_ == before) advance();
  }
  for (auto& d : block.decls) {
    d.section = block.section;
    d.constant = block.constant;
    d.retain = block.retain;
  }
  return block;
}

// var_decl := name {',' name} [AT direct_address] ':' type_spec [':=' initializer] ';'
// (VAR_CONFIG: name is a dotted instance path)
bool Parser::parse_var_decl(std::vector<VarDecl>& out, VarSection section, bool path_names) {
  VarDecl decl;
  decl.section = section;
  decl.loc = cur().loc;
  do {
    Ident name;
    if (!expect_ident(&name, "ST100", "a variable name")) {
      sync_decl();
      return false;
    }
    while (path_names && at(Tok::Dot) && la(1).kind == Tok::Ident) {
      advance();
      name.text += "." + std::string(advance().text);
    }
    decl.names.push_back(std::move(name));
  } while (accept(Tok::Comma));
  if (at(Tok::At)) {
    const Token& at_kw = advance();
    if (at(Tok::DirectAddr)) {
      const Token& t = advance();
      DirectAddrExpr addr(t.loc);
      addr.text = std::string(t.text);
      addr.area = t.area;
      addr.size = t.size;
      addr.parts = t.parts;
      decl.location = addr;
    } else {
      error("ST123", missing_loc(), "expected a direct address such as %IX0.0 after AT, found " + describe(cur()));
    }
    if (decl.names.size() > 1)
      error("ST123", at_kw.loc, "AT can locate only a single variable, not " + std::to_string(decl.names.size()));
  }
  const std::string first = decl.names.front().text;
  if (!accept(Tok::Colon)) {
    error("ST134", missing_loc(), "expected ':' and a type after '" + first + "', found " + describe(cur()));
    sync_decl();
    return false;
  }
  decl.type = parse_type_spec();
  if (accept(Tok::Assign)) decl.init = parse_initializer();
  if (!accept(Tok::Semi)) {
    error("ST105", missing_loc(), "expected ';' after the declaration of '" + first + "', found " + describe(cur()));
    if (pos_ > 0 && cur().loc.line == prev().end.line && !at(Tok::EndVar) && !at(Tok::EndStruct)) sync_decl();
  }
  out.push_back(std::move(decl));
  return true;
}

// type_spec := ARRAY '[' range {',' range} ']' OF type_spec
//            | STRUCT {var_decl} END_STRUCT
//            | REF_TO type_spec | POINTER TO type_spec
//            | '(' enum_value {',' enum_value} ')' [name]
//            | (STRING | WSTRING) ['[' expr ']' | '(' expr ')']
//            | name ['(' enum_value {',' enum_value} ')' | '(' expr '..' expr ')']
// range := expr '..' expr
TypeSpecPtr Parser::parse_type_spec() {
  DepthGuard guard(*this);
  const Token& t = cur();
  if (guard.exceeded) {
    report_too_deep();
    skip_nested();
    return error_type(t.loc);
  }
  auto spec = std::make_unique<TypeSpec>();
  spec->loc = t.loc;
  if (at(Tok::Array)) {
    advance();
    spec->kind = TypeSpecKind::Array;
    if (expect(Tok::LBracket, "ST119", "after ARRAY")) {
      do {
        TypeSpec::Range r;
        r.lo = parse_expr();
        if (!accept(Tok::DotDot)) {
          error("ST119", missing_loc(), "expected '..' in the array bounds (e.g. ARRAY [1..10] OF INT), found " +
                                            describe(cur()));
        }
        r.hi = parse_expr();
        spec->dims.push_back(std::move(r));
      } while (accept(Tok::Comma));
      expect(Tok::RBracket, "ST116", "to close the array bounds");
    }
    expect(Tok::Of, "ST109", "after the array bounds");
    spec->element = parse_type_spec();
    return spec;
  }
  if (at(Tok::Struct)) {
    advance();
    spec->kind = TypeSpecKind::Struct;
    for (;;) {
      if (accept(Tok::EndStruct)) break;
      if (at(Tok::Ident)) {
        const size_t before = pos_;
        parse_var_decl(spec->members, VarSection::Var, false);
        if (pos_ == before) advance();
        continue;
      }
      if (at_terminator() || is_stmt_keyword(cur().kind)) {
        Diagnostic* d = error("ST124", cur().loc, "expected END_STRUCT to close STRUCT at line " +
                                                      std::to_string(t.loc.line) + ", found " + describe(cur()));
        if (d) d->notes.emplace_back(t.loc, "STRUCT starts here");
        break;
      }
      error("ST121", cur().loc, "expected a member declaration such as 'x : INT;', found " + describe(cur()));
      const size_t before = pos_;
      sync_decl();
      if (pos_ == before) advance();
    }
    return spec;
  }
  if (at(Tok::RefTo) || (at_word("POINTER") && la(1).kind == Tok::To)) {
    spec->is_pointer = !at(Tok::RefTo);
    advance();
    if (spec->is_pointer) advance();
    spec->kind = TypeSpecKind::Ref;
    spec->element = parse_type_spec();
    return spec;
  }
  if (at(Tok::LParen)) {
    spec->kind = TypeSpecKind::Enum;
    parse_enum_values(*spec);
    // `(A, B) INT`; but a name followed by ':' starts the next declaration (missing ';').
    if (at(Tok::Ident) && la(1).kind != Tok::Colon && la(1).kind != Tok::Comma) {
      const Token& b = advance();
      spec->element = std::make_unique<TypeSpec>();
      spec->element->loc = b.loc;
      spec->element->name = Ident{std::string(b.text), b.loc};
    }
    return spec;
  }
  if (!at(Tok::Ident)) {
    error("ST119", missing_loc(), "expected a type, found " + describe(cur()));
    return error_type(t.loc);
  }
  advance();
  spec->kind = TypeSpecKind::Named;
  spec->name = Ident{std::string(t.text), t.loc};
  const bool is_string = iequals(t.text, "STRING") || iequals(t.text, "WSTRING");
  if (is_string && (at(Tok::LBracket) || at(Tok::LParen))) {
    const Tok close = at(Tok::LBracket) ? Tok::RBracket : Tok::RParen;
    advance();
    spec->string_length = parse_expr();
    expect(close, "ST116", "to close the string length");
    return spec;
  }
  if (at(Tok::LParen)) {
    const Tok k1 = la(1).kind, k2 = la(2).kind;
    if (k1 == Tok::Ident && (k2 == Tok::Assign || k2 == Tok::Comma || k2 == Tok::RParen)) {
      // Typed enum INT (A := 1, B := 2): the named type becomes the base.
      auto base = std::move(spec);
      spec = std::make_unique<TypeSpec>();
      spec->kind = TypeSpecKind::Enum;
      spec->loc = base->loc;
      parse_enum_values(*spec);
      spec->element = std::move(base);
      return spec;
    }
    advance();
    auto base = std::move(spec);
    spec = std::make_unique<TypeSpec>();
    spec->kind = TypeSpecKind::Subrange;
    spec->loc = base->loc;
    spec->element = std::move(base);
    spec->sub_lo = parse_expr();
    if (!accept(Tok::DotDot))
      error("ST119", missing_loc(), "expected '..' in the subrange (e.g. INT (0..100)), found " + describe(cur()));
    spec->sub_hi = parse_expr();
    expect(Tok::RParen, "ST116", "to close the subrange");
  }
  return spec;
}

// return_type := type_spec   (after FUNCTION name ':' / METHOD name ':')
TypeSpecPtr Parser::parse_return_type() {
  // `FUNCTION F :` with the type forgotten: do not take the first statement's target as the type.
  if (at(Tok::Ident) && (la(1).kind == Tok::Assign || la(1).kind == Tok::RefAssign)) {
    error("ST119", missing_loc(), "expected the return type after ':', found " + describe(cur()));
    return error_type(cur().loc);
  }
  return parse_type_spec();
}

// enum_values := '(' enum_value {',' enum_value} ')'; enum_value := name [':=' expr]
void Parser::parse_enum_values(TypeSpec& spec) {
  advance();  // '('
  do {
    TypeSpec::EnumValue v;
    if (!expect_ident(&v.name, "ST119", "an enumeration value name")) break;
    if (accept(Tok::Assign)) v.value = parse_expr();
    spec.enum_values.push_back(std::move(v));
  } while (accept(Tok::Comma));
  expect(Tok::RParen, "ST116", "to close the enumeration");
}

// type_block := TYPE type_decl {type_decl} END_TYPE
// type_decl := name ':' type_spec [':=' initializer] ';'   (';' optional after END_STRUCT)
void Parser::parse_type_block(std::vector<TypeDecl>& out) {
  const Token& kw = advance();
  FrameGuard frame(*this, {Tok::EndType, Tok::Eof, Tok::Eof}, false);
  for (;;) {
    if (accept(Tok::EndType)) {
      accept(Tok::Semi);
      return;
    }
    if (at(Tok::Ident)) {
      TypeDecl td;
      const Token& name = advance();
      td.name = Ident{std::string(name.text), name.loc};
      td.loc = name.loc;
      if (!accept(Tok::Colon)) {
        error("ST134", missing_loc(), "expected ':' and a type after '" + td.name.text + "', found " + describe(cur()));
        sync_decl();
        continue;
      }
      td.spec = parse_type_spec();
      if (accept(Tok::Assign)) td.init = parse_initializer();
      const bool struct_like = td.spec->kind == TypeSpecKind::Struct;
      if (!accept(Tok::Semi) && !struct_like) {
        error("ST105", missing_loc(), "expected ';' after the type declaration of '" + td.name.text + "', found " +
                                          describe(cur()));
        if (pos_ > 0 && cur().loc.line == prev().end.line && !at(Tok::EndType)) sync_decl();
      }
      out.push_back(std::move(td));
      continue;
    }
    if (at_terminator() || is_stmt_keyword(cur().kind)) {
      Diagnostic* d = error("ST126", cur().loc, "expected END_TYPE to close TYPE at line " +
                                                    std::to_string(kw.loc.line) + ", found " + describe(cur()));
      if (d) d->notes.emplace_back(kw.loc, "TYPE starts here");
      return;
    }
    error("ST126", cur().loc, "expected a type declaration such as 'MyInt : INT;', found " + describe(cur()));
    const size_t before = pos_;
    sync_decl();
    if (pos_ == before) advance();
  }
}

// modifiers := {PUBLIC | PRIVATE | PROTECTED | INTERNAL | ABSTRACT | FINAL | OVERRIDE}
// (contextual words: only taken as modifiers when a name follows)
void Parser::parse_modifiers(Access* access, bool* is_abstract, bool* is_final) {
  while (at(Tok::Ident) && la(1).kind == Tok::Ident) {
    const std::string w = canon(cur().text);
    if (w == "PUBLIC") *access = Access::Public;
    else if (w == "PRIVATE") *access = Access::Private;
    else if (w == "PROTECTED") *access = Access::Protected;
    else if (w == "INTERNAL") *access = Access::Internal;
    else if (w == "ABSTRACT") *is_abstract = true;
    else if (w == "FINAL") *is_final = true;
    else if (w == "OVERRIDE") {
    } else {
      return;
    }
    advance();
  }
}

void Parser::expect_unit_end(Tok end, const std::string& what, SourceLoc open_loc, SourceLoc* end_loc) {
  if (at(end)) {
    *end_loc = advance().loc;
    accept(Tok::Semi);
    return;
  }
  *end_loc = cur().loc;
  if (is_unit_end(cur().kind) && !open_has(cur().kind)) {
    Diagnostic* d = error("ST102", cur().loc, describe(cur()) + " does not match " + what + " (line " +
                                                  std::to_string(open_loc.line) + "): expected " +
                                                  std::string(tok_name(end)), true);
    if (d) d->notes.emplace_back(open_loc, what + " starts here");
    advance();
    accept(Tok::Semi);
    return;
  }
  Diagnostic* d = error("ST103", cur().loc, "expected " + std::string(tok_name(end)) + " to close " + what +
                                                " (line " + std::to_string(open_loc.line) + "), found " +
                                                describe(cur()), true);
  if (d) d->notes.emplace_back(open_loc, what + " starts here");
}

// pou_body := {var_block | method | property | statement}
void Parser::parse_pou_body(Pou& pou, bool allow_members) {
  bool seen_statements = false;
  for (;;) {
    const size_t before = pos_;
    if (is_var_keyword(cur().kind)) {
      if (seen_statements)
        error("ST129", cur().loc, "variable declarations must come before the statements of " +
                                      std::string(pou_keyword(pou.kind)) + " '" + pou.name.text + "'");
      pou.var_blocks.push_back(parse_var_block());
    } else if (at(Tok::Method) || at(Tok::Property)) {
      if (!allow_members) {
        error("ST129", cur().loc, std::string(tok_name(cur().kind)) + " is not allowed inside " +
                                      pou_keyword(pou.kind) + " '" + pou.name.text +
                                      "' (only in FUNCTION_BLOCK, PROGRAM and INTERFACE)");
        if (pou.kind == PouKind::Method) return;  // probably a missing END_METHOD
      }
      const bool in_interface = pou.kind == PouKind::Interface;
      if (at(Tok::Method)) pou.methods.push_back(parse_method(in_interface));
      else pou.properties.push_back(parse_property(in_interface));
    } else if (at(Tok::Eof) || is_unit_end(cur().kind) || is_top_level_start(cur().kind) || at(Tok::Resource) ||
               at_test_block_start()) {
      return;
    } else {
      const size_t first = pou.body.size();
      parse_stmt_list(pou.body, false);
      if (pou.body.size() > first) {
        seen_statements = true;
        if (pou.kind == PouKind::Interface || !pou.has_body)
          error("ST129", pou.body[first]->loc, std::string(pou.kind == PouKind::Interface ? "an INTERFACE" : "a method prototype") +
                                                   " cannot contain statements");
      }
    }
    if (pos_ == before) return;
  }
}

// pou := PROGRAM name pou_body END_PROGRAM
//      | FUNCTION name [':' type_spec] pou_body END_FUNCTION
//      | FUNCTION_BLOCK {ABSTRACT | FINAL | access} name [EXTENDS name] [IMPLEMENTS name {',' name}]
//        pou_body END_FUNCTION_BLOCK
//      | INTERFACE name [EXTENDS name {',' name}] pou_body END_INTERFACE
PouPtr Parser::parse_pou() {
  const Token& kw = advance();
  auto pou = std::make_unique<Pou>();
  pou->loc = kw.loc;
  Tok end = Tok::EndProgram;
  switch (kw.kind) {
    case Tok::Function: pou->kind = PouKind::Function; end = Tok::EndFunction; break;
    case Tok::FunctionBlock: pou->kind = PouKind::FunctionBlock; end = Tok::EndFunctionBlock; break;
    case Tok::Interface: pou->kind = PouKind::Interface; end = Tok::EndInterface; break;
    default: pou->kind = PouKind::Program; break;
  }
  FrameGuard frame(*this, {end, Tok::Eof, Tok::Eof}, false);
  if (pou->kind == PouKind::FunctionBlock) parse_modifiers(&pou->access, &pou->is_abstract, &pou->is_final);
  expect_ident(&pou->name, "ST100", std::string("a name after ") + std::string(kw.text));
  if (pou->kind == PouKind::Function && accept(Tok::Colon)) pou->return_type = parse_return_type();
  if (pou->kind == PouKind::FunctionBlock) {
    if (accept(Tok::Extends)) {
      Ident base;
      if (expect_ident(&base, "ST100", "a base FUNCTION_BLOCK name after EXTENDS")) pou->extends = base;
    }
    if (accept(Tok::Implements)) {
      do {
        Ident i;
        if (!expect_ident(&i, "ST100", "an interface name after IMPLEMENTS")) break;
        pou->implements.push_back(std::move(i));
      } while (accept(Tok::Comma));
    }
  } else if (pou->kind == PouKind::Interface && accept(Tok::Extends)) {
    do {
      Ident i;
      if (!expect_ident(&i, "ST100", "an interface name after EXTENDS")) break;
      pou->implements.push_back(std::move(i));
    } while (accept(Tok::Comma));
  }
  if (pou->kind == PouKind::Interface) pou->has_body = false;
  accept(Tok::Semi);  // tolerated after the header
  parse_pou_body(*pou, pou->kind != PouKind::Function);
  const std::string what = std::string(pou_keyword(pou->kind)) + " '" + pou->name.text + "'";
  expect_unit_end(end, what, kw.loc, &pou->end_loc);
  return pou;
}

// method := METHOD {access | ABSTRACT | FINAL | OVERRIDE} name [':' type_spec] {var_block} stmt_list END_METHOD
PouPtr Parser::parse_method(bool in_interface) {
  const Token& kw = advance();
  auto m = std::make_unique<Pou>();
  m->kind = PouKind::Method;
  m->loc = kw.loc;
  m->has_body = !in_interface;
  FrameGuard frame(*this, {Tok::EndMethod, Tok::Eof, Tok::Eof}, false);
  parse_modifiers(&m->access, &m->is_abstract, &m->is_final);
  expect_ident(&m->name, "ST100", "a method name after METHOD");
  if (accept(Tok::Colon)) m->return_type = parse_return_type();
  accept(Tok::Semi);
  parse_pou_body(*m, false);
  expect_unit_end(Tok::EndMethod, "METHOD '" + m->name.text + "'", kw.loc, &m->end_loc);
  return m;
}

// property := PROPERTY {access | ABSTRACT | FINAL | OVERRIDE} name ':' type_spec {accessor} END_PROPERTY
// accessor := GET {var_block} stmt_list END_GET | SET {var_block} stmt_list END_SET
std::unique_ptr<PropertyDecl> Parser::parse_property(bool in_interface) {
  const Token& kw = advance();
  auto p = std::make_unique<PropertyDecl>();
  p->loc = kw.loc;
  FrameGuard frame(*this, {Tok::EndProperty, Tok::Eof, Tok::Eof}, false);
  bool is_abstract = false, is_final = false;
  parse_modifiers(&p->access, &is_abstract, &is_final);
  expect_ident(&p->name, "ST100", "a property name after PROPERTY");
  if (accept(Tok::Colon)) {
    p->type = parse_type_spec();
  } else {
    error("ST134", missing_loc(), "expected ':' and a type after PROPERTY '" + p->name.text + "', found " +
                                      describe(cur()));
    p->type = error_type(cur().loc);
  }
  accept(Tok::Semi);
  for (;;) {
    const bool get = at_word("GET");
    if (!get && !at_word("SET")) break;
    const Token& acc = advance();
    auto a = std::make_unique<Pou>();
    a->kind = PouKind::Method;
    a->name = p->name;
    a->loc = acc.loc;
    a->access = p->access;
    a->is_abstract = is_abstract;
    a->is_final = is_final;
    a->has_body = !in_interface;
    const Tok end = get ? Tok::EndGet : Tok::EndSet;
    {
      FrameGuard acc_frame(*this, {end, Tok::Eof, Tok::Eof}, false);
      parse_pou_body(*a, false);
      expect_unit_end(end, std::string(get ? "GET" : "SET") + " of PROPERTY '" + p->name.text + "'", acc.loc,
                      &a->end_loc);
    }
    if (get ? p->getter != nullptr : p->setter != nullptr)
      error("ST129", acc.loc, std::string("duplicate ") + (get ? "GET" : "SET") + " in PROPERTY '" + p->name.text + "'");
    (get ? p->getter : p->setter) = std::move(a);
  }
  if (!at(Tok::EndProperty) && !is_unit_end(cur().kind) && !at(Tok::Eof) && !is_top_level_start(cur().kind) &&
      !at(Tok::Method) && !at(Tok::Property)) {
    error("ST100", cur().loc, "expected GET, SET or END_PROPERTY in PROPERTY '" + p->name.text + "', found " +
                                  describe(cur()));
    // Skip to the end of the property rather than misreading its contents.
    while (!at(Tok::Eof) && !at(Tok::EndProperty) && !is_top_level_start(cur().kind) &&
           !(is_unit_end(cur().kind) && open_has(cur().kind) && !at(Tok::EndProperty)))
      advance();
  }
  SourceLoc end_loc;
  expect_unit_end(Tok::EndProperty, "PROPERTY '" + p->name.text + "'", kw.loc, &end_loc);
  return p;
}

// task := TASK name '(' name ':=' expr {',' name ':=' expr} ')' ';'
TaskDecl Parser::parse_task() {
  const Token& kw = advance();
  TaskDecl task;
  task.loc = kw.loc;
  expect_ident(&task.name, "ST100", "a task name after TASK");
  if (accept(Tok::LParen)) {
    if (!at(Tok::RParen)) {
      do {
        Ident param;
        if (!expect_ident(&param, "ST128", "a task parameter (INTERVAL, PRIORITY or SINGLE)")) break;
        expect(Tok::Assign, "ST128", "after task parameter '" + param.text + "'");
        ExprPtr value = parse_expr();
        const std::string w = canon(param.text);
        if (w == "INTERVAL") task.interval = std::move(value);
        else if (w == "PRIORITY") task.priority = std::move(value);
        else if (w == "SINGLE") task.single = std::move(value);
        else
          error("ST128", param.loc, "unknown task parameter '" + param.text + "' (expected INTERVAL, PRIORITY or SINGLE)");
      } while (accept(Tok::Comma));
    }
    expect(Tok::RParen, "ST116", "to close the task parameters");
  }
  expect_semi("the TASK declaration");
  return task;
}

// program_inst := PROGRAM name [WITH name] ':' name ['(' call_args ')'] ';'
ProgramInstDecl Parser::parse_program_inst() {
  const Token& kw = advance();
  ProgramInstDecl p;
  p.loc = kw.loc;
  expect_ident(&p.instance, "ST100", "a program instance name after PROGRAM");
  if (at_word("WITH")) {
    advance();
    Ident task;
    if (expect_ident(&task, "ST100", "a task name after WITH")) p.task = task;
  }
  if (expect(Tok::Colon, "ST127", "and the program type after the instance name '" + p.instance.text + "'"))
    expect_ident(&p.type, "ST100", "a program type name");
  if (at(Tok::LParen)) parse_call_args(p.args, p.instance.text);
  expect_semi("the PROGRAM instance declaration");
  return p;
}

// resource_body := {var_block | task | program_inst}
void Parser::parse_resource_body(ResourceDecl& res, Tok end) {
  for (;;) {
    const size_t before = pos_;
    if (at(end) || at(Tok::EndConfiguration) || at(Tok::EndResource) || at(Tok::Eof)) return;
    if (at(Tok::VarGlobal) || at(Tok::VarConfig) || at(Tok::Var)) {
      res.globals.push_back(parse_var_block());
    } else if (at_word("TASK") && la(1).kind == Tok::Ident) {
      res.tasks.push_back(parse_task());
    } else if (at(Tok::Program) && la(1).kind == Tok::Ident && la(2).kind != Tok::Semi &&
               (la(2).kind == Tok::Colon || (la(2).kind == Tok::Ident && iequals(la(2).text, "WITH")))) {
      res.programs.push_back(parse_program_inst());
    } else if (at(Tok::Resource) || is_top_level_start(cur().kind) || is_unit_end(cur().kind)) {
      return;
    } else {
      error("ST127", cur().loc, "expected TASK, PROGRAM, VAR_GLOBAL or " + std::string(tok_name(end)) + ", found " +
                                    describe(cur()));
      sync_decl();
    }
    if (pos_ == before) advance();
  }
}

// configuration := CONFIGURATION name {var_block} {resource | task | program_inst} END_CONFIGURATION
// resource := RESOURCE name ON name {var_block | task | program_inst} END_RESOURCE
ConfigDecl Parser::parse_configuration() {
  const Token& kw = advance();
  ConfigDecl cfg;
  cfg.loc = kw.loc;
  FrameGuard frame(*this, {Tok::EndConfiguration, Tok::Eof, Tok::Eof}, false);
  expect_ident(&cfg.name, "ST100", "a configuration name after CONFIGURATION");
  for (;;) {
    const size_t before = pos_;
    if (at(Tok::EndConfiguration) || at(Tok::Eof)) break;
    if (at(Tok::VarGlobal) || at(Tok::VarConfig) || at(Tok::Var)) {
      cfg.globals.push_back(parse_var_block());
    } else if (at(Tok::Resource)) {
      const Token& rk = advance();
      ResourceDecl res;
      res.loc = rk.loc;
      FrameGuard res_frame(*this, {Tok::EndResource, Tok::Eof, Tok::Eof}, false);
      expect_ident(&res.name, "ST100", "a resource name after RESOURCE");
      if (at_word("ON")) {
        advance();
        expect_ident(&res.on, "ST100", "a processor name after ON");
      } else {
        error("ST127", missing_loc(), "expected ON after RESOURCE '" + res.name.text + "', found " + describe(cur()));
      }
      parse_resource_body(res, Tok::EndResource);
      SourceLoc end_loc;
      expect_unit_end(Tok::EndResource, "RESOURCE '" + res.name.text + "'", rk.loc, &end_loc);
      cfg.resources.push_back(std::move(res));
    } else if ((at_word("TASK") && la(1).kind == Tok::Ident) || at(Tok::Program)) {
      // Tasks and programs directly in the configuration live in an implicit resource.
      if (cfg.resources.empty() || !cfg.resources.back().name.text.empty()) {
        ResourceDecl implicit;
        implicit.loc = cur().loc;
        implicit.name = Ident{"", cur().loc};
        cfg.resources.push_back(std::move(implicit));
      }
      parse_resource_body(cfg.resources.back(), Tok::EndConfiguration);
    } else if (is_top_level_start(cur().kind) || is_unit_end(cur().kind)) {
      break;
    } else {
      error("ST127", cur().loc, "expected RESOURCE, TASK, PROGRAM, VAR_GLOBAL or END_CONFIGURATION, found " +
                                    describe(cur()));
      sync_decl();
    }
    if (pos_ == before) advance();
  }
  SourceLoc end_loc;
  expect_unit_end(Tok::EndConfiguration, "CONFIGURATION '" + cfg.name.text + "'", kw.loc, &end_loc);
  return cfg;
}

// test_case := (SETUP | TEARDOWN | TEST string) {var_block} stmt_list (END_SETUP | END_TEARDOWN | END_TEST)
void Parser::parse_test_case(TestCase& tc, Tok end, const char* what) {
  FrameGuard frame(*this, {end, Tok::Eof, Tok::Eof}, false);
  bool seen_statements = false;
  for (;;) {
    const size_t before = pos_;
    if (is_var_keyword(cur().kind)) {
      if (seen_statements)
        error("ST130", cur().loc, std::string("variable declarations must come before the statements of ") + what);
      tc.var_blocks.push_back(parse_var_block());
    } else if (at(Tok::Eof) || is_unit_end(cur().kind) || is_top_level_start(cur().kind) || at_test_block_start() ||
               at(Tok::Method) || at(Tok::Property) || at(Tok::Resource)) {
      break;
    } else {
      const size_t first = tc.body.size();
      parse_stmt_list(tc.body, false);
      if (tc.body.size() > first) seen_statements = true;
    }
    if (pos_ == before) break;
  }
  SourceLoc end_loc;
  expect_unit_end(end, what, tc.loc, &end_loc);
}

// top_level := pou | type_block | var_block | configuration
void Parser::parse_top_level(CompilationUnit& unit) {
  const Tok k = cur().kind;
  if (k == Tok::Program || k == Tok::Function || k == Tok::FunctionBlock || k == Tok::Interface) {
    unit.pous.push_back(parse_pou());
  } else if (k == Tok::Type) {
    parse_type_block(unit.types);
  } else if (is_var_keyword(k)) {
    if (k != Tok::VarGlobal && k != Tok::VarConfig)
      error("ST101", cur().loc, describe(cur()) + " is not allowed at top level (only VAR_GLOBAL)");
    unit.globals.push_back(parse_var_block());
  } else if (k == Tok::Configuration) {
    unit.configs.push_back(parse_configuration());
  } else {
    error("ST101", cur().loc, std::string("expected PROGRAM, FUNCTION_BLOCK, FUNCTION, INTERFACE, TYPE, VAR_GLOBAL") +
                                  (test_mode_ ? ", CONFIGURATION, SETUP, TEARDOWN or TEST" : " or CONFIGURATION") +
                                  ", found " + describe(cur()));
    // One error for a run of garbage: skip to the next declaration.
    advance();
    while (!at(Tok::Eof) && !is_top_level_start(cur().kind) && !at(Tok::VarGlobal) && !at_test_block_start())
      advance();
  }
}

// unit := {top_level}
std::unique_ptr<CompilationUnit> Parser::parse_unit() {
  auto unit = std::make_unique<CompilationUnit>();
  unit->file = file_;
  while (!at(Tok::Eof)) {
    const size_t before = pos_;
    parse_top_level(*unit);
    if (pos_ == before) advance();
  }
  return unit;
}

// test_file := {setup | teardown | test | top_level}
std::unique_ptr<TestFile> Parser::parse_test_file() {
  auto tf = std::make_unique<TestFile>();
  tf->file = file_;
  tf->decls.file = file_;
  while (!at(Tok::Eof)) {
    const size_t before = pos_;
    if (at_test_block_start()) {
      const Token& kw = advance();
      TestCase tc;
      tc.loc = kw.loc;
      if (iequals(kw.text, "TEST")) {
        tc.name = advance().str_value;
        parse_test_case(tc, Tok::EndTest, "TEST");
        tf->tests.push_back(std::move(tc));
      } else {
        const bool setup = iequals(kw.text, "SETUP");
        tc.name = setup ? "SETUP" : "TEARDOWN";
        parse_test_case(tc, setup ? Tok::EndSetup : Tok::EndTeardown, setup ? "SETUP" : "TEARDOWN");
        auto& slot = setup ? tf->setup : tf->teardown;
        if (slot) error("ST130", kw.loc, std::string("duplicate ") + tc.name + " block (only one is allowed)", true);
        else slot = std::move(tc);
      }
    } else if (at_word("TEST")) {
      error("ST130", cur().loc, "expected the test name as a string after TEST (e.g. TEST 'counts up'), found " +
                                    describe(la(1)));
      const Token& kw = advance();
      if (at(Tok::Ident) && cur().loc.line == kw.loc.line) advance();  // an unquoted name
      TestCase tc;
      tc.loc = kw.loc;
      parse_test_case(tc, Tok::EndTest, "TEST");
      tf->tests.push_back(std::move(tc));
    } else {
      parse_top_level(tf->decls);
    }
    if (pos_ == before) advance();
  }
  return tf;
}

// standalone := initializer EOF
ExprPtr Parser::parse_standalone_expression() {
  ExprPtr e = parse_initializer();
  if (!at(Tok::Eof)) error("ST131", cur().loc, "unexpected " + describe(cur()) + " after the expression");
  return e;
}

}  // namespace

std::unique_ptr<CompilationUnit> parse_unit(const SourceManager& sm, uint32_t file, DiagEngine& diags) {
  Parser p(sm, file, diags, false);
  return p.parse_unit();
}

std::unique_ptr<TestFile> parse_test_file(const SourceManager& sm, uint32_t file, DiagEngine& diags) {
  Parser p(sm, file, diags, true);
  return p.parse_test_file();
}

bool is_test_file(const SourceManager& sm, uint32_t file) {
  DiagEngine quiet(sm);
  Lexer lexer(sm, file, quiet);
  const Token t = lexer.next();
  return t.kind == Tok::Ident &&
         (iequals(t.text, "TEST") || iequals(t.text, "SETUP") || iequals(t.text, "TEARDOWN"));
}

ExprPtr parse_expression(const SourceManager& sm, uint32_t file, DiagEngine& diags) {
  Parser p(sm, file, diags, false);
  return p.parse_standalone_expression();
}

}  // namespace plcfi::st
