// The ST lexer: source text -> tokens, with literal values decoded and lexical errors reported.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "diag.hpp"
#include "source.hpp"
#include "token.hpp"

namespace plcfi::st {

class Lexer {
 public:
  Lexer(const SourceManager& sm, uint32_t file, DiagEngine& diags);

  // Next token; Tok::Eof forever at the end. Comments, pragmas and whitespace are skipped.
  Token next();

 private:
  void skip_trivia();
  Token make(Tok kind, size_t begin) const;
  SourceLoc loc_at(size_t offset) const;
  char peek(size_t ahead = 0) const { return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0'; }

  Token lex_identifier();
  Token lex_number();
  Token lex_string(char quote);
  Token lex_direct_address();
  Token lex_time_literal(size_t begin, std::string_view prefix);
  void error(std::string_view code, size_t offset, std::string message);
  // A pragma `{...}` at [begin, end): conditional compilation ({IF defined(X)}, {ELSIF},
  // {ELSE}, {END_IF}, {define X}, {undefine X}), the message pragmas ({warning '...'},
  // {error '...'}, {info '...'}), and the ones that change nothing here (attribute,
  // region, ...); any other is warned about and ignored.
  void pragma(size_t begin, size_t end);
  // Skips the text of a conditional branch not taken, up to the next pragma.
  void skip_inactive();
  bool eval_condition(std::string_view expr, size_t at);
  bool active() const;

  struct Cond {
    bool active;      // this branch's text is compiled
    bool taken;       // some branch of this IF was taken
    bool outer;       // the enclosing text is compiled
    size_t at;        // the {IF} (for an unterminated one)
  };
  std::vector<Cond> conds_;
  std::vector<std::string> defines_;

  const SourceFile& src_;
  uint32_t file_;
  DiagEngine& diags_;
  std::string_view text_;
  size_t pos_ = 0;
  Tok prev_ = Tok::Eof;
  bool junk_ = false;    // an error was reported for text skipped before the next token  // kind of the previous token: after '.', digits are a bit number
};

// Lexes a whole file; the last token is Tok::Eof.
std::vector<Token> lex_file(const SourceManager& sm, uint32_t file, DiagEngine& diags);

}  // namespace plcfi::st
