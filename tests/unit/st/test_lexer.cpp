// Unit tests of the ST lexer: every token and literal form, its decoded value and location.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "st/syntax/lexer.hpp"

namespace plcfi::st {
namespace {

struct Lexed {
  SourceManager sm;
  DiagEngine diags{sm};
  std::vector<Token> toks;
};

std::unique_ptr<Lexed> lex(const std::string& text) {
  auto l = std::make_unique<Lexed>();
  const uint32_t f = l->sm.add("test.st", text);
  l->toks = lex_file(l->sm, f, l->diags);
  return l;
}

// Lexes a single token (plus Eof) and checks there were no diagnostics. The source is kept
// alive because a token's text points into it.
Token one(const std::string& text) {
  static std::vector<std::unique_ptr<Lexed>> keep;
  keep.push_back(lex(text));
  const Lexed& l = *keep.back();
  EXPECT_FALSE(l.diags.has_errors()) << text << ": " << l.diags.render_all();
  EXPECT_EQ(l.toks.size(), 2u) << text;
  return l.toks.front();
}

std::vector<std::string> codes(const Lexed& l) {
  std::vector<std::string> out;
  for (const auto& d : l.diags.all()) out.push_back(d.code);
  return out;
}

std::string first_message(const std::string& text) {
  auto l = lex(text);
  return l->diags.all().empty() ? std::string() : l->diags.all().front().message;
}

std::string first_code(const std::string& text) {
  auto l = lex(text);
  return l->diags.all().empty() ? std::string() : l->diags.all().front().code;
}

constexpr int64_t kSec = 1'000'000'000;

TEST(Lexer, KeywordsAreCaseInsensitiveAndNamesKeepSpelling) {
  auto l = lex("if Then END_if myVar _x1");
  ASSERT_EQ(l->toks.size(), 6u);
  EXPECT_EQ(l->toks[0].kind, Tok::If);
  EXPECT_EQ(l->toks[1].kind, Tok::Then);
  EXPECT_EQ(l->toks[2].kind, Tok::EndIf);
  EXPECT_EQ(l->toks[3].kind, Tok::Ident);
  EXPECT_EQ(l->toks[3].text, "myVar");
  EXPECT_EQ(l->toks[4].text, "_x1");
  EXPECT_EQ(l->toks[5].kind, Tok::Eof);
}

TEST(Lexer, ContextualWordsStayIdentifiers) {
  for (const char* w : {"TEST", "SETUP", "GET", "SET", "ON", "WITH", "TASK", "PUBLIC", "ABSTRACT", "MOCK", "NULL",
                        "STRING", "TIME", "POINTER"})
    EXPECT_EQ(one(w).kind, Tok::Ident) << w;
}

TEST(Lexer, Punctuation) {
  auto l = lex(":= => : .. . ( ) [ ] , ; # ^ + - * ** / & = <> < > <= >= REF=");
  const std::vector<Tok> want = {Tok::Assign, Tok::Arrow, Tok::Colon, Tok::DotDot, Tok::Dot, Tok::LParen,
                                 Tok::RParen, Tok::LBracket, Tok::RBracket, Tok::Comma, Tok::Semi, Tok::Hash,
                                 Tok::Caret, Tok::Plus, Tok::Minus, Tok::Star, Tok::Power, Tok::Slash, Tok::Amp,
                                 Tok::Eq, Tok::Ne, Tok::Lt, Tok::Gt, Tok::Le, Tok::Ge, Tok::RefAssign, Tok::Eof};
  ASSERT_EQ(l->toks.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(l->toks[i].kind, want[i]) << i;
  EXPECT_FALSE(l->diags.has_errors());
}

TEST(Lexer, RefAloneIsAName) {
  auto l = lex("REF(x) r REF= y");
  EXPECT_EQ(l->toks[0].kind, Tok::Ident);
  EXPECT_EQ(l->toks[5].kind, Tok::RefAssign);
}

TEST(Lexer, CommentsAndPragmasAreSkipped) {
  auto l = lex("a (* c1 (* nested *) still *) b /* c2 /* n */ x */ c // to end\n d {attribute 'qualified_only'} e");
  ASSERT_EQ(l->toks.size(), 6u);
  EXPECT_EQ(l->toks[0].text, "a");
  EXPECT_EQ(l->toks[1].text, "b");
  EXPECT_EQ(l->toks[2].text, "c");
  EXPECT_EQ(l->toks[3].text, "d");
  EXPECT_EQ(l->toks[4].text, "e");
  EXPECT_FALSE(l->diags.has_errors());
}

TEST(Lexer, UnterminatedCommentReportsOpeningPosition) {
  auto l = lex("x\n  (* open (* nested *)\n y");
  ASSERT_EQ(codes(*l), std::vector<std::string>{"ST002"});
  EXPECT_EQ(l->diags.all()[0].loc.line, 2u);
  EXPECT_EQ(l->diags.all()[0].loc.col, 3u);
  EXPECT_EQ(l->toks.back().kind, Tok::Eof);
  EXPECT_EQ(first_code("/* never closed"), "ST002");
  EXPECT_EQ(first_code("{attribute"), "ST011");
}

TEST(Lexer, Locations) {
  auto l = lex("PROGRAM p\n  x := 10;\n");
  EXPECT_EQ(l->toks[0].loc.line, 1u);
  EXPECT_EQ(l->toks[0].loc.col, 1u);
  EXPECT_EQ(l->toks[1].loc.col, 9u);
  EXPECT_EQ(l->toks[2].loc.line, 2u);
  EXPECT_EQ(l->toks[2].loc.col, 3u);
  EXPECT_EQ(l->toks[3].loc.col, 5u);
  EXPECT_EQ(l->toks[4].loc.col, 8u);
  EXPECT_EQ(l->toks[4].end.col, 10u);
}

TEST(Lexer, IntegerLiterals) {
  EXPECT_EQ(one("42").int_value, 42u);
  EXPECT_EQ(one("1_000_000").int_value, 1000000u);
  EXPECT_EQ(one("2#1010_1010").int_value, 0xAAu);
  EXPECT_EQ(one("8#17").int_value, 15u);
  EXPECT_EQ(one("16#FF").int_value, 255u);
  EXPECT_EQ(one("16#ff_ff").int_value, 0xFFFFu);
  EXPECT_EQ(one("18446744073709551615").int_value, UINT64_MAX);
  EXPECT_EQ(one("16#FFFFFFFFFFFFFFFF").int_value, UINT64_MAX);
  EXPECT_EQ(one("42").kind, Tok::IntLit);
  EXPECT_EQ(one("10#0").int_value, 0u);  // an explicit base 10, as TwinCAT code writes it
  EXPECT_EQ(one("10#1_234").int_value, 1234u);
}

TEST(Lexer, IntegerErrors) {
  EXPECT_EQ(first_code("18446744073709551616"), "ST007");
  EXPECT_EQ(first_code("16#1_0000_0000_0000_0000"), "ST007");
  EXPECT_EQ(first_message("8#19"), "invalid digit '9' in base-8 literal '8#19'");
  EXPECT_EQ(first_code("2#102"), "ST006");
  EXPECT_EQ(first_code("3#12"), "ST006");
  EXPECT_EQ(first_code("10#1A"), "ST006");
  EXPECT_EQ(first_code("16#"), "ST005");
  EXPECT_EQ(first_message("12abc"), "invalid numeric literal '12abc'");
}

TEST(Lexer, RealLiterals) {
  EXPECT_DOUBLE_EQ(one("1.5").real_value, 1.5);
  EXPECT_DOUBLE_EQ(one("1.5e3").real_value, 1500.0);
  EXPECT_DOUBLE_EQ(one("1E-3").real_value, 0.001);
  EXPECT_DOUBLE_EQ(one("2.0E+10").real_value, 2e10);
  EXPECT_DOUBLE_EQ(one("3_000.25").real_value, 3000.25);
  EXPECT_EQ(one("1.5").kind, Tok::RealLit);
  EXPECT_EQ(first_code("1e999"), "ST012");
}

TEST(Lexer, RangeAndBitAccessAreNotReals) {
  auto l = lex("1..10 w.3 a.1.2");
  const std::vector<Tok> want = {Tok::IntLit, Tok::DotDot, Tok::IntLit, Tok::Ident, Tok::Dot, Tok::IntLit,
                                 Tok::Ident, Tok::Dot, Tok::IntLit, Tok::Dot, Tok::IntLit, Tok::Eof};
  ASSERT_EQ(l->toks.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(l->toks[i].kind, want[i]) << i;
}

TEST(Lexer, StringLiterals) {
  Token t = one("'abc'");
  EXPECT_EQ(t.kind, Tok::StringLit);
  EXPECT_EQ(t.lit, LiteralKind::String);
  EXPECT_EQ(t.str_value, "abc");
  EXPECT_EQ(one("'a$$b$'c'").str_value, "a$b'c");
  EXPECT_EQ(one("'$L$N$P$R$T'").str_value, "\n\n\f\r\t");
  EXPECT_EQ(one("'$l$n$t'").str_value, "\n\n\t");
  EXPECT_EQ(one("'$41$42'").str_value, "AB");
  EXPECT_EQ(one("''").str_value, "");
  Token w = one("\"wide $\"q$\"\"");
  EXPECT_EQ(w.kind, Tok::WStringLit);
  EXPECT_EQ(w.lit, LiteralKind::WString);
  EXPECT_EQ(w.str_value, "wide \"q\"");
  EXPECT_EQ(one("\"$0041\"").str_value, "A");
}

TEST(Lexer, StringErrors) {
  auto l = lex("x := 'abc;\ny := 1;");
  ASSERT_EQ(codes(*l), std::vector<std::string>{"ST003"});
  EXPECT_EQ(l->diags.all()[0].loc.line, 1u);
  EXPECT_EQ(l->diags.all()[0].loc.col, 6u);
  // The next line still lexes normally.
  EXPECT_EQ(l->toks[3].text, "y");
  EXPECT_EQ(first_code("'bad $Q escape'"), "ST004");
  EXPECT_EQ(first_code("\"open"), "ST003");
}

TEST(Lexer, Durations) {
  Token t = one("T#1h2m3s4ms5us6ns");
  EXPECT_EQ(t.kind, Tok::TimeLit);
  EXPECT_EQ(t.lit, LiteralKind::Time);
  EXPECT_EQ(t.time_ns, 3723 * kSec + 4'000'000 + 5'000 + 6);
  EXPECT_EQ(t.prefix, "T");
  EXPECT_FALSE(t.is_long);
  EXPECT_EQ(one("TIME#5s").time_ns, 5 * kSec);
  EXPECT_EQ(one("time#5S").time_ns, 5 * kSec);
  EXPECT_EQ(one("T#1d").time_ns, 86400 * kSec);
  EXPECT_EQ(one("T#1.5s").time_ns, 1'500'000'000);
  EXPECT_EQ(one("T#0.5ms").time_ns, 500'000);
  EXPECT_EQ(one("T#1s_500ms").time_ns, 1'500'000'000);
  EXPECT_EQ(one("T#-5s").time_ns, -5 * kSec);
  EXPECT_EQ(one("T#2.5h").time_ns, 9000 * kSec);
  EXPECT_EQ(one("T#100ms").time_ns, 100'000'000);
  Token lt = one("LTIME#1us");
  EXPECT_TRUE(lt.is_long);
  EXPECT_EQ(lt.time_ns, 1000);
  EXPECT_EQ(lt.prefix, "LTIME");
  EXPECT_TRUE(one("LT#1ns").is_long);
}

TEST(Lexer, DurationErrors) {
  EXPECT_EQ(first_message("T#5x"), "T#5x: unknown duration unit 'x' (use d, h, m, s, ms, us or ns)");
  EXPECT_EQ(first_code("T#5"), "ST008");
  EXPECT_EQ(first_code("T#"), "ST008");
  EXPECT_EQ(first_code("T#5sec"), "ST008");
  EXPECT_EQ(first_code("T#999999999999d"), "ST008");
  // A malformed literal is one token.
  auto l = lex("T#5x;");
  EXPECT_EQ(l->toks[1].kind, Tok::Semi);
}

TEST(Lexer, DatesAndTimesOfDay) {
  Token d = one("D#2024-01-31");
  EXPECT_EQ(d.lit, LiteralKind::Date);
  EXPECT_EQ(d.time_ns, int64_t{19753} * 86400 * kSec);
  EXPECT_EQ(one("DATE#1970-01-01").time_ns, 0);
  EXPECT_TRUE(one("LDATE#1970-01-02").is_long);
  EXPECT_EQ(one("LD#1970-01-02").time_ns, 86400 * kSec);
  Token tod = one("TOD#12:30:15.5");
  EXPECT_EQ(tod.lit, LiteralKind::TimeOfDay);
  EXPECT_EQ(tod.time_ns, (12 * 3600 + 30 * 60 + 15) * kSec + 500'000'000);
  EXPECT_EQ(one("TIME_OF_DAY#00:00:01").time_ns, kSec);
  EXPECT_TRUE(one("LTOD#01:00:00").is_long);
  EXPECT_EQ(one("LTIME_OF_DAY#01:00:00").time_ns, 3600 * kSec);
  Token dt = one("DT#2024-01-31-12:30:15");
  EXPECT_EQ(dt.lit, LiteralKind::DateTime);
  EXPECT_EQ(dt.time_ns, int64_t{19753} * 86400 * kSec + (12 * 3600 + 30 * 60 + 15) * kSec);
  EXPECT_EQ(one("DATE_AND_TIME#1970-01-01-00:00:00").time_ns, 0);
  EXPECT_TRUE(one("LDT#2000-02-29-23:59:59").is_long);
}

TEST(Lexer, DateErrors) {
  EXPECT_EQ(first_code("D#2024-13-01"), "ST009");
  EXPECT_EQ(first_code("D#2023-02-29"), "ST009");
  EXPECT_EQ(first_code("D#24-01-01"), "ST009");
  EXPECT_EQ(first_code("TOD#25:00:00"), "ST009");
  EXPECT_EQ(first_code("TOD#12:61:00"), "ST009");
  EXPECT_EQ(first_code("DT#2024-01-01"), "ST009");
  EXPECT_EQ(first_code("DT#2024-01-01-12:00:00x"), "ST009");
  EXPECT_EQ(first_code("D#9999-12-31"), "ST009");
  EXPECT_EQ(first_code("DT#1000-01-01-00:00:00"), "ST009");
  EXPECT_EQ(one("D#1969-12-31").time_ns, -86400 * kSec);
}

TEST(Lexer, DirectAddresses) {
  Token a = one("%IX0.3");
  EXPECT_EQ(a.kind, Tok::DirectAddr);
  EXPECT_EQ(a.area, 'I');
  EXPECT_EQ(a.size, 'X');
  EXPECT_EQ(a.parts, (std::vector<uint32_t>{0, 3}));
  Token b = one("%I0.3");
  EXPECT_EQ(b.size, 'X');
  EXPECT_EQ(b.parts, (std::vector<uint32_t>{0, 3}));
  Token c = one("%QW3");
  EXPECT_EQ(c.area, 'Q');
  EXPECT_EQ(c.size, 'W');
  EXPECT_EQ(c.parts, (std::vector<uint32_t>{3}));
  EXPECT_EQ(one("%MD10").size, 'D');
  EXPECT_EQ(one("%IB2").size, 'B');
  EXPECT_EQ(one("%QL1").size, 'L');
  EXPECT_EQ(one("%qx1.7").area, 'Q');
  EXPECT_TRUE(one("%I*").parts.empty());
}

TEST(Lexer, DirectAddressErrors) {
  EXPECT_EQ(first_code("%Z0"), "ST010");
  EXPECT_EQ(first_code("%IY3"), "ST010");
  EXPECT_EQ(first_code("%IX"), "ST010");
  EXPECT_EQ(first_code("%"), "ST010");
}

TEST(Lexer, TypedLiteralPiecesAreSeparateTokens) {
  auto l = lex("INT#16#FF Color#Red");
  const std::vector<Tok> want = {Tok::Ident, Tok::Hash, Tok::IntLit, Tok::Ident, Tok::Hash, Tok::Ident, Tok::Eof};
  ASSERT_EQ(l->toks.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(l->toks[i].kind, want[i]) << i;
  EXPECT_EQ(l->toks[2].int_value, 255u);
}

TEST(Lexer, ByteOrderMarkAndCrLf) {
  auto l = lex("\xEF\xBB\xBFPROGRAM p\r\n  x := 'a';\r\nEND_PROGRAM\r\n");
  EXPECT_FALSE(l->diags.has_errors()) << l->diags.render_all();
  ASSERT_EQ(l->toks.size(), 8u);
  EXPECT_EQ(l->toks[0].kind, Tok::Program);
  EXPECT_EQ(l->toks[0].loc.col, 4u);  // columns count bytes
  EXPECT_EQ(l->toks[4].str_value, "a");
  EXPECT_EQ(l->toks[6].loc.line, 3u);
}

TEST(Lexer, GarbageIsReportedOnceAndSkipped) {
  auto l = lex("a @ b ? c \xC3\xA9 d");
  EXPECT_EQ(codes(*l), (std::vector<std::string>{"ST001", "ST001", "ST001"}));
  ASSERT_EQ(l->toks.size(), 5u);
  EXPECT_EQ(l->toks[3].text, "d");
}

}  // namespace
}  // namespace plcfi::st
