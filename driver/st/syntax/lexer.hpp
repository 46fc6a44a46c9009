// The ST lexer: source text -> tokens, with literal values decoded and lexical errors reported.
#pragma once

#include <cstdint>
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
