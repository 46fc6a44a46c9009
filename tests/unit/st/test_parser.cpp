// Unit tests of the ST parser: every construct, precedence, locations, recovery and robustness.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "st/syntax/ast_dump.hpp"
#include "st/syntax/parser.hpp"

namespace plcfi::st {
namespace {

struct Parsed {
  SourceManager sm;
  DiagEngine diags{sm};
  std::unique_ptr<CompilationUnit> unit;
  std::unique_ptr<TestFile> tests;
  ExprPtr expr;

  std::vector<std::pair<std::string, uint32_t>> errors() const {
    std::vector<std::pair<std::string, uint32_t>> out;
    for (const auto& d : diags.all()) out.emplace_back(d.code, d.loc.line);
    return out;
  }
  std::vector<std::string> codes() const {
    std::vector<std::string> out;
    for (const auto& d : diags.all()) out.push_back(d.code);
    return out;
  }
};

std::unique_ptr<Parsed> unit(const std::string& text) {
  auto p = std::make_unique<Parsed>();
  const uint32_t f = p->sm.add("unit.st", text);
  p->unit = parse_unit(p->sm, f, p->diags);
  return p;
}

std::unique_ptr<Parsed> test_file(const std::string& text) {
  auto p = std::make_unique<Parsed>();
  const uint32_t f = p->sm.add("tests.st", text);
  p->tests = parse_test_file(p->sm, f, p->diags);
  return p;
}

// Dump of one expression; failures to parse show up as the diagnostics.
std::string expr(const std::string& text) {
  Parsed p;
  const uint32_t f = p.sm.add("expr", text);
  ExprPtr e = parse_expression(p.sm, f, p.diags);
  if (p.diags.has_errors()) return "ERROR: " + p.diags.render_all();
  return e ? dump(*e) : "null";
}

// Dump of the body of a PROGRAM wrapped around `stmts`.
std::string body(const std::string& stmts) {
  auto p = unit("PROGRAM p\n" + stmts + "\nEND_PROGRAM\n");
  if (p->diags.has_errors()) return "ERROR: " + p->diags.render_all();
  if (p->unit->pous.size() != 1) return "ERROR: no POU";
  return dump(p->unit->pous[0]->body);
}

// The single variable declaration of `VAR <decl> END_VAR`.
std::string var_type(const std::string& decl) {
  auto p = unit("PROGRAM p VAR " + decl + " END_VAR END_PROGRAM");
  if (p->diags.has_errors()) return "ERROR: " + p->diags.render_all();
  const auto& d = p->unit->pous[0]->var_blocks.at(0).decls.at(0);
  return dump(*d.type) + (d.init ? " := " + dump(*d.init) : std::string());
}

using Errors = std::vector<std::pair<std::string, uint32_t>>;

// ------------------------------------------------------------------ expressions

TEST(ParserExpr, Precedence) {
  EXPECT_EQ(expr("-2**2"), "(neg (** 2 2))");
  EXPECT_EQ(expr("NOT a AND b"), "(AND (NOT a) b)");
  EXPECT_EQ(expr("2**3**2"), "(** (** 2 3) 2)");
  EXPECT_EQ(expr("a - b - c"), "(- (- a b) c)");
  EXPECT_EQ(expr("a + b * c"), "(+ a (* b c))");
  EXPECT_EQ(expr("(a + b) * c"), "(* (+ a b) c)");
  EXPECT_EQ(expr("a OR b XOR c AND d"), "(OR a (XOR b (AND c d)))");
  EXPECT_EQ(expr("a = b AND c <> d"), "(AND (= a b) (<> c d))");
  EXPECT_EQ(expr("a < b = c >= d"), "(= (< a b) (>= c d))");
  EXPECT_EQ(expr("a + b < c * d"), "(< (+ a b) (* c d))");
  EXPECT_EQ(expr("a & b OR c"), "(OR (AND a b) c)");
  EXPECT_EQ(expr("a MOD b / c"), "(/ (MOD a b) c)");
  EXPECT_EQ(expr("-a * b"), "(* (neg a) b)");
  EXPECT_EQ(expr("NOT NOT x"), "(NOT (NOT x))");
  EXPECT_EQ(expr("+x"), "(plus x)");
  EXPECT_EQ(expr("2 ** -1"), "(** 2 (neg 1))");
  EXPECT_EQ(expr("a <= b"), "(<= a b)");
  EXPECT_EQ(expr("a > b"), "(> a b)");
}

TEST(ParserExpr, PostfixChains) {
  EXPECT_EQ(expr("a.b[i, j].c^.d"), "(. (^ (. ([] (. a b) i j) c)) d)");
  EXPECT_EQ(expr("w.3"), "(bit w 3)");
  EXPECT_EQ(expr("s.w.15"), "(bit (. s w) 15)");
  EXPECT_EQ(expr("f(1)"), "(call f 1)");
  EXPECT_EQ(expr("fbs[2](IN := x)"), "(call ([] fbs 2) (IN := x))");
  EXPECT_EQ(expr("THIS^.m()"), "(call (. (^ THIS) m))");
  EXPECT_EQ(expr("SUPER^.Init(1, 2)"), "(call (. (^ SUPER) Init) 1 2)");
  EXPECT_EQ(expr("obj.method(1).x"), "(. (call (. obj method) 1) x)");
  EXPECT_EQ(expr("p^^"), "(^ (^ p))");
  EXPECT_EQ(expr("fb.Method.Type"), "(. (. fb Method) Type)");
  EXPECT_EQ(unit("PROGRAM p\n  x := fb.\nEND_PROGRAM\n")->errors(), (Errors{{"ST133", 2}}));
}

TEST(ParserExpr, CallArguments) {
  EXPECT_EQ(expr("fb(IN := x, PT := T#1s, Q => q, NOT Done => nd, E =>)"),
            "(call fb (IN := x) (PT := T#1000000000ns) (Q => q) (NOT Done => nd) (E => _))");
  EXPECT_EQ(expr("f(a, b + 1, g(c))"), "(call f a (+ b 1) (call g c))");
  EXPECT_EQ(expr("f()"), "(call f)");
}

TEST(ParserExpr, Literals) {
  EXPECT_EQ(expr("42"), "42");
  EXPECT_EQ(expr("16#FF"), "255");
  EXPECT_EQ(expr("1.5e3"), "1500");
  EXPECT_EQ(expr("TRUE"), "TRUE");
  EXPECT_EQ(expr("false"), "FALSE");
  EXPECT_EQ(expr("'a$Nb'"), "'a\nb'");
  EXPECT_EQ(expr("\"w\""), "\"w\"");
  EXPECT_EQ(expr("T#1s"), "T#1000000000ns");
  EXPECT_EQ(expr("-5"), "(neg 5)");
  EXPECT_EQ(expr("NULL"), "NULL");
  EXPECT_EQ(expr("null"), "NULL");
  EXPECT_EQ(expr("%IX0.3 AND %QW2.1"), "(AND %IX0.3 %QW2.1)");
}

TEST(ParserExpr, TypedLiterals) {
  EXPECT_EQ(expr("INT#5"), "INT#5");
  EXPECT_EQ(expr("INT#16#FF"), "INT#255");
  EXPECT_EQ(expr("REAL#1.5"), "REAL#1.5");
  EXPECT_EQ(expr("BOOL#TRUE"), "BOOL#TRUE");
  EXPECT_EQ(expr("BOOL#1"), "BOOL#TRUE");
  EXPECT_EQ(expr("BOOL#0"), "BOOL#FALSE");
  EXPECT_EQ(expr("INT#-5"), "(neg INT#5)");
  EXPECT_EQ(expr("STRING#'x'"), "STRING#'x'");
  EXPECT_EQ(expr("Color#Red"), "(enum Color Red)");
  EXPECT_EQ(expr("LTIME#1ms"), "LTIME#1000000ns");
  Parsed p;
  const uint32_t f = p.sm.add("e", "INT#-5");
  ExprPtr e = parse_expression(p.sm, f, p.diags);
  ASSERT_EQ(e->kind, ExprKind::Unary);
  const auto& lit = static_cast<const LiteralExpr&>(*static_cast<const UnaryExpr&>(*e).operand);
  EXPECT_EQ(lit.type_prefix, "INT");
  EXPECT_EQ(lit.int_value, 5u);
  EXPECT_EQ(lit.lit, LiteralKind::Int);
}

TEST(ParserExpr, TimeLiteralFields) {
  Parsed p;
  const uint32_t f = p.sm.add("e", "LT#1.5s");
  ExprPtr e = parse_expression(p.sm, f, p.diags);
  ASSERT_EQ(e->kind, ExprKind::Literal);
  const auto& lit = static_cast<const LiteralExpr&>(*e);
  EXPECT_EQ(lit.lit, LiteralKind::Time);
  EXPECT_EQ(lit.time_ns, 1'500'000'000);
  EXPECT_TRUE(lit.is_long);
  EXPECT_EQ(lit.type_prefix, "LT");
}

TEST(ParserExpr, DirectAddressFields) {
  Parsed p;
  const uint32_t f = p.sm.add("e", "%QW3");
  ExprPtr e = parse_expression(p.sm, f, p.diags);
  ASSERT_EQ(e->kind, ExprKind::DirectAddr);
  const auto& a = static_cast<const DirectAddrExpr&>(*e);
  EXPECT_EQ(a.area, 'Q');
  EXPECT_EQ(a.size, 'W');
  EXPECT_EQ(a.parts, std::vector<uint32_t>{3});
  EXPECT_EQ(a.text, "%QW3");
}

TEST(ParserExpr, Initializers) {
  EXPECT_EQ(expr("[1, 2, 3(0)]"), "[1, 2, 3(0)]");
  EXPECT_EQ(expr("[[1, 2], [3, 4]]"), "[[1, 2], [3, 4]]");
  EXPECT_EQ(expr("(a := 1, b := 2)"), "(a := 1, b := 2)");
  EXPECT_EQ(expr("(a := [1, 2], b := (c := 3))"), "(a := [1, 2], b := (c := 3))");
  EXPECT_EQ(expr("[(x := 1), (x := 2)]"), "[(x := 1), (x := 2)]");
  EXPECT_EQ(expr("[2()]"), "[2()]");
  EXPECT_EQ(expr("(a + 1)"), "(+ a 1)");
}

TEST(ParserExpr, TrailingTokensAreAnError) {
  Parsed p;
  const uint32_t f = p.sm.add("e", "a + b c");
  parse_expression(p.sm, f, p.diags);
  EXPECT_EQ(p.codes(), std::vector<std::string>{"ST131"});
}

// ------------------------------------------------------------------ statements

TEST(ParserStmt, AssignmentsAndCalls) {
  EXPECT_EQ(body("x := 1;"), "((:= x 1))");
  EXPECT_EQ(body("r REF= pt;"), "((REF= r pt))");
  EXPECT_EQ(body("f(a, b);"), "((call f a b))");
  EXPECT_EQ(body("fb(IN := x, PT := T#1s, Q => q, NOT Done => nd);"),
            "((call fb (IN := x) (PT := T#1000000000ns) (Q => q) (NOT Done => nd)))");
  EXPECT_EQ(body("obj.method(1);"), "((call (. obj method) 1))");
  EXPECT_EQ(body("THIS^.m();"), "((call (. (^ THIS) m)))");
  EXPECT_EQ(body("a.b[1].c := %IX0.1;"), "((:= (. ([] (. a b) 1) c) %IX0.1))");
  EXPECT_EQ(body("%QX0.1 := TRUE;"), "((:= %QX0.1 TRUE))");
  EXPECT_EQ(body("w.3 := TRUE;"), "((:= (bit w 3) TRUE))");
  EXPECT_EQ(body("x := 1; ;"), "((:= x 1) ;)");
  EXPECT_EQ(body("EXIT; CONTINUE; RETURN;"), "(EXIT CONTINUE RETURN)");
}

TEST(ParserStmt, If) {
  EXPECT_EQ(body("IF a THEN x := 1; END_IF"), "((if a ((:= x 1))))");
  EXPECT_EQ(body("IF a THEN x := 1; ELSIF b THEN x := 2; ELSIF c THEN ; ELSE x := 3; END_IF;"),
            "((if a ((:= x 1)) elsif b ((:= x 2)) elsif c (;) else ((:= x 3))))");
  EXPECT_EQ(body("IF a THEN END_IF"), "((if a ()))");
}

TEST(ParserStmt, Case) {
  EXPECT_EQ(body("CASE s OF 1, 2: x := 1; 5..10: x := 2; x := 3; -1: ; ELSE x := 4; END_CASE"),
            "((case s [1, 2] ((:= x 1)) [5..10] ((:= x 2) (:= x 3)) [(neg 1)] (;) else ((:= x 4))))");
  EXPECT_EQ(body("CASE c OF Red, Green: x := 1; Color#Blue: x := 2; kMax: ; E.Val: ; END_CASE"),
            "((case c [Red, Green] ((:= x 1)) [(enum Color Blue)] ((:= x 2)) [kMax] (;) [(. E Val)] (;)))");
  EXPECT_EQ(body("CASE s OF -5..-1: ; INT#3: ; END_CASE"), "((case s [(neg 5)..(neg 1)] (;) [INT#3] (;)))");
}

TEST(ParserStmt, Loops) {
  EXPECT_EQ(body("FOR i := 1 TO 10 DO x := i; END_FOR"), "((for i 1 10 _ ((:= x i))))");
  EXPECT_EQ(body("FOR i := a TO b BY -2 DO EXIT; END_FOR;"), "((for i a b (neg 2) (EXIT)))");
  EXPECT_EQ(body("WHILE x < 10 DO x := x + 1; END_WHILE"), "((while (< x 10) ((:= x (+ x 1)))))");
  EXPECT_EQ(body("REPEAT x := x - 1; UNTIL x <= 0 END_REPEAT"), "((repeat ((:= x (- x 1))) (<= x 0)))");
}

TEST(ParserStmt, Nested) {
  EXPECT_EQ(body("IF a THEN FOR i := 1 TO 2 DO CASE i OF 1: WHILE b DO b := FALSE; END_WHILE END_CASE END_FOR END_IF"),
            "((if a ((for i 1 2 _ ((case i [1] ((while b ((:= b FALSE))))))))))");
}

TEST(ParserStmt, LocationsOfBranches) {
  auto p = unit(
      "PROGRAM p\n"
      "  IF a THEN\n"
      "    x := 1;\n"
      "  ELSIF b THEN\n"
      "    x := 2;\n"
      "  ELSE\n"
      "    x := 3;\n"
      "  END_IF\n"
      "  CASE s OF\n"
      "    1, 2:\n"
      "      x := 1;\n"
      "     3: x := 2;\n"
      "  ELSE\n"
      "    x := 4;\n"
      "  END_CASE\n"
      "END_PROGRAM\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  const Pou& pou = *p->unit->pous[0];
  EXPECT_EQ(pou.loc.line, 1u);
  EXPECT_EQ(pou.end_loc.line, 16u);
  EXPECT_EQ(pou.end_loc.col, 1u);
  const auto& ifs = static_cast<const IfStmt&>(*pou.body[0]);
  EXPECT_EQ(ifs.loc.line, 2u);
  EXPECT_EQ(ifs.loc.col, 3u);
  EXPECT_EQ(ifs.arms[0].loc.line, 2u);
  EXPECT_EQ(ifs.arms[1].loc.line, 4u);
  EXPECT_EQ(ifs.arms[1].loc.col, 3u);
  EXPECT_EQ(ifs.else_loc.line, 6u);
  EXPECT_EQ(ifs.arms[0].body[0]->loc.line, 3u);
  EXPECT_EQ(ifs.arms[0].body[0]->loc.col, 5u);
  const auto& cs = static_cast<const CaseStmt&>(*pou.body[1]);
  EXPECT_EQ(cs.loc.line, 9u);
  EXPECT_EQ(cs.arms[0].loc.line, 10u);
  EXPECT_EQ(cs.arms[0].loc.col, 5u);
  EXPECT_EQ(cs.arms[1].loc.line, 12u);
  EXPECT_EQ(cs.arms[1].loc.col, 6u);
  EXPECT_EQ(cs.else_loc.line, 13u);
  // Expression nodes carry the location of their first token.
  const auto& assign = static_cast<const AssignStmt&>(*ifs.arms[0].body[0]);
  EXPECT_EQ(assign.rhs->loc.line, 3u);
  EXPECT_EQ(assign.rhs->loc.col, 10u);
}

TEST(ParserStmt, ExpressionLocations) {
  Parsed p;
  const uint32_t f = p.sm.add("e", "a +\n  b.c");
  ExprPtr e = parse_expression(p.sm, f, p.diags);
  const auto& bin = static_cast<const BinaryExpr&>(*e);
  EXPECT_EQ(bin.loc.line, 1u);
  EXPECT_EQ(bin.rhs->loc.line, 2u);
  EXPECT_EQ(bin.rhs->loc.col, 3u);
  const auto& mem = static_cast<const MemberExpr&>(*bin.rhs);
  EXPECT_EQ(mem.member.loc.col, 5u);
}

// ------------------------------------------------------------------ types and declarations

TEST(ParserDecl, TypeSpecs) {
  EXPECT_EQ(var_type("x : INT;"), "INT");
  EXPECT_EQ(var_type("x : STRING;"), "STRING");
  EXPECT_EQ(var_type("x : STRING[20] := 'abc';"), "STRING[20] := 'abc'");
  EXPECT_EQ(var_type("x : STRING(20);"), "STRING[20]");
  EXPECT_EQ(var_type("x : WSTRING[10];"), "WSTRING[10]");
  EXPECT_EQ(var_type("x : ARRAY [1..10, -2..2] OF INT;"), "ARRAY[1..10, (neg 2)..2] OF INT");
  EXPECT_EQ(var_type("x : ARRAY [0..N-1] OF ARRAY [1..2] OF BOOL;"), "ARRAY[0..(- N 1)] OF ARRAY[1..2] OF BOOL");
  EXPECT_EQ(var_type("x : ARRAY [1..3] OF INT := [1, 2, 3(0)];"), "ARRAY[1..3] OF INT := [1, 2, 3(0)]");
  EXPECT_EQ(var_type("x : STRUCT a : INT; b, c : BOOL := TRUE; END_STRUCT;"),
            "STRUCT a:INT; b,c:BOOL:=TRUE; END_STRUCT");
  EXPECT_EQ(var_type("x : (A, B := 5, C);"), "(A, B := 5, C)");
  EXPECT_EQ(var_type("x : INT (A := 1, B := 2);"), "(A := 1, B := 2) INT");
  EXPECT_EQ(var_type("x : (A := 1, B) DINT;"), "(A := 1, B) DINT");
  EXPECT_EQ(var_type("x : INT (0..100) := 5;"), "INT (0..100) := 5");
  EXPECT_EQ(var_type("x : REF_TO INT;"), "REF_TO INT");
  EXPECT_EQ(var_type("x : POINTER TO Point;"), "POINTER TO Point");
  EXPECT_EQ(var_type("x : Point := (x := 1.5, y := 2);"), "Point := (x := 1.5, y := 2)");
  EXPECT_EQ(var_type("x : ARRAY [1..2, 1..2] OF INT := [[1, 2], [3, 4]];"),
            "ARRAY[1..2, 1..2] OF INT := [[1, 2], [3, 4]]");
}

// `fb : FB_X(...)` holds FB_init's arguments; an elementary integer type before '(' is
// still a typed enumeration or a subrange, and so is any type with '..' in the parentheses.
TEST(ParserDecl, FbInitArguments) {
  EXPECT_EQ(var_type("x : FB_Log('pump', nSize := 3);"), "(FB_init FB_Log 'pump' (nSize := 3))");
  EXPECT_EQ(var_type("x : FB_Log();"), "(FB_init FB_Log)");
  EXPECT_EQ(var_type("x : Lib.FB_Log(n := 1);"), "(FB_init FB_Log (n := 1))");
  EXPECT_EQ(var_type("x : FB_Log(a := f(1, 2), b := (1 + 2));"), "(FB_init FB_Log (a := (call f 1 2)) (b := (+ 1 2)))");
  EXPECT_EQ(var_type("x : UDINT (A := 1);"), "(A := 1) UDINT");
  EXPECT_EQ(var_type("x : MyInt (lo..hi);"), "MyInt (lo..hi)");
  EXPECT_EQ(var_type("x : MyInt (f(1)..10);"), "MyInt ((call f 1)..10)");
}

TEST(ParserDecl, VarBlocks) {
  auto p = unit(
      "FUNCTION_BLOCK fb\n"
      "VAR_INPUT a, b : INT := 5; END_VAR\n"
      "VAR_OUTPUT q : BOOL; END_VAR\n"
      "VAR_IN_OUT io : INT; END_VAR\n"
      "VAR_TEMP t : INT; END_VAR\n"
      "VAR_EXTERNAL e : INT; END_VAR\n"
      "VAR_STAT s : INT; END_VAR\n"
      "VAR CONSTANT k : INT := 1; END_VAR\n"
      "VAR RETAIN r : INT; END_VAR\n"
      "VAR PERSISTENT pp : INT; END_VAR\n"
      "VAR NON_RETAIN n : INT; END_VAR\n"
      "VAR x AT %IX0.0 : BOOL; y AT %QW4 : WORD; z AT %I* : BOOL; END_VAR\n"
      "END_FUNCTION_BLOCK\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  const auto& blocks = p->unit->pous[0]->var_blocks;
  ASSERT_EQ(blocks.size(), 11u);
  EXPECT_EQ(blocks[0].section, VarSection::Input);
  EXPECT_EQ(blocks[0].decls[0].names.size(), 2u);
  EXPECT_EQ(blocks[0].decls[0].names[1].text, "b");
  EXPECT_EQ(blocks[0].decls[0].section, VarSection::Input);
  EXPECT_EQ(blocks[0].decls[0].loc.line, 2u);
  EXPECT_EQ(blocks[0].decls[0].loc.col, 11u);
  EXPECT_EQ(blocks[1].section, VarSection::Output);
  EXPECT_EQ(blocks[2].section, VarSection::InOut);
  EXPECT_EQ(blocks[3].section, VarSection::Temp);
  EXPECT_EQ(blocks[4].section, VarSection::External);
  EXPECT_EQ(blocks[5].section, VarSection::Stat);
  EXPECT_TRUE(blocks[6].constant);
  EXPECT_TRUE(blocks[6].decls[0].constant);
  EXPECT_TRUE(blocks[7].retain);
  EXPECT_TRUE(blocks[7].decls[0].retain);
  EXPECT_TRUE(blocks[8].decls[0].retain);
  EXPECT_FALSE(blocks[9].retain);
  const auto& located = blocks[10].decls;
  ASSERT_TRUE(located[0].location.has_value());
  EXPECT_EQ(located[0].location->text, "%IX0.0");
  EXPECT_EQ(located[0].location->parts, (std::vector<uint32_t>{0, 0}));
  EXPECT_EQ(located[1].location->size, 'W');
  EXPECT_EQ(located[1].location->area, 'Q');
  EXPECT_TRUE(located[2].location->parts.empty());
}

TEST(ParserDecl, TypeBlock) {
  auto p = unit(
      "TYPE\n"
      "  Color : (Red, Green := 5, Blue);\n"
      "  Point : STRUCT x, y : REAL; END_STRUCT\n"
      "  Small : INT (0..100) := 10;\n"
      "  Buf : ARRAY [1..4] OF BYTE;\n"
      "END_TYPE\n"
      "TYPE Alias : INT := 5; END_TYPE\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  const auto& types = p->unit->types;
  ASSERT_EQ(types.size(), 5u);
  EXPECT_EQ(types[0].name.text, "Color");
  EXPECT_EQ(types[0].loc.line, 2u);
  EXPECT_EQ(dump(*types[0].spec), "(Red, Green := 5, Blue)");
  EXPECT_EQ(types[1].spec->kind, TypeSpecKind::Struct);
  EXPECT_EQ(types[2].spec->kind, TypeSpecKind::Subrange);
  EXPECT_EQ(dump(*types[2].init), "10");
  EXPECT_EQ(types[4].name.text, "Alias");
  EXPECT_EQ(dump(*types[4].init), "5");
}

TEST(ParserDecl, GlobalsAtTopLevel) {
  auto p = unit("VAR_GLOBAL CONSTANT kMax : INT := 10; END_VAR\nVAR_GLOBAL RETAIN g : INT; END_VAR\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  ASSERT_EQ(p->unit->globals.size(), 2u);
  EXPECT_EQ(p->unit->globals[0].section, VarSection::Global);
  EXPECT_TRUE(p->unit->globals[0].constant);
  EXPECT_TRUE(p->unit->globals[1].decls[0].retain);
}

// ------------------------------------------------------------------ POUs

TEST(ParserPou, ProgramFunctionAndFunctionBlock) {
  auto p = unit(
      "FUNCTION Add : INT\n"
      "VAR_INPUT a, b : INT; END_VAR\n"
      "  Add := a + b;\n"
      "END_FUNCTION\n"
      "FUNCTION NoResult\n"
      "  ;\n"
      "END_FUNCTION\n"
      "FUNCTION_BLOCK ABSTRACT Counter EXTENDS Base IMPLEMENTS I1, I2\n"
      "VAR cnt : INT; END_VAR\n"
      "  cnt := cnt + 1;\n"
      "METHOD PUBLIC Inc : INT\n"
      "VAR_INPUT step : INT; END_VAR\n"
      "  cnt := cnt + step;\n"
      "END_METHOD\n"
      "METHOD PRIVATE FINAL Reset\n"
      "  cnt := 0;\n"
      "END_METHOD\n"
      "PROPERTY PROTECTED Value : INT\n"
      "GET\n"
      "  Value := cnt;\n"
      "END_GET\n"
      "SET\n"
      "VAR tmp : INT; END_VAR\n"
      "  cnt := Value;\n"
      "END_SET\n"
      "END_PROPERTY\n"
      "END_FUNCTION_BLOCK\n"
      "FUNCTION_BLOCK FINAL Leaf\n"
      "METHOD OVERRIDE Inc : INT\n"
      "  SUPER^.Inc(1);\n"
      "END_METHOD\n"
      "  x := 1; (* body after methods *)\n"
      "END_FUNCTION_BLOCK\n"
      "PROGRAM Main\n"
      "END_PROGRAM\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  const auto& pous = p->unit->pous;
  ASSERT_EQ(pous.size(), 5u);
  EXPECT_EQ(pous[0]->kind, PouKind::Function);
  EXPECT_EQ(pous[0]->name.text, "Add");
  EXPECT_EQ(dump(*pous[0]->return_type), "INT");
  EXPECT_EQ(pous[0]->end_loc.line, 4u);
  EXPECT_EQ(pous[1]->return_type, nullptr);
  const Pou& fb = *pous[2];
  EXPECT_EQ(fb.kind, PouKind::FunctionBlock);
  EXPECT_TRUE(fb.is_abstract);
  EXPECT_EQ(fb.extends->text, "Base");
  ASSERT_EQ(fb.implements.size(), 2u);
  EXPECT_EQ(fb.implements[1].text, "I2");
  EXPECT_EQ(fb.body.size(), 1u);
  ASSERT_EQ(fb.methods.size(), 2u);
  EXPECT_EQ(fb.methods[0]->kind, PouKind::Method);
  EXPECT_EQ(fb.methods[0]->access, Access::Public);
  EXPECT_EQ(fb.methods[0]->var_blocks.size(), 1u);
  EXPECT_EQ(fb.methods[0]->loc.line, 11u);
  EXPECT_EQ(fb.methods[0]->end_loc.line, 14u);
  EXPECT_EQ(fb.methods[1]->access, Access::Private);
  EXPECT_TRUE(fb.methods[1]->is_final);
  EXPECT_EQ(fb.methods[1]->return_type, nullptr);
  ASSERT_EQ(fb.properties.size(), 1u);
  const PropertyDecl& prop = *fb.properties[0];
  EXPECT_EQ(prop.name.text, "Value");
  EXPECT_EQ(prop.access, Access::Protected);
  EXPECT_EQ(dump(*prop.type), "INT");
  ASSERT_NE(prop.getter, nullptr);
  ASSERT_NE(prop.setter, nullptr);
  EXPECT_EQ(prop.getter->kind, PouKind::Method);
  EXPECT_EQ(prop.getter->name.text, "Value");
  EXPECT_EQ(prop.getter->return_type, nullptr);
  EXPECT_EQ(prop.getter->body.size(), 1u);
  EXPECT_EQ(prop.setter->var_blocks.size(), 1u);
  EXPECT_TRUE(pous[3]->is_final);
  EXPECT_EQ(pous[3]->methods.size(), 1u);
  EXPECT_EQ(pous[3]->body.size(), 1u);
  EXPECT_EQ(pous[4]->kind, PouKind::Program);
  EXPECT_EQ(pous[4]->end_loc.line, 35u);
}

TEST(ParserPou, Interface) {
  auto p = unit(
      "INTERFACE ICounter EXTENDS IBase, IOther\n"
      "METHOD Inc : INT\n"
      "VAR_INPUT step : INT; END_VAR\n"
      "END_METHOD\n"
      "PROPERTY Value : DINT\n"
      "GET END_GET\n"
      "END_PROPERTY\n"
      "PROPERTY Bare : BOOL\n"
      "END_PROPERTY\n"
      "END_INTERFACE\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  const Pou& i = *p->unit->pous[0];
  EXPECT_EQ(i.kind, PouKind::Interface);
  ASSERT_EQ(i.implements.size(), 2u);
  EXPECT_EQ(i.implements[0].text, "IBase");
  ASSERT_EQ(i.methods.size(), 1u);
  EXPECT_FALSE(i.methods[0]->has_body);
  EXPECT_EQ(i.methods[0]->var_blocks.size(), 1u);
  ASSERT_EQ(i.properties.size(), 2u);
  ASSERT_NE(i.properties[0]->getter, nullptr);
  EXPECT_FALSE(i.properties[0]->getter->has_body);
  EXPECT_EQ(i.properties[1]->getter, nullptr);
}

TEST(ParserPou, InterfaceMethodWithStatementsIsAnError) {
  auto p = unit("INTERFACE I\nMETHOD M\n  x := 1;\nEND_METHOD\nEND_INTERFACE\n");
  EXPECT_EQ(p->errors(), (std::vector<std::pair<std::string, uint32_t>>{{"ST129", 3}}));
}

TEST(ParserPou, Configuration) {
  auto p = unit(
      "CONFIGURATION Cfg\n"
      "  VAR_GLOBAL g : INT; END_VAR\n"
      "  RESOURCE Res ON PLC\n"
      "    VAR_GLOBAL r : BOOL; END_VAR\n"
      "    TASK Fast (INTERVAL := T#10ms, PRIORITY := 1);\n"
      "    TASK Slow (INTERVAL := T#100ms, PRIORITY := 5);\n"
      "    PROGRAM P1 WITH Fast : Main;\n"
      "    PROGRAM P2 WITH Slow : Other (in := g, out => r);\n"
      "  END_RESOURCE\n"
      "END_CONFIGURATION\n"
      "CONFIGURATION Flat\n"
      "  TASK T1 (INTERVAL := T#20ms, PRIORITY := 2);\n"
      "  PROGRAM Inst WITH T1 : Main;\n"
      "  PROGRAM Free : Main;\n"
      "END_CONFIGURATION\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  ASSERT_EQ(p->unit->configs.size(), 2u);
  const ConfigDecl& c = p->unit->configs[0];
  EXPECT_EQ(c.name.text, "Cfg");
  EXPECT_EQ(c.globals.size(), 1u);
  ASSERT_EQ(c.resources.size(), 1u);
  const ResourceDecl& r = c.resources[0];
  EXPECT_EQ(r.name.text, "Res");
  EXPECT_EQ(r.on.text, "PLC");
  EXPECT_EQ(r.globals.size(), 1u);
  ASSERT_EQ(r.tasks.size(), 2u);
  EXPECT_EQ(r.tasks[0].name.text, "Fast");
  EXPECT_EQ(dump(*r.tasks[0].interval), "T#10000000ns");
  EXPECT_EQ(dump(*r.tasks[0].priority), "1");
  EXPECT_EQ(r.tasks[0].loc.line, 5u);
  ASSERT_EQ(r.programs.size(), 2u);
  EXPECT_EQ(r.programs[0].instance.text, "P1");
  EXPECT_EQ(r.programs[0].task->text, "Fast");
  EXPECT_EQ(r.programs[0].type.text, "Main");
  ASSERT_EQ(r.programs[1].args.size(), 2u);
  EXPECT_TRUE(r.programs[1].args[1].is_output);
  const ConfigDecl& flat = p->unit->configs[1];
  ASSERT_EQ(flat.resources.size(), 1u);
  EXPECT_EQ(flat.resources[0].tasks.size(), 1u);
  EXPECT_EQ(flat.resources[0].programs.size(), 2u);
  EXPECT_FALSE(flat.resources[0].programs[1].task.has_value());
}

TEST(ParserPou, UnknownTaskParameter) {
  auto p = unit("CONFIGURATION C TASK t (INTERVAL := T#1ms, SPEED := 2); END_CONFIGURATION");
  EXPECT_EQ(p->codes(), std::vector<std::string>{"ST128"});
}

// ------------------------------------------------------------------ test files

TEST(ParserTestFile, Blocks) {
  const std::string text =
      "SETUP\n"
      "VAR c : Counter; END_VAR\n"
      "  c.IN := FALSE;\n"
      "END_SETUP\n"
      "TEARDOWN\n"
      "  c.IN := FALSE;\n"
      "END_TEARDOWN\n"
      "TEST 'counts up'\n"
      "VAR x : INT; END_VAR\n"
      "  MOCK c.timer;\n"
      "  MOCK_FUNCTION Add RETURNS 5;\n"
      "  ADVANCE_TIME(T#1s);\n"
      "  ASSERT_EQ(c.cnt, 1);\n"
      "END_TEST\n"
      "TEST \"second\"\n"
      "  ASSERT_TRUE(TRUE);\n"
      "  MOCK_VERIFY_CALLED(c.timer);\n"
      "END_TEST\n"
      "FUNCTION_BLOCK Helper\n"
      "END_FUNCTION_BLOCK\n"
      "TYPE T : INT; END_TYPE\n";
  auto p = test_file(text);
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  const TestFile& tf = *p->tests;
  ASSERT_TRUE(tf.setup.has_value());
  EXPECT_EQ(tf.setup->name, "SETUP");
  EXPECT_EQ(tf.setup->var_blocks.size(), 1u);
  EXPECT_EQ(tf.setup->body.size(), 1u);
  ASSERT_TRUE(tf.teardown.has_value());
  EXPECT_EQ(tf.teardown->name, "TEARDOWN");
  ASSERT_EQ(tf.tests.size(), 2u);
  EXPECT_EQ(tf.tests[0].name, "counts up");
  EXPECT_EQ(tf.tests[0].loc.line, 8u);
  EXPECT_EQ(dump(tf.tests[0].body), "((mock (. c timer)) (mock_function Add 5) (call ADVANCE_TIME T#1000000000ns) "
                                    "(call ASSERT_EQ (. c cnt) 1))");
  EXPECT_EQ(tf.tests[1].name, "second");
  EXPECT_EQ(tf.decls.pous.size(), 1u);
  EXPECT_EQ(tf.decls.types.size(), 1u);

  SourceManager sm;
  EXPECT_TRUE(is_test_file(sm, sm.add("a", text)));
  EXPECT_TRUE(is_test_file(sm, sm.add("b", "(* c *) test 'x' END_TEST")));
  EXPECT_TRUE(is_test_file(sm, sm.add("c", "TEARDOWN END_TEARDOWN")));
  EXPECT_FALSE(is_test_file(sm, sm.add("d", "PROGRAM p END_PROGRAM")));
  EXPECT_FALSE(is_test_file(sm, sm.add("e", "")));
}

TEST(ParserTestFile, Errors) {
  auto p = test_file(
      "TEST missing_quotes\n"
      "  x := 1;\n"
      "END_TEST\n"
      "TEST 'unclosed'\n"
      "  x := 1;\n");
  EXPECT_EQ(p->errors(), (std::vector<std::pair<std::string, uint32_t>>{{"ST130", 1}, {"ST103", 5}}));
  EXPECT_EQ(p->tests->tests.size(), 2u);
}

TEST(ParserTestFile, MockIsAnOrdinaryNameOutsideTests) {
  EXPECT_EQ(body("mock := 1;"), "((:= mock 1))");
}

// ------------------------------------------------------------------ errors and recovery

TEST(ParserRecovery, ThreeSeparateErrors) {
  auto p = unit(
      "PROGRAM p\n"
      "VAR x : INT; y : INT; END_VAR\n"
      "  x := 1\n"            // missing ';'
      "  y := 2;\n"
      "  IF x > 1 y := 3; END_IF\n"  // missing THEN
      "  x = 4;\n"            // '=' instead of ':='
      "  y := 5;\n"
      "END_PROGRAM\n");
  EXPECT_EQ(p->errors(), (Errors{{"ST105", 3}, {"ST107", 5}, {"ST106", 6}}));
  // The statements around the errors are still there.
  EXPECT_EQ(p->unit->pous[0]->body.size(), 4u);
}

TEST(ParserRecovery, ErrorsInSeveralPous) {
  auto p = unit(
      "FUNCTION f : INT\n"
      "  f := ;\n"
      "END_FUNCTION\n"
      "FUNCTION_BLOCK fb\n"
      "VAR a : ; END_VAR\n"
      "END_FUNCTION_BLOCK\n"
      "PROGRAM p\n"
      "  WHILE TRUE x := 1; END_WHILE\n"
      "END_PROGRAM\n");
  EXPECT_EQ(p->errors(), (Errors{{"ST115", 2}, {"ST119", 5}, {"ST108", 8}}));
  EXPECT_EQ(p->unit->pous.size(), 3u);
}

TEST(ParserRecovery, MissingAndMismatchedEnds) {
  EXPECT_EQ(unit("PROGRAM p\n IF a THEN\n x := 1;\nEND_PROGRAM\n")->errors(), (Errors{{"ST110", 4}}));
  EXPECT_EQ(unit("PROGRAM p\n FOR i := 1 TO 2 DO\n x := 1;\nEND_PROGRAM\n")->errors(), (Errors{{"ST112", 4}}));
  EXPECT_EQ(unit("PROGRAM p\n WHILE a DO\n x := 1;\nEND_PROGRAM\n")->errors(), (Errors{{"ST113", 4}}));
  EXPECT_EQ(unit("PROGRAM p\n REPEAT\n x := 1;\nEND_PROGRAM\n")->errors(), (Errors{{"ST114", 4}}));
  EXPECT_EQ(unit("PROGRAM p\n CASE a OF 1: x := 1;\nEND_PROGRAM\n")->errors(), (Errors{{"ST111", 3}}));
  EXPECT_EQ(unit("FUNCTION_BLOCK fb\n x := 1;\nEND_PROGRAM\n")->errors(), (Errors{{"ST102", 3}}));
  EXPECT_EQ(unit("PROGRAM p\n x := 1;\n")->errors(), (Errors{{"ST103", 2}}));
  EXPECT_EQ(unit("PROGRAM p\n x := 1;\n END_IF\nEND_PROGRAM\n")->errors(), (Errors{{"ST118", 3}}));
  EXPECT_EQ(unit("PROGRAM p\n IF a THEN x := 1; END_FOR\nEND_PROGRAM\n")->errors(), (Errors{{"ST110", 2}}));
  EXPECT_EQ(unit("PROGRAM p\n ELSE x := 1;\nEND_PROGRAM\n")->errors(), (Errors{{"ST118", 2}}));
  EXPECT_EQ(unit("PROGRAM p\n IF a THEN ; ELSE ;\n ELSIF b THEN ; END_IF\nEND_PROGRAM\n")->errors(),
            (Errors{{"ST118", 3}}));
  EXPECT_EQ(unit("PROGRAM p\nVAR x : INT; END_VAR;\nVAR y : INT; END_VAR\nEND_PROGRAM\n")->errors(), Errors{});
  // Both missing ends are reported.
  EXPECT_EQ(unit("PROGRAM p\n FOR i := 1 TO 2 DO\n IF a THEN\nEND_PROGRAM\n")->errors(),
            (Errors{{"ST110", 4}, {"ST112", 4}}));
  // A missing END_METHOD does not swallow the function block's end.
  auto m = unit("FUNCTION_BLOCK fb\nMETHOD m\n x := 1;\nEND_FUNCTION_BLOCK\n");
  EXPECT_EQ(m->errors(), (Errors{{"ST103", 4}}));
  EXPECT_EQ(m->unit->pous[0]->end_loc.line, 4u);
}

TEST(ParserRecovery, MissingEndVar) {
  auto p = unit("PROGRAM p\nVAR\n x : INT;\n x := 1;\nEND_PROGRAM\n");
  EXPECT_EQ(p->errors(), (Errors{{"ST120", 4}}));
  EXPECT_EQ(p->unit->pous[0]->body.size(), 1u);
}

TEST(ParserRecovery, DeclarationErrors) {
  auto p = unit(
      "PROGRAM p\n"
      "VAR\n"
      "  a INT;\n"              // missing ':'
      "  b : INT := 5\n"        // missing ';'
      "  c : ARRAY [1 10] OF INT;\n"  // missing '..'
      "  d, e AT %IX0.0 : BOOL;\n"    // AT with two names
      "  f : INT;\n"
      "END_VAR\n"
      "END_PROGRAM\n");
  EXPECT_EQ(p->errors(), (Errors{{"ST134", 3}, {"ST105", 4}, {"ST119", 5}, {"ST123", 6}}));
  EXPECT_EQ(p->unit->pous[0]->var_blocks[0].decls.back().names[0].text, "f");
}

TEST(ParserRecovery, ForgottenPiecesDoNotSwallowTheNextLine) {
  EXPECT_EQ(unit("FUNCTION F :\n  F := 1;\nEND_FUNCTION\n")->errors(), (Errors{{"ST119", 1}}));
  EXPECT_EQ(unit("TYPE\n  E : (A, B)\n  S : INT;\nEND_TYPE\n")->errors(), (Errors{{"ST105", 2}}));
  EXPECT_EQ(unit("PROGRAM p\n  IF a THN x := 1; END_IF\nEND_PROGRAM\n")->errors(), (Errors{{"ST107", 2}}));
  EXPECT_EQ(unit("PROGRAM p\n  x := 1 ? 2;\nEND_PROGRAM\n")->codes(), std::vector<std::string>{"ST001"});
  EXPECT_EQ(unit("PROGRAM p\n  x := 1;\n  (* open\nEND_PROGRAM\n")->codes(), std::vector<std::string>{"ST002"});
  EXPECT_EQ(unit("PROGRAM p\n  s := 'open;\n  x := 1;\nEND_PROGRAM\n")->codes(), std::vector<std::string>{"ST003"});
}

TEST(ParserRecovery, DiagnosticsComeInSourceOrder) {
  auto p = unit("PROGRAM p\n  x := ;\n  y := 8#9;\n  z := ;\nEND_PROGRAM\n");
  EXPECT_EQ(p->errors(), (Errors{{"ST115", 2}, {"ST006", 3}, {"ST115", 4}}));
}

TEST(ParserDecl, VarConfigPaths) {
  auto p = unit("CONFIGURATION C\nVAR_CONFIG\n  R.Inst.sensor AT %IX1.0 : BOOL;\nEND_VAR\nEND_CONFIGURATION\n");
  ASSERT_FALSE(p->diags.has_errors()) << p->diags.render_all();
  const auto& decl = p->unit->configs[0].globals[0].decls[0];
  EXPECT_EQ(decl.section, VarSection::Config);
  EXPECT_EQ(decl.names[0].text, "R.Inst.sensor");
  EXPECT_EQ(decl.location->text, "%IX1.0");
}

TEST(ParserRecovery, GarbageAtTopLevelIsOneError) {
  auto p = unit("garbage here 1 2 3 ;\nPROGRAM p END_PROGRAM\n+ + +\n");
  EXPECT_EQ(p->errors(), (Errors{{"ST101", 1}, {"ST101", 3}}));
  EXPECT_EQ(p->unit->pous.size(), 1u);
}

TEST(ParserRecovery, MessagesArePrecise) {
  auto p = unit("PROGRAM p\n  IF a THEN x THEN END_IF\nEND_PROGRAM\n");
  ASSERT_EQ(p->diags.all().size(), 1u);
  EXPECT_EQ(p->diags.all()[0].message, "expected ':=' or '(' after 'x', found 'THEN'");
  auto q = unit("PROGRAM p\n  x := 1\n  y := 2;\nEND_PROGRAM\n");
  ASSERT_EQ(q->diags.all().size(), 1u);
  EXPECT_EQ(q->diags.all()[0].message, "expected ';' after assignment, found 'y'");
  EXPECT_EQ(q->diags.all()[0].loc.line, 2u);
  EXPECT_EQ(q->diags.all()[0].loc.col, 9u);
}

TEST(ParserRecovery, NestingTooDeep) {
  std::string deep_parens = "PROGRAM p\n x := " + std::string(300, '(') + "1" + std::string(300, ')') +
                            ";\n y := ;\nEND_PROGRAM\n";
  auto a = unit(deep_parens);
  EXPECT_EQ(a->errors(), (Errors{{"ST117", 2}, {"ST115", 3}}));

  std::string deep_ifs = "PROGRAM p\n";
  for (int i = 0; i < 300; ++i) deep_ifs += "IF a THEN\n";
  deep_ifs += "x := 1;\n";
  for (int i = 0; i < 300; ++i) deep_ifs += "END_IF\n";
  deep_ifs += "END_PROGRAM\n";
  auto b = unit(deep_ifs);
  EXPECT_EQ(b->codes(), std::vector<std::string>{"ST117"});

  std::string deep_unary = "PROGRAM p\n x := " + std::string(5000, '-') + "1;\nEND_PROGRAM\n";
  EXPECT_EQ(unit(deep_unary)->codes(), std::vector<std::string>{"ST117"});

  std::string deep_pow = "PROGRAM p\n x := ";
  for (int i = 0; i < 5000; ++i) deep_pow += "2 ** -";
  deep_pow += "1;\nEND_PROGRAM\n";
  EXPECT_EQ(unit(deep_pow)->codes(), std::vector<std::string>{"ST117"});

  std::string deep_refs = "PROGRAM p\nVAR x : ";
  for (int i = 0; i < 5000; ++i) deep_refs += i % 2 ? "REF_TO " : "POINTER TO ";
  deep_refs += "INT; END_VAR\nEND_PROGRAM\n";
  EXPECT_EQ(unit(deep_refs)->codes(), std::vector<std::string>{"ST117"});

  std::string deep_calls = "PROGRAM p\n x := ";
  for (int i = 0; i < 1000; ++i) deep_calls += "f(";
  deep_calls += std::string(1000, ')') + ";\nEND_PROGRAM\n";
  EXPECT_EQ(unit(deep_calls)->codes(), std::vector<std::string>{"ST117"});

  std::string deep_arrays = "PROGRAM p\nVAR x : ";
  for (int i = 0; i < 1000; ++i) deep_arrays += "ARRAY [1..2] OF ";
  deep_arrays += "INT; END_VAR\nEND_PROGRAM\n";
  EXPECT_TRUE(unit(deep_arrays)->diags.has_errors());

  std::string deep_init = "PROGRAM p\nVAR x : INT := " + std::string(1000, '[') + std::string(1000, ']') +
                          "; END_VAR\nEND_PROGRAM\n";
  EXPECT_TRUE(unit(deep_init)->diags.has_errors());

  std::string deep_struct = "TYPE t : ";
  for (int i = 0; i < 500; ++i) deep_struct += "STRUCT a : ";
  deep_struct += "INT;";
  for (int i = 0; i < 500; ++i) deep_struct += " END_STRUCT";
  deep_struct += " END_TYPE";
  EXPECT_TRUE(unit(deep_struct)->diags.has_errors());
}

// ------------------------------------------------------------------ robustness

const char* const kRealistic = R"ST(
(* A realistic program used as the seed for mutation tests. *)
{attribute 'qualified_only'}
TYPE
  Mode : (Idle, Run := 5, Fault);
  Cfg : STRUCT
    limit : INT := 100;
    name : STRING[20] := 'pump$N';
    gains : ARRAY [1..3] OF REAL := [1.0, 2(0.5)];
  END_STRUCT
  Pct : INT (0..100);
END_TYPE
VAR_GLOBAL CONSTANT kMax : DINT := 16#7FFF_FFFF; END_VAR
INTERFACE IPump
  METHOD Start : BOOL VAR_INPUT speed : REAL; END_VAR END_METHOD
  PROPERTY Running : BOOL END_PROPERTY
END_INTERFACE
FUNCTION_BLOCK Pump EXTENDS Base IMPLEMENTS IPump
VAR_INPUT en : BOOL; sp : REAL := 1.5E2; END_VAR
VAR_OUTPUT q AT %QX0.1 : BOOL; END_VAR
VAR t : TON; m : Mode := Mode#Idle; r : REF_TO Cfg; c : Cfg := (limit := 5); END_VAR
  t(IN := en AND NOT q, PT := T#1s_500ms, Q => q);
  CASE m OF
    Mode#Idle: IF en THEN m := Mode#Run; END_IF
    Mode#Run, 7..9: WHILE sp > 0.0 DO sp := sp - 1.0; IF sp < 10 THEN EXIT; END_IF END_WHILE
  ELSE
    m := Mode#Fault;
  END_CASE
METHOD PUBLIC Start : BOOL
VAR_INPUT speed : REAL; END_VAR
  sp := speed; Start := TRUE; THIS^.q := %IX0.3;
END_METHOD
PROPERTY Running : BOOL
GET Running := q; END_GET
END_PROPERTY
END_FUNCTION_BLOCK
PROGRAM Main
VAR p : Pump; i : INT; a : ARRAY [0..9] OF INT; w : WORD; d : DT := DT#2024-01-31-12:30:15; END_VAR
  FOR i := 0 TO 9 BY 1 DO a[i] := i * 2 ** 2 MOD 7; END_FOR
  REPEAT i := i - 1; UNTIL i <= -5 END_REPEAT
  w.3 := p.Running XOR (i <> 0);
  p.Start(speed := REAL#2.5);
  IF a[1] >= INT#-5 AND TOD#12:00:00 > TOD#11:00:00 THEN RETURN; ELSIF w = 16#FF THEN CONTINUE; END_IF;
END_PROGRAM
CONFIGURATION Plant
  RESOURCE R ON PLC
    TASK Cyclic (INTERVAL := T#10ms, PRIORITY := 1);
    PROGRAM Inst WITH Cyclic : Main;
  END_RESOURCE
END_CONFIGURATION
)ST";

const char* const kRealisticTests = R"ST(
SETUP VAR p : Pump; END_VAR p.en := TRUE; END_SETUP
TEARDOWN p.en := FALSE; END_TEARDOWN
TEST 'starts'
  MOCK p.t;
  MOCK_FUNCTION Helper RETURNS 42;
  p(en := TRUE);
  ADVANCE_TIME(T#2s);
  ASSERT_EQ(p.q, TRUE);
END_TEST
TEST "second" VAR x : INT; END_VAR
  ASSERT_TRUE(x = 0);
END_TEST
)ST";

TEST(ParserRobustness, SeedsParseCleanly) {
  auto a = unit(kRealistic);
  EXPECT_FALSE(a->diags.has_errors()) << a->diags.render_all();
  auto b = test_file(kRealisticTests);
  EXPECT_FALSE(b->diags.has_errors()) << b->diags.render_all();
}

// Splits a source into rough token spans for token-level mutations.
std::vector<std::pair<size_t, size_t>> rough_tokens(const std::string& s) {
  std::vector<std::pair<size_t, size_t>> out;
  size_t i = 0;
  while (i < s.size()) {
    if (std::isspace(static_cast<unsigned char>(s[i]))) {
      ++i;
      continue;
    }
    size_t j = i + 1;
    if (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '_')
      while (j < s.size() && (std::isalnum(static_cast<unsigned char>(s[j])) || s[j] == '_')) ++j;
    out.emplace_back(i, j - i);
    i = j;
  }
  return out;
}

void parse_both(const std::string& text) {
  SourceManager sm;
  DiagEngine diags(sm);
  const uint32_t f = sm.add("m.st", text);
  auto u = parse_unit(sm, f, diags);
  ASSERT_NE(u, nullptr);
  auto t = parse_test_file(sm, f, diags);
  ASSERT_NE(t, nullptr);
  (void)is_test_file(sm, f);
  DiagEngine d2(sm);
  (void)parse_expression(sm, f, d2);
}

TEST(ParserRobustness, MutationsNeverCrashOrHang) {
  const auto start = std::chrono::steady_clock::now();
  size_t runs = 0;
  for (const std::string& seed : {std::string(kRealistic), std::string(kRealisticTests)}) {
    std::mt19937 rng(12345);
    // Truncations at many points.
    for (size_t cut = 0; cut < seed.size(); cut += 7) {
      parse_both(seed.substr(0, cut));
      ++runs;
    }
    // Random byte flips, insertions of punctuation and deletions.
    const std::string alphabet = "();:=[].,'\"#%*$^{}/+-<>&\n\x01\xff";
    for (int iter = 0; iter < 400; ++iter) {
      std::string m = seed;
      const int edits = 1 + static_cast<int>(rng() % 6);
      for (int e = 0; e < edits && !m.empty(); ++e) {
        const size_t at = rng() % m.size();
        switch (rng() % 3) {
          case 0: m[at] = static_cast<char>(rng() % 256); break;
          case 1: m.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
          default: m.erase(at, 1 + rng() % 8); break;
        }
      }
      parse_both(m);
      ++runs;
    }
    // Token deletions and duplications.
    const auto toks = rough_tokens(seed);
    for (int iter = 0; iter < 300; ++iter) {
      std::string m = seed;
      const auto [at, len] = toks[rng() % toks.size()];
      if (iter % 2 == 0) {
        m.erase(at, len);
      } else {
        m.insert(at, seed.substr(at, len) + " ");
      }
      parse_both(m);
      ++runs;
    }
    // Swap two tokens.
    for (int iter = 0; iter < 100; ++iter) {
      auto a = toks[rng() % toks.size()], b = toks[rng() % toks.size()];
      if (a.first > b.first) std::swap(a, b);
      if (a.first + a.second > b.first) continue;
      std::string m = seed.substr(0, a.first) + seed.substr(b.first, b.second) +
                      seed.substr(a.first + a.second, b.first - a.first - a.second) +
                      seed.substr(a.first, a.second) + seed.substr(b.first + b.second);
      parse_both(m);
      ++runs;
    }
  }
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(runs, 1000u);
  RecordProperty("runs", static_cast<int>(runs));
  RecordProperty("ms", static_cast<int>(ms));
}

TEST(ParserRobustness, PathologicalInputs) {
  parse_both("");
  parse_both(std::string(10000, '('));
  parse_both(std::string(10000, '['));
  parse_both(std::string(10000, ';'));
  parse_both("PROGRAM p " + std::string(5000, 'x') + " END_PROGRAM");
  std::string ends;
  for (int i = 0; i < 2000; ++i) ends += "END_IF END_VAR ELSE UNTIL END_PROGRAM END_STRUCT ";
  parse_both(ends);
  std::string opens;
  for (int i = 0; i < 2000; ++i) opens += "PROGRAM p VAR x : STRUCT IF CASE x OF 1: ";
  parse_both(opens);
  std::string nul("PROGRAM p\0x := 1;\nEND_PROGRAM", 30);
  parse_both(nul);
}

// ------------------------------------------------------------------ Instruction List

// The lowering of IL to ST statements: the current result stays an expression until a
// write could change what it reads and a later instruction still reads it; a function
// call is kept at once (`let`: a hidden variable typed by the compiler).
TEST(ParserIl, LowersToStStatements) {
  EXPECT_EQ(body("  LD a\n  ADD b\n  ST c"), "((:= c (+ a b)))");
  EXPECT_EQ(body("  LDN a\n  ANDN b\n  STN c"), "((:= c (NOT (AND (NOT a) (NOT b)))))");
  EXPECT_EQ(body("  LD a\n  ST b\n  ST c"), "((let __IL_CR1 a) (:= b __IL_CR1) (:= c __IL_CR1))");
  EXPECT_EQ(body("  LD a\n  S q\n  LD b\n  R q"), "((if a ((:= q TRUE))) (if b ((:= q FALSE))))");
  EXPECT_EQ(body("  LD a\n  AND( b\n  OR c\n  )\n  ST d"), "((:= d (AND a (OR b c))))");
  EXPECT_EQ(body("  LD a\n  F b, 2\n  ST c"), "((let __IL_CR1 (call F a b 2)) (:= c __IL_CR1))");
  EXPECT_EQ(body("  LD a\n  JMPCN l\n  CAL t(IN := a)\nl: RET"),
            "((if (NOT a) ((jmp l))) (call t (IN := a)) (label l) RETURN)");
  EXPECT_EQ(body("  LD x\n  IN t\n  CAL t"), "((:= (. t IN) x) (call t))");
}

// Bodies that begin with a name of an IL operator but are ST stay ST.
TEST(ParserIl, StBodiesStaySt) {
  EXPECT_EQ(body("LD := 1;"), "((:= LD 1))");
  EXPECT_EQ(body("ST(x);"), "((call ST x))");
  EXPECT_EQ(body("JMP done;\ndone:\nx := 1;"), "((jmp done) (label done) (:= x 1))");
  EXPECT_EQ(body("S.x := 2;"), "((:= (. S x) 2))");
}

TEST(ParserIl, Errors) {
  EXPECT_EQ(unit("PROGRAM p\n  LD a\n  ST\nEND_PROGRAM")->errors(), (Errors{{"ST136", 3}}));
  EXPECT_EQ(unit("PROGRAM p\n  LD a\n  ADD( b\nEND_PROGRAM")->errors(), (Errors{{"ST137", 3}}));
  EXPECT_EQ(unit("PROGRAM p\n  CAL t\n  ST a\nEND_PROGRAM")->errors(), (Errors{{"ST138", 3}}));
  EXPECT_EQ(unit("PROGRAM p\n  LD a\n  42\nEND_PROGRAM")->errors(), (Errors{{"ST135", 3}}));
}

}  // namespace
}  // namespace plcfi::st
