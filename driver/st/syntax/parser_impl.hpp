// The parser class, shared by its translation units: parser.cpp (entry points, recovery),
// parse_exprs.cpp, parse_stmts.cpp, parse_decls.cpp and parse_tests.cpp. Internal: the
// public interface is parser.hpp.
//
// Recursive-descent parser for ST sources and STruC++ test files, with error recovery.
//
// Recovery model: errors never abort. Statements resynchronise at ';', statement keywords
// and block ends; declarations at ';' and END_VAR. A stack of open blocks tells a block end
// that closes an enclosing construct (report "missing END_IF", keep the token) from a stray
// or misspelt one (report it and consume it). At most one error is reported per token, so a
// single mistake does not cascade, and nesting is bounded so deep input cannot overflow the
// stack.
#pragma once

#include <array>
#include <cstddef>
#include <deque>
#include <string>
#include <utility>

#include "lexer.hpp"
#include "parser.hpp"

namespace plcfi::st::detail {

// Nesting limit for expressions, statements, types and initializers together.
inline constexpr int kMaxDepth = 128;

inline bool is_var_keyword(Tok k) {
  switch (k) {
    case Tok::Var: case Tok::VarInput: case Tok::VarOutput: case Tok::VarInOut: case Tok::VarTemp:
    case Tok::VarGlobal: case Tok::VarExternal: case Tok::VarStat: case Tok::VarInst: case Tok::VarConfig:
      return true;
    default:
      return false;
  }
}

inline bool is_top_level_start(Tok k) {
  return k == Tok::Program || k == Tok::Function || k == Tok::FunctionBlock || k == Tok::Interface ||
         k == Tok::Type || k == Tok::Configuration;
}

// Ends of POU-like blocks: never skipped inside statement lists; the POU decides.
inline bool is_unit_end(Tok k) {
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

inline bool is_stmt_end(Tok k) {
  return k == Tok::EndIf || k == Tok::EndCase || k == Tok::EndFor || k == Tok::EndWhile || k == Tok::EndRepeat;
}

inline bool is_stmt_keyword(Tok k) {
  return k == Tok::If || k == Tok::Case || k == Tok::For || k == Tok::While || k == Tok::Repeat ||
         k == Tok::Exit || k == Tok::Continue || k == Tok::Return;
}

// Block keywords that only make sense inside a matching construct.
inline bool is_strayable(Tok k) {
  return is_stmt_end(k) || k == Tok::Else || k == Tok::Elsif || k == Tok::Until || k == Tok::EndVar ||
         k == Tok::EndStruct || k == Tok::EndType || k == Tok::Then || k == Tok::Do || k == Tok::Of;
}

inline const char* pou_keyword(PouKind k) {
  switch (k) {
    case PouKind::Program: return "PROGRAM";
    case PouKind::FunctionBlock: return "FUNCTION_BLOCK";
    case PouKind::Function: return "FUNCTION";
    case PouKind::Method: return "METHOD";
    case PouKind::Interface: return "INTERFACE";
  }
  return "POU";
}

inline ExprPtr error_expr(SourceLoc loc) {
  auto e = std::make_unique<NameExpr>(loc);
  e->name = Ident{"<error>", loc};
  return e;
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
  // deque keeps references to earlier tokens valid while it grows. Indexes are absolute:
  // toks_[0] is token number base_; tokens of finished top-level declarations are released
  // (release_tokens), so a large file never holds all its tokens at once.
  const Token& tok(size_t i) const {
    while (base_ + toks_.size() <= i && (toks_.empty() || toks_.back().kind != Tok::Eof))
      toks_.push_back(lexer_.next());
    return toks_[std::min(std::max(i, base_), base_ + toks_.size() - 1) - base_];
  }
  // Between top-level declarations nothing looks further back than the previous token
  // (prev(), first_on_line()): drop the ones before it.
  void release_tokens() {
    while (base_ + 1 < pos_ && !toks_.empty()) {
      toks_.pop_front();
      ++base_;
    }
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
  // A line an importer wrote itself (an LD/FBD network's jump or label), not user text.
  bool synthesized_line(uint32_t line) const {
    const auto& origins = sm_.file(file_).origins;
    return line >= 1 && line <= origins.size() && origins[line - 1].where.generated;
  }

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
    if (from_tok >= to_tok || from_tok < base_ || to_tok > base_ + toks_.size()) return "";
    const auto& text = sm_.file(file_).text;
    const size_t begin = toks_[from_tok - base_].offset;
    const size_t end = toks_[to_tok - 1 - base_].offset + toks_[to_tok - 1 - base_].text.size();
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
        return at_test_block_start() || at_sfc_start() || (!sfc_end_.empty() && at_word(sfc_end_));
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

  // ------------------------------------------------------------ recovery (parser.cpp)
  void sync_statement();
  void sync_decl();
  void skip_nested();
  void report_too_deep() {
    if (too_deep_reported_) return;
    too_deep_reported_ = true;
    error("ST117", cur().loc, "nesting too deep (more than " + std::to_string(kMaxDepth) +
                                  " levels of parentheses, blocks or types)");
  }
  // Past the depth limit inside an expression: report once, skip the rest of the nested
  // text without recursing, and stand in an error node where it began.
  ExprPtr too_deep_expr() {
    const SourceLoc loc = cur().loc;
    report_too_deep();
    skip_nested();
    return error_expr(loc);
  }
  // After a name: `.Name` parts of a library namespace (TcUnit.FB_TestSuite, as CODESYS
  // and TwinCAT write a POU or type of a library): *id becomes the last part.
  void skip_namespace(Ident* id);
  bool expect_ident(Ident* out, const char* code, const std::string& what);

  // ------------------------------------------------------------ expressions (parse_exprs.cpp)
  ExprPtr parse_expr();
  ExprPtr parse_binary(int min_prec);
  ExprPtr parse_unary();
  ExprPtr parse_power();
  ExprPtr parse_postfix();
  StmtPtr parse_chained(std::unique_ptr<AssignStmt> first, size_t b_start);
  std::vector<StmtPtr> pending_;  // statements a chained assignment adds after the one returned
  ExprPtr parse_primary();
  ExprPtr parse_typed_literal();
  std::unique_ptr<LiteralExpr> literal_from(const Token& t);
  void parse_call_args(std::vector<CallArg>& args, const std::string& callee);
  static bool is_integer_type_name(std::string_view name);
  bool subrange_follows() const;
  ExprPtr parse_initializer();

  // ------------------------------------------------------------ statements (parse_stmts.cpp)
  void parse_stmt_list(StmtList& out, bool case_arm);
  StmtPtr parse_statement();
  StmtPtr parse_assign_or_call();
  StmtPtr parse_if();
  StmtPtr parse_case();
  StmtPtr parse_for();
  StmtPtr parse_while();
  StmtPtr parse_repeat();
  void expect_semi(const char* what);
  void expect_block_end(Tok end, const char* code, const char* opener, SourceLoc open_loc);

  // ------------------------------------------------------------ declarations (parse_decls.cpp)
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

  // ------------------------------------------------------------ SFC (parse_sfc.cpp)
  // The start of a textual SFC element: INITIAL_STEP/STEP name ':', ACTION name ':' or
  // TRANSITION [name] [(PRIORITY := n)] FROM. These words are not reserved in ST, so a
  // variable called `step` or `action` still parses as one.
  bool at_sfc_start() const;
  void parse_sfc_element(Pou& pou);
  void parse_sfc_step(SfcChart& chart);
  void parse_sfc_association(SfcStep& step);
  void parse_sfc_transition(SfcChart& chart);
  bool parse_sfc_step_list(std::vector<Ident>& out, const char* what);
  void parse_sfc_action(SfcChart& chart);
  void expect_sfc_end(std::string_view end, const std::string& what, SourceLoc open_loc);
  std::string_view sfc_end_;  // END_ACTION / END_TRANSITION while reading an SFC body
  // ------------------------------------------------------------ Instruction List (parse_il.cpp)
  // The body's first line is an IL instruction: the statements are IL, up to the POU's end.
  bool at_il_body() const;
  bool il_line_at(size_t i, bool formal_call) const;
  bool formal_call_line(size_t open) const;
  void parse_il_body(Pou& pou);
  // IL statements up to the next terminator into holder.body (an SFC action's or
  // transition's); with result_var, the final current result is stored into it.
  void parse_il_into(Pou& holder, const std::string& result_var);
  friend class IlReader;

  // ------------------------------------------------------------ test files (parse_tests.cpp)
  StmtPtr parse_mock();
  StmtPtr parse_mock_function();
  void parse_test_case(TestCase& tc, Tok end, const char* what);

  const SourceManager& sm_;
  uint32_t file_;
  DiagEngine& diags_;
  bool test_mode_;
  mutable Lexer lexer_;
  mutable std::deque<Token> toks_;
  size_t base_ = 0;  // the absolute index of toks_.front()
  size_t pos_ = 0;
  size_t last_error_pos_ = SIZE_MAX;
  int depth_ = 0;
  bool too_deep_reported_ = false;
  std::vector<Frame> open_;
};

}  // namespace plcfi::st::detail
