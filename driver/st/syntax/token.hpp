// Token kinds and the token record the lexer hands to the parser.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ast.hpp"
#include "source.hpp"

namespace plcfi::st {

// Reserved words. Words that only matter in one context (ON, WITH, TASK, GET, SET, PUBLIC,
// ABSTRACT, TEST, MOCK, RETURNS, ...) stay identifiers so that user code may still use them
// as names; the parser recognises them by spelling where they matter.
#define PLCFI_ST_KEYWORDS(X)                                  \
  X(Program, "PROGRAM")                                       \
  X(EndProgram, "END_PROGRAM")                                \
  X(Function, "FUNCTION")                                     \
  X(EndFunction, "END_FUNCTION")                              \
  X(FunctionBlock, "FUNCTION_BLOCK")                          \
  X(EndFunctionBlock, "END_FUNCTION_BLOCK")                   \
  X(Interface, "INTERFACE")                                   \
  X(EndInterface, "END_INTERFACE")                            \
  X(Method, "METHOD")                                         \
  X(EndMethod, "END_METHOD")                                  \
  X(Property, "PROPERTY")                                     \
  X(EndProperty, "END_PROPERTY")                              \
  X(EndGet, "END_GET")                                        \
  X(EndSet, "END_SET")                                        \
  X(Type, "TYPE")                                             \
  X(EndType, "END_TYPE")                                      \
  X(Struct, "STRUCT")                                         \
  X(EndStruct, "END_STRUCT")                                  \
  X(Var, "VAR")                                               \
  X(VarInput, "VAR_INPUT")                                    \
  X(VarOutput, "VAR_OUTPUT")                                  \
  X(VarInOut, "VAR_IN_OUT")                                   \
  X(VarTemp, "VAR_TEMP")                                      \
  X(VarGlobal, "VAR_GLOBAL")                                  \
  X(VarExternal, "VAR_EXTERNAL")                              \
  X(VarStat, "VAR_STAT")                                      \
  X(VarInst, "VAR_INST")                                      \
  X(VarConfig, "VAR_CONFIG")                                  \
  X(EndVar, "END_VAR")                                        \
  X(Constant, "CONSTANT")                                     \
  X(Retain, "RETAIN")                                         \
  X(NonRetain, "NON_RETAIN")                                  \
  X(Persistent, "PERSISTENT")                                 \
  X(At, "AT")                                                 \
  X(Array, "ARRAY")                                           \
  X(Of, "OF")                                                 \
  X(RefTo, "REF_TO")                                          \
  X(If, "IF")                                                 \
  X(Then, "THEN")                                             \
  X(Elsif, "ELSIF")                                           \
  X(Else, "ELSE")                                             \
  X(EndIf, "END_IF")                                          \
  X(Case, "CASE")                                             \
  X(EndCase, "END_CASE")                                      \
  X(For, "FOR")                                               \
  X(To, "TO")                                                 \
  X(By, "BY")                                                 \
  X(Do, "DO")                                                 \
  X(EndFor, "END_FOR")                                        \
  X(While, "WHILE")                                           \
  X(EndWhile, "END_WHILE")                                    \
  X(Repeat, "REPEAT")                                         \
  X(Until, "UNTIL")                                           \
  X(EndRepeat, "END_REPEAT")                                  \
  X(Exit, "EXIT")                                             \
  X(Continue, "CONTINUE")                                     \
  X(Return, "RETURN")                                         \
  X(And, "AND")                                               \
  X(AndThen, "AND_THEN")                                      \
  X(OrElse, "OR_ELSE")                                        \
  X(Or, "OR")                                                 \
  X(Xor, "XOR")                                               \
  X(Not, "NOT")                                               \
  X(Mod, "MOD")                                               \
  X(True, "TRUE")                                             \
  X(False, "FALSE")                                           \
  X(This, "THIS")                                             \
  X(Super, "SUPER")                                           \
  X(Extends, "EXTENDS")                                       \
  X(Implements, "IMPLEMENTS")                                 \
  X(Configuration, "CONFIGURATION")                           \
  X(EndConfiguration, "END_CONFIGURATION")                    \
  X(Resource, "RESOURCE")                                     \
  X(EndResource, "END_RESOURCE")                              \
  X(EndTest, "END_TEST")                                      \
  X(EndSetup, "END_SETUP")                                    \
  X(EndTeardown, "END_TEARDOWN")

enum class Tok : uint8_t {
  Eof,
  Ident,
  IntLit,      // 42, 16#FF (magnitude in int_value)
  RealLit,     // 1.5, 1e3
  StringLit,   // 'abc' (decoded in str_value)
  WStringLit,  // "abc"
  TimeLit,     // T#.., D#.., TOD#.., DT#.. (lit says which; value in time_ns)
  DirectAddr,  // %IX0.3
  // punctuation
  LParen, RParen, LBracket, RBracket, Comma, Semi, Colon,
  Assign,     // :=
  Arrow,      // =>
  RefAssign,  // REF=
  Dot, DotDot, Hash, Caret,
  Plus, Minus, Star, Power, Slash, Amp,
  Eq, Ne, Lt, Gt, Le, Ge,
#define PLCFI_ST_KW_ENUM(name, text) name,
  PLCFI_ST_KEYWORDS(PLCFI_ST_KW_ENUM)
#undef PLCFI_ST_KW_ENUM
  Count
};

struct Token {
  Tok kind = Tok::Eof;
  SourceLoc loc;         // first character
  SourceLoc end;         // one past the last character (same line)
  uint32_t offset = 0;   // byte offset of the first character
  std::string_view text; // as written (points into the SourceFile)
  bool bad = false;      // malformed literal: already reported by the lexer
  bool after_junk = false;  // skipped text before it was reported (garbage, unclosed comment)

  // Literal payload (IntLit, RealLit, StringLit, WStringLit, TimeLit).
  LiteralKind lit = LiteralKind::Int;
  uint64_t int_value = 0;
  double real_value = 0;
  std::string str_value;
  int64_t time_ns = 0;
  bool is_long = false;
  bool beyond_signed = false;  // LTIME# above INT64_MAX: time_ns holds the unsigned bits
  std::string_view prefix;  // TimeLit: "T", "TIME", "LTIME", "DT", ... as written

  // DirectAddr payload.
  char area = 'I';
  char size = 'X';
  std::vector<uint32_t> parts;
};

// "identifier", "':='", "END_IF", ... for messages about expected tokens.
std::string_view tok_name(Tok kind);
// Keyword kind for a word (any case), or Tok::Ident.
Tok keyword_kind(std::string_view word);

}  // namespace plcfi::st
