// Parser entry points (source file, test file, single expression), error recovery
// (resynchronising after a syntax error, skipping past a nesting overflow) and expect_ident().
#include "parser_impl.hpp"

namespace plcfi::st::detail {

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

// ================================================================ names

void Parser::skip_namespace(Ident* id) {
  while (at(Tok::Dot) && la(1).kind == Tok::Ident) {
    advance();
    const Token& t = advance();
    *id = Ident{std::string(t.text), t.loc};
  }
}

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

// ================================================================ entry points

// unit := {top_level}
std::unique_ptr<CompilationUnit> Parser::parse_unit() {
  auto unit = std::make_unique<CompilationUnit>();
  unit->file = file_;
  while (!at(Tok::Eof)) {
    release_tokens();
    const size_t before = pos_;
    parse_top_level(*unit);
    if (pos_ == before) advance();
  }
  return unit;
}

// standalone := initializer EOF
ExprPtr Parser::parse_standalone_expression() {
  ExprPtr e = parse_initializer();
  if (!at(Tok::Eof)) error("ST131", cur().loc, "unexpected " + describe(cur()) + " after the expression");
  return e;
}

}  // namespace plcfi::st::detail

namespace plcfi::st {

std::unique_ptr<CompilationUnit> parse_unit(const SourceManager& sm, uint32_t file, DiagEngine& diags) {
  detail::Parser p(sm, file, diags, false);
  return p.parse_unit();
}

std::unique_ptr<TestFile> parse_test_file(const SourceManager& sm, uint32_t file, DiagEngine& diags) {
  detail::Parser p(sm, file, diags, true);
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
  detail::Parser p(sm, file, diags, false);
  return p.parse_standalone_expression();
}

}  // namespace plcfi::st
