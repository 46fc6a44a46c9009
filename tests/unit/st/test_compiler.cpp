// Semantic diagnostics of the ST compiler: code, line, column and message of each error and warning, all errors in one run, and their rendering.
#include <gtest/gtest.h>
#include <sstream>
#include <set>
#include <regex>
#include <fstream>
#include <filesystem>

#include <ostream>
#include <string>
#include <vector>

#include "engine.hpp"

namespace plcfi::st {
namespace {

std::unique_ptr<Build> compile_one(const std::string& src, CompileOptions opt = {}) {
  return build_sources({{"a.st", src}}, opt);
}

// One program with one diagnostic of interest at a known place.
struct SemaCase {
  const char* name;
  const char* src;
  const char* code;
  uint32_t line, col;
  const char* message;  // a substring of the message
  Severity severity = Severity::Error;
};

void PrintTo(const SemaCase& c, std::ostream* os) { *os << c.name; }

class SemanticDiagnostic : public ::testing::TestWithParam<SemaCase> {};

TEST_P(SemanticDiagnostic, IsReportedWithCodeLocationAndMessage) {
  const SemaCase& c = GetParam();
  auto b = compile_one(c.src);
  std::string all = b->diags.render_all();
  const Diagnostic* found = nullptr;
  for (const auto& d : b->diags.all())
    if (d.code == c.code && !found) found = &d;
  ASSERT_NE(nullptr, found) << "no " << c.code << "; reported:\n" << all;
  EXPECT_EQ(c.severity, found->severity) << all;
  EXPECT_EQ(c.line, found->loc.line) << all;
  EXPECT_EQ(c.col, found->loc.col) << all;
  EXPECT_NE(std::string::npos, found->message.find(c.message)) << "message: " << found->message;
  if (c.severity == Severity::Error) {
    EXPECT_FALSE(b->ok()) << "a build with errors must not produce an application";
  } else {
    EXPECT_TRUE(b->ok()) << "warnings must not fail the build:\n" << all;
    EXPECT_EQ(0u, b->diags.error_count()) << all;
  }
}

const SemaCase kCases[] = {
    {"unknown_identifier", "PROGRAM Main\nVAR i : INT; END_VAR\ni := nothing;\nEND_PROGRAM\n", "ST200", 3, 6,
     "unknown identifier 'nothing'"},
    {"unknown_type", "PROGRAM Main\nVAR m : Motor; END_VAR\nEND_PROGRAM\n", "ST201", 2, 9, "unknown type 'Motor'"},
    {"function_used_as_type",
     "FUNCTION F : INT\nF := 1;\nEND_FUNCTION\nPROGRAM Main\nVAR m : F; END_VAR\nEND_PROGRAM\n", "ST201", 5, 9,
     "'F' is a function, not a type"},
    {"narrowing_dint_to_int", "PROGRAM Main\nVAR i : INT; d : DINT; END_VAR\ni := d;\nEND_PROGRAM\n", "ST203", 3, 1,
     "cannot convert DINT to INT implicitly in assignment; use DINT_TO_INT()"},
    {"real_to_dint", "PROGRAM Main\nVAR r : REAL; d : DINT; END_VAR\nd := r;\nEND_PROGRAM\n", "ST203", 3, 1,
     "use REAL_TO_DINT()"},
    {"dint_to_real", "PROGRAM Main\nVAR r : REAL; d : DINT; END_VAR\nr := d;\nEND_PROGRAM\n", "ST203", 3, 1,
     "use DINT_TO_REAL()"},
    {"real_literal_to_int", "PROGRAM Main\nVAR i : INT; END_VAR\ni := 1.5;\nEND_PROGRAM\n", "ST203", 3, 1,
     "cannot use a REAL literal as INT"},
    {"if_condition_not_bool", "PROGRAM Main\nVAR i : INT; END_VAR\nIF i THEN i := 0; END_IF;\nEND_PROGRAM\n", "ST205",
     3, 4, "a condition must be BOOL, not INT"},
    {"while_condition_not_bool",
     "PROGRAM Main\nVAR i : INT; END_VAR\nWHILE i + 1 DO i := 0; END_WHILE;\nEND_PROGRAM\n", "ST205", 3, 7,
     "a condition must be BOOL"},
    {"constant_out_of_range_sint", "PROGRAM Main\nVAR s : SINT; END_VAR\ns := 300;\nEND_PROGRAM\n", "ST216", 3, 1,
     "constant 300 does not fit SINT"},
    {"negative_constant_to_usint", "PROGRAM Main\nVAR u : USINT; END_VAR\nu := -1;\nEND_PROGRAM\n", "ST216", 3, 1,
     "does not fit USINT"},
    {"assign_to_constant",
     "PROGRAM Main\nVAR CONSTANT LIMIT : INT := 5; END_VAR\nLIMIT := 3;\nEND_PROGRAM\n", "ST206", 3, 1,
     "'LIMIT' is a constant and cannot be assigned"},
    {"duplicate_variable", "PROGRAM Main\nVAR\n  x : INT;\n  x : DINT;\nEND_VAR\nEND_PROGRAM\n", "ST202", 4, 3,
     "'x' is declared twice in Main"},
    {"duplicate_type", "TYPE A : INT; END_TYPE\nTYPE A : DINT; END_TYPE\nPROGRAM Main\nVAR a : A; END_VAR\nEND_PROGRAM\n",
     "ST202", 2, 6, "type 'A' is declared twice"},
    {"builtin_argument_count", "PROGRAM Main\nVAR i : INT; END_VAR\ni := LIMIT(1, 2);\nEND_PROGRAM\n", "ST210", 3, 6,
     "LIMIT takes 3 argument(s), not 2"},
    {"user_function_too_many_arguments",
     "FUNCTION Add2 : INT\nVAR_INPUT a, b : INT; END_VAR\nAdd2 := a + b;\nEND_FUNCTION\n"
     "PROGRAM Main\nVAR i : INT; END_VAR\ni := Add2(1, 2, 3);\nEND_PROGRAM\n",
     "ST210", 7, 17, "Add2 takes 2 argument(s)"},
    {"unknown_formal_of_function",
     "FUNCTION Add2 : INT\nVAR_INPUT a, b : INT; END_VAR\nAdd2 := a + b;\nEND_FUNCTION\n"
     "PROGRAM Main\nVAR i : INT; END_VAR\ni := Add2(a := 1, c := 2);\nEND_PROGRAM\n",
     "ST212", 7, 19, "Add2 has no parameter 'c'"},
    {"unknown_formal_of_fb", "PROGRAM Main\nVAR t : TON; END_VAR\nt(IN := TRUE, PX := T#1s);\nEND_PROGRAM\n", "ST212",
     3, 15, "TON has no input or output 'PX'"},
    {"recursion",
     "FUNCTION Fact : DINT\nVAR_INPUT n : DINT; END_VAR\nFact := n * Fact(n - 1);\nEND_FUNCTION\n"
     "PROGRAM Main\nVAR r : DINT; END_VAR\nr := Fact(3);\nEND_PROGRAM\n",
     "ST214", 3, 13, "recursive use of 'Fact' (Fact -> Fact)"},
    {"mutual_recursion",
     "FUNCTION F : INT\nF := G();\nEND_FUNCTION\nFUNCTION G : INT\nG := F();\nEND_FUNCTION\n"
     "PROGRAM Main\nVAR r : INT; END_VAR\nr := F();\nEND_PROGRAM\n",
     "ST214", 5, 6, "recursive use of 'F' (F -> G -> F)"},
    {"exit_outside_loop", "PROGRAM Main\nVAR i : INT; END_VAR\ni := 1;\nEXIT;\nEND_PROGRAM\n", "ST219", 4, 1,
     "EXIT outside a loop"},
    {"duplicate_case_label",
     "PROGRAM Main\nVAR i, k : INT; END_VAR\nCASE i OF\n1: k := 1;\n2, 1: k := 2;\nEND_CASE;\nEND_PROGRAM\n", "ST221", 5,
     4, "CASE label 1 appears twice"},
    {"overlapping_case_range",
     "PROGRAM Main\nVAR i, k : INT; END_VAR\nCASE i OF\n1..5: k := 1;\n3: k := 2;\nEND_CASE;\nEND_PROGRAM\n", "ST221", 5,
     1, "CASE label 3 appears twice"},
    {"for_variable_not_integer",
     "PROGRAM Main\nVAR r : REAL; k : INT; END_VAR\nFOR r := 1 TO 3 DO k := 2; END_FOR;\nEND_PROGRAM\n", "ST220", 3, 5,
     "the FOR control variable must be a writable variable of an integer type"},
    {"for_step_zero", "PROGRAM Main\nVAR i, k : INT; END_VAR\nFOR i := 1 TO 3 BY 0 DO k := 2; END_FOR;\nEND_PROGRAM\n",
     "ST220", 3, 20, "FOR step must not be zero"},
    {"constant_index_out_of_range",
     "PROGRAM Main\nVAR a : ARRAY [1..10] OF INT; END_VAR\na[11] := 1;\nEND_PROGRAM\n", "ST209", 3, 3,
     "index 11 is outside 1..10"},
    {"too_many_initial_values", "PROGRAM Main\nVAR a : ARRAY [1..2] OF INT := [1, 2, 3]; END_VAR\nEND_PROGRAM\n",
     "ST209", 2, 32, "too many initial values"},
    {"external_without_global", "PROGRAM Main\nVAR_EXTERNAL g : INT; END_VAR\ng := 1;\nEND_PROGRAM\n", "ST228", 2, 14,
     "VAR_EXTERNAL 'g' has no matching VAR_GLOBAL"},
    {"external_type_differs",
     "VAR_GLOBAL g : DINT; END_VAR\nPROGRAM Main\nVAR_EXTERNAL g : INT; END_VAR\ng := 1;\nEND_PROGRAM\n", "ST228", 3, 14,
     "VAR_EXTERNAL 'g' is declared INT but the global is DINT"},
    {"address_size_mismatch", "PROGRAM Main\nVAR x AT %IW0 : DINT; END_VAR\nEND_PROGRAM\n", "ST218", 2, 10,
     "%IW0 addresses 16 bits; DINT has 32"},
    {"bit_address_on_int", "PROGRAM Main\nVAR x AT %IX0.1 : INT; END_VAR\nEND_PROGRAM\n", "ST218", 2, 10,
     "is a bit address; it needs a BOOL variable, not INT"},
    {"address_outside_image", "PROGRAM Main\nVAR x AT %QB5000 : BYTE; END_VAR\nEND_PROGRAM\n", "ST218", 2, 10,
     "is outside the %Q image (4096 bytes)"},
    {"interface_not_implemented",
     "INTERFACE IArea\nMETHOD Area : REAL\nEND_METHOD\nEND_INTERFACE\n"
     "FUNCTION_BLOCK Square IMPLEMENTS IArea\nEND_FUNCTION_BLOCK\n"
     "PROGRAM Main\nVAR s : Square; END_VAR\nEND_PROGRAM\n",
     "ST225", 5, 16, "Square does not implement method 'Area' of interface IArea"},
    {"extends_unknown", "FUNCTION_BLOCK Sq EXTENDS Nothing\nEND_FUNCTION_BLOCK\nPROGRAM Main\nVAR s : Sq; END_VAR\nEND_PROGRAM\n",
     "ST226", 1, 27, "'Nothing' is not a function block"},
    {"constant_division_by_zero", "PROGRAM Main\nVAR i : INT; END_VAR\ni := 10 / 0;\nEND_PROGRAM\n", "ST217", 3, 6,
     "division by zero in a constant expression"},
    {"constant_mod_by_zero", "PROGRAM Main\nVAR CONSTANT N : INT := 7 MOD 0; END_VAR\nEND_PROGRAM\n", "ST217", 2, 31,
     "zero"},
    {"unknown_enum_value",
     "TYPE Color : (Red, Green); END_TYPE\nPROGRAM Main\nVAR c : Color; END_VAR\nc := Color#Blue;\nEND_PROGRAM\n", "ST230",
     4, 12, "'Blue' is not a value of Color"},
    {"ambiguous_enum_value",
     "TYPE Color : (Red, Green); END_TYPE\nTYPE Light : (Red, Off); END_TYPE\nPROGRAM Main\nVAR c : Color; b : BOOL; END_VAR\n"
     "b := Red = Red;\nEND_PROGRAM\n",
     "ST230", 5, 6, "'Red' is a value of several enumerations; write Type#Red"},
    {"integer_to_enum", "TYPE Color : (Red, Green); END_TYPE\nPROGRAM Main\nVAR c : Color; END_VAR\nc := 1;\nEND_PROGRAM\n",
     "ST203", 4, 1, "cannot use an integer as enumeration Color; use Color#Value"},
    {"unknown_function", "PROGRAM Main\nVAR i : INT; END_VAR\ni := MaybeFn(3);\nEND_PROGRAM\n", "ST211", 3, 6,
     "unknown function 'MaybeFn'"},
    {"fb_type_called", "PROGRAM Main\nVAR t : TON; END_VAR\nTON(IN := TRUE, PT := T#1s);\nEND_PROGRAM\n", "ST213", 3, 1,
     "'TON' is a function block type"},
    {"unknown_member", "PROGRAM Main\nVAR t : TON; b : BOOL; END_VAR\nb := t.QQ;\nEND_PROGRAM\n", "ST207", 3, 8,
     "'TON' has no member 'QQ'"},
    {"index_of_non_array", "PROGRAM Main\nVAR i : INT; END_VAR\ni := i[1];\nEND_PROGRAM\n", "ST208", 3, 6,
     "'[ ]' needs an array, not INT"},
    {"wrong_index_count", "PROGRAM Main\nVAR a : ARRAY [1..3] OF INT; END_VAR\na[1, 2] := 0;\nEND_PROGRAM\n", "ST208", 3, 1,
     "needs 1 index(es), not 2"},
    {"this_outside_fb", "FUNCTION F : INT\nF := THIS^.x;\nEND_FUNCTION\nPROGRAM Main\nEND_PROGRAM\n", "ST231", 2, 6,
     "THIS is only available inside a function block"},
    {"deref_non_reference", "PROGRAM Main\nVAR i, k : INT; END_VAR\nk := i^;\nEND_PROGRAM\n", "ST232", 3, 6,
     "'^' needs a reference (REF_TO), not INT"},
    {"bit_out_of_range", "PROGRAM Main\nVAR w : WORD; b : BOOL; END_VAR\nb := w.16;\nEND_PROGRAM\n", "ST237", 3, 6,
     "bit 16 does not exist in WORD"},
    {"fb_instance_in_function",
     "FUNCTION F : INT\nVAR t : TON; END_VAR\nF := 1;\nEND_FUNCTION\nPROGRAM Main\nEND_PROGRAM\n", "ST239", 2, 5,
     "a FUNCTION cannot declare function block instances"},
    {"bool_plus_int", "PROGRAM Main\nVAR i : INT; b : BOOL; END_VAR\ni := b + i;\nEND_PROGRAM\n", "ST204", 3, 6,
     "operator + mixes BOOL and INT"},
    {"lint_plus_real", "PROGRAM Main\nVAR l : LINT; r : REAL; x : LREAL; END_VAR\nx := l + r;\nEND_PROGRAM\n", "ST204",
     3, 6, "operator + mixes LINT and REAL which have no common type"},
    {"negate_unsigned", "PROGRAM Main\nVAR u, v : UINT; END_VAR\nv := -u;\nEND_PROGRAM\n", "ST204", 3, 6,
     "'-' is not applicable to UINT"},
    {"in_out_not_passed",
     "FUNCTION Inc : INT\nVAR_IN_OUT v : INT; END_VAR\nv := v + 1;\nInc := v;\nEND_FUNCTION\n"
     "PROGRAM Main\nVAR r : INT; END_VAR\nr := Inc();\nEND_PROGRAM\n",
     "ST224", 8, 6, "VAR_IN_OUT 'v' of Inc must be passed"},
    {"in_out_wrong_type",
     "FUNCTION Inc : INT\nVAR_IN_OUT v : INT; END_VAR\nv := v + 1;\nInc := v;\nEND_FUNCTION\n"
     "PROGRAM Main\nVAR r : INT; d : DINT; END_VAR\nr := Inc(v := d);\nEND_PROGRAM\n",
     "ST222", 8, 15, "VAR_IN_OUT 'v' needs a variable of type INT, not DINT"},
    {"invalid_array_bounds", "PROGRAM Main\nVAR a : ARRAY [5..1] OF INT; END_VAR\nEND_PROGRAM\n", "ST229", 2, 16,
     "invalid array bounds 5..1"},
    {"empty_subrange", "PROGRAM Main\nVAR s : INT (10..1); END_VAR\nEND_PROGRAM\n", "ST229", 2, 9, "empty subrange 10..1"},
    {"string_length_zero", "PROGRAM Main\nVAR s : STRING[0]; END_VAR\nEND_PROGRAM\n", "ST238", 2, 16,
     "string length must be 1..65535, not 0"},
    {"pou_as_variable",
     "FUNCTION_BLOCK Motor\nEND_FUNCTION_BLOCK\nPROGRAM Main\nVAR i : INT; END_VAR\ni := Motor;\nEND_PROGRAM\n", "ST223", 5,
     6, "'Motor' is a POU, not a variable"},
    {"unknown_task",
     "PROGRAM Main\nEND_PROGRAM\nCONFIGURATION C\nRESOURCE R ON PLC\nTASK Slow (INTERVAL := T#100ms, PRIORITY := 1);\n"
     "PROGRAM P1 WITH Fast : Main;\nEND_RESOURCE\nEND_CONFIGURATION\n",
     "ST227", 6, 17, "unknown task 'Fast'"},
    {"fb_contains_itself", "FUNCTION_BLOCK Node\nVAR next : Node; END_VAR\nEND_FUNCTION_BLOCK\nPROGRAM Main\nEND_PROGRAM\n",
     "ST240", 2, 5, "Node cannot contain an instance of itself"},
    {"unused_temp_warning",
     "FUNCTION F : INT\nVAR_TEMP tmp : INT; END_VAR\nF := 1;\nEND_FUNCTION\nPROGRAM Main\nVAR r : INT; END_VAR\nr := F();\nEND_PROGRAM\n",
     "ST400", 2, 10, "variable 'tmp' is declared but never used", Severity::Warning},
    {"self_assignment_warning", "PROGRAM Main\nVAR i : INT; END_VAR\ni := i;\nEND_PROGRAM\n", "ST401", 3, 1,
     "assignment of 'i' to itself", Severity::Warning},
    {"unreachable_warning",
     "PROGRAM Main\nVAR i : INT; END_VAR\nWHILE i < 10 DO\n  EXIT;\n  i := i + 1;\nEND_WHILE;\nEND_PROGRAM\n", "ST402", 5, 3,
     "unreachable statement", Severity::Warning},
    {"constant_condition_warning", "PROGRAM Main\nVAR i : INT; END_VAR\nIF FALSE THEN i := 1; END_IF;\nEND_PROGRAM\n", "ST404",
     3, 4, "condition is always FALSE", Severity::Warning},
};

INSTANTIATE_TEST_SUITE_P(Compiler, SemanticDiagnostic, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<SemaCase>& i) { return std::string(i.param.name); });

TEST(Compiler, IndependentErrorsAreAllReportedInOneRun) {
  auto b = compile_one(
      "PROGRAM Main\n"
      "VAR i : INT; d : DINT; END_VAR\n"
      "i := nothing;\n"
      "IF d THEN d := 0; END_IF;\n"
      "i := d;\n"
      "END_PROGRAM\n");
  EXPECT_FALSE(b->ok());
  ASSERT_EQ(3u, b->diags.error_count()) << b->diags.render_all();
  std::vector<std::string> got;
  for (const auto& d : b->diags.all()) got.push_back(d.code + "@" + std::to_string(d.loc.line));
  EXPECT_EQ((std::vector<std::string>{"ST200@3", "ST205@4", "ST203@5"}), got);
}

TEST(Compiler, ErrorsInSeveralPousAreAllReported) {
  auto b = compile_one(
      "FUNCTION_BLOCK A\nVAR x : INT; END_VAR\nx := y;\nEND_FUNCTION_BLOCK\n"
      "FUNCTION F : INT\nF := 1.5;\nEND_FUNCTION\n"
      "PROGRAM Main\nVAR a : A; END_VAR\na(z := 1);\nEND_PROGRAM\n");
  EXPECT_FALSE(b->ok());
  ASSERT_EQ(3u, b->diags.error_count()) << b->diags.render_all();
  std::string all = b->diags.render_all();
  EXPECT_NE(std::string::npos, all.find("a.st:3:6: error[ST200]")) << all;
  EXPECT_NE(std::string::npos, all.find("a.st:6:1: error[ST203]")) << all;
  EXPECT_NE(std::string::npos, all.find("a.st:10:3: error[ST212]")) << all;
}

TEST(Compiler, RenderShowsLocationCodeSourceLineAndCaret) {
  auto b = compile_one("PROGRAM Main\nVAR i : INT; d : DINT; END_VAR\n    i := d + 1;\nEND_PROGRAM\n");
  ASSERT_EQ(1u, b->diags.all().size()) << b->diags.render_all();
  EXPECT_EQ(
      "a.st:3:5: error[ST203]: cannot convert DINT to INT implicitly in assignment; use DINT_TO_INT()\n"
      "      i := d + 1;\n"
      "      ^\n",
      b->diags.render(b->diags.all()[0]));
}

TEST(Compiler, RenderOfAWarningAndANote) {
  auto b = compile_one(
      "FUNCTION Fact : DINT\nVAR_INPUT n : DINT; END_VAR\nFact := n * Fact(n - 1);\nEND_FUNCTION\n"
      "PROGRAM Main\nVAR r : DINT; END_VAR\nr := Fact(3);\nr := r;\nEND_PROGRAM\n");
  std::string all = b->diags.render_all();
  EXPECT_NE(std::string::npos, all.find("a.st:3:13: error[ST214]: recursive use of 'Fact'")) << all;
  EXPECT_NE(std::string::npos, all.find("a.st:1:10: note: 'Fact' is declared here")) << all;
  EXPECT_NE(std::string::npos, all.find("a.st:8:1: warning[ST401]: assignment of 'r' to itself\n  r := r;\n  ^\n")) << all;
  // render_all sorts by position: the error on line 3 comes before the warning on line 8
  EXPECT_LT(all.find("ST214"), all.find("ST401"));
}

TEST(Compiler, WarningsCanBeSwitchedOff) {
  const char* src = "PROGRAM Main\nVAR i : INT; END_VAR\ni := i;\nIF TRUE THEN i := 1; END_IF;\nEND_PROGRAM\n";
  auto with = compile_one(src);
  EXPECT_TRUE(with->ok());
  EXPECT_EQ(2u, with->diags.warning_count()) << with->diags.render_all();
  CompileOptions quiet;
  quiet.warnings = false;
  auto without = compile_one(src, quiet);
  EXPECT_TRUE(without->ok());
  EXPECT_EQ(0u, without->diags.warning_count()) << without->diags.render_all();
}

TEST(Compiler, ProgramInstanceVariablesAreNotReportedUnused) {
  auto b = compile_one("PROGRAM Main\nVAR never_used : INT; END_VAR\nEND_PROGRAM\n");
  EXPECT_TRUE(b->ok());
  EXPECT_EQ(0u, b->diags.all().size()) << b->diags.render_all();
}

TEST(Compiler, ValidProgramHasNoDiagnostics) {
  auto b = compile_one(
      "TYPE Color : (Red, Green, Blue); END_TYPE\n"
      "FUNCTION Clamp : INT\nVAR_INPUT v : DINT; END_VAR\nClamp := DINT_TO_INT(LIMIT(-100, v, 100));\nEND_FUNCTION\n"
      "PROGRAM Main\nVAR i : INT; d : DINT := 1000; s : SINT := -128; r : LREAL; c : Color := Color#Green; t : TON; END_VAR\n"
      "i := Clamp(d);\nr := d + s;\nt(IN := c = Green, PT := T#1s);\nEND_PROGRAM\n");
  EXPECT_TRUE(b->ok()) << b->diags.render_all();
  EXPECT_EQ(0u, b->diags.all().size()) << b->diags.render_all();
}

// IEC 61131-3 (6.6.1.4.2): a non-formal call lists every input in order; leaving one out
// is only possible in a formal call.
TEST(Compiler, NonFormalCallWithTooFewArgumentsIsAnError) {
  auto b = compile_one(
      "FUNCTION Add2 : INT\nVAR_INPUT a, b : INT; END_VAR\nAdd2 := a + b;\nEND_FUNCTION\n"
      "PROGRAM Main\nVAR i : INT; END_VAR\ni := Add2(1);\nEND_PROGRAM\n");
  EXPECT_FALSE(b->ok());
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST210", b->diags.all()[0].code);
}

// Untyped literals are ANY_INT: a generic standard function of literals takes its type
// from the context, as `a := 10 + 20` does.
TEST(Compiler, GenericFunctionOfLiteralsAdaptsToTheTarget) {
  auto b = compile_one("PROGRAM Main\nVAR mx, a : INT; k : INT := 1; END_VAR\n"
                       "mx := MAX(10, 20);\nmx := LIMIT(0, 5, 3);\nmx := SEL(TRUE, 1, 2);\nmx := MUX(k, 10, 20, 30);\n"
                       "a := 10 + 20;\nEND_PROGRAM\n");
  EXPECT_TRUE(b->ok()) << b->diags.render_all();
  EXPECT_EQ(0u, b->diags.error_count()) << b->diags.render_all();
}

// CODESYS references (REFERENCE TO): misuse the codesys suite's files cannot show, as the
// negative suite checks without a dialect.
CompileOptions codesys() {
  CompileOptions opt;
  opt.dialect = Dialect::Codesys;
  return opt;
}

TEST(CodesysReference, BindingToAConstantIsAnError) {
  auto b = compile_one("PROGRAM Main\nVAR CONSTANT k : INT := 3; END_VAR\nVAR r : REFERENCE TO INT; END_VAR\n"
                       "r REF= k;\nEND_PROGRAM\n", codesys());
  EXPECT_FALSE(b->ok());
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST232", b->diags.all()[0].code);
  EXPECT_EQ(4u, b->diags.all()[0].loc.line);
  EXPECT_NE(std::string::npos, b->diags.all()[0].message.find("'k' is a constant")) << b->diags.all()[0].message;
}

TEST(CodesysReference, BindingToALiteralOrAnotherTypeIsAnError) {
  auto b = compile_one("PROGRAM Main\nVAR r : REFERENCE TO INT; d : DINT; END_VAR\n"
                       "r REF= 5;\nr REF= d;\nEND_PROGRAM\n", codesys());
  ASSERT_EQ(2u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST206", b->diags.all()[0].code);
  EXPECT_EQ("ST203", b->diags.all()[1].code);
  EXPECT_NE(std::string::npos, b->diags.all()[1].message.find("REFERENCE TO INT needs a variable of type INT, not DINT"));
}

TEST(CodesysReference, IsValidRefNeedsAReference) {
  auto b = compile_one("PROGRAM Main\nVAR i : INT; ok : BOOL; END_VAR\nok := __ISVALIDREF(i);\nEND_PROGRAM\n", codesys());
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST232", b->diags.all()[0].code);
}

TEST(CodesysReference, IecRejectsEachDeclarationOnce) {
  auto b = compile_one("PROGRAM Main\nVAR x : INT; r : REFERENCE TO INT; END_VAR\nr REF= x;\nr := r + 1;\nEND_PROGRAM\n");
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST241", b->diags.all()[0].code);
  EXPECT_EQ(2u, b->diags.all()[0].loc.line);
  EXPECT_EQ(18u, b->diags.all()[0].loc.col);
}

TEST(CodesysReference, UnboundUseTrapsAtTheUse) {
  auto b = compile_one("PROGRAM Main\nVAR x : INT; r : REFERENCE TO INT; bind : BOOL; y : INT; END_VAR\n"
                       "IF bind THEN r REF= x; END_IF\nx := 41;\ny := r + 1;\nEND_PROGRAM\n", codesys());
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  Machine m(*b->app);
  const auto& p = b->app->programs.at(0);
  EXPECT_FALSE(m.call(p.pou->entry, p.addr));
  EXPECT_EQ(TrapKind::NullReference, m.trap().kind);
  EXPECT_EQ(5u, m.trap().loc.line);
  EXPECT_EQ(6u, m.trap().loc.col);
  std::string err;
  auto bind = resolve(*b->app, "Main.bind", &err);
  ASSERT_TRUE(bind) << err;
  write_int(m, *bind, 1);
  EXPECT_TRUE(m.call(p.pou->entry, p.addr));
  auto y = resolve(*b->app, "Main.y", &err);
  ASSERT_TRUE(y) << err;
  EXPECT_EQ(42, read_int(m, *y));
}

// CODESYS unions: misuse (the negative suite checks without a dialect, where UNION itself
// is the error).
TEST(CodesysUnion, AFunctionBlockMemberIsAnError) {
  auto b = compile_one("TYPE U :\nUNION\n  i : INT;\n  t : TON;\nEND_UNION\nEND_TYPE\n"
                       "PROGRAM Main\nVAR u : U; END_VAR\nu.i := 1;\nEND_PROGRAM\n", codesys());
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST201", b->diags.all()[0].code);
  EXPECT_EQ(4u, b->diags.all()[0].loc.line);
  EXPECT_NE(std::string::npos, b->diags.all()[0].message.find("a UNION cannot hold function block instances"));
}

TEST(CodesysUnion, OnlyTheFirstMemberIsInitialized) {
  auto b = compile_one("TYPE U :\nUNION\n  i : INT;\n  b : BYTE := 3;\nEND_UNION\nEND_TYPE\n"
                       "PROGRAM Main\nVAR u : U; v : U := (b := 1); w : U := (i := 2); END_VAR\nu.i := 1;\nEND_PROGRAM\n",
                       codesys());
  ASSERT_EQ(2u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST209", b->diags.all()[0].code);
  EXPECT_EQ(4u, b->diags.all()[0].loc.line);
  EXPECT_EQ("ST209", b->diags.all()[1].code);
  EXPECT_EQ(8u, b->diags.all()[1].loc.line);
  EXPECT_NE(std::string::npos, b->diags.all()[1].message.find("(i := ...)"));
}

TEST(CodesysUnion, IecRejectsEachUnionOnce) {
  auto b = compile_one("TYPE U :\nUNION\n  i : INT;\n  b : BYTE;\nEND_UNION\nEND_TYPE\n"
                       "PROGRAM Main\nVAR u : U; END_VAR\nu.b := 1;\nEND_PROGRAM\n");
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST241", b->diags.all()[0].code);
  EXPECT_EQ(2u, b->diags.all()[0].loc.line);
}

// VAR_INST and VAR_STAT: misuse (the negative suite checks without a dialect).
TEST(CodesysInstanceVars, VarInstInAFunctionIsOneError) {
  auto b = compile_one("FUNCTION F : INT\nVAR_INST n : INT; END_VAR\nn := n + 1;\nF := n;\nEND_FUNCTION\n", codesys());
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST129", b->diags.all()[0].code);
  EXPECT_EQ(2u, b->diags.all()[0].loc.line);
}

TEST(CodesysInstanceVars, AMethodsVarInstIsNotAVariableOfTheBlock) {
  auto b = compile_one("FUNCTION_BLOCK Fb\nMETHOD M : INT\nVAR_INST n : INT; END_VAR\nn := n + 1;\nM := n;\nEND_METHOD\n"
                       "n := 1;\nEND_FUNCTION_BLOCK\n", codesys());
  ASSERT_EQ(1u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST200", b->diags.all()[0].code);
  EXPECT_EQ(7u, b->diags.all()[0].loc.line);
}

TEST(CodesysInstanceVars, IecRejectsEachBlockOnce) {
  auto b = compile_one("FUNCTION F : INT\nVAR_STAT a, b : INT; c : INT; END_VAR\nF := a + b + c;\nEND_FUNCTION\n"
                       "FUNCTION_BLOCK Fb\nMETHOD M : INT\nVAR_INST n : INT; END_VAR\nM := n;\nEND_METHOD\nEND_FUNCTION_BLOCK\n");
  ASSERT_EQ(2u, b->diags.error_count()) << b->diags.render_all();
  EXPECT_EQ("ST241", b->diags.all()[0].code);
  EXPECT_EQ(2u, b->diags.all()[0].loc.line);
  EXPECT_EQ("ST241", b->diags.all()[1].code);
  EXPECT_EQ(7u, b->diags.all()[1].loc.line);
}

}  // namespace
}  // namespace plcfi::st

// Every diagnostic code the engine can emit is in the catalogue (driver/st/DIAGNOSTICS.md).
TEST(DiagnosticsCatalogue, ListsEveryCodeTheEngineEmits) {
  namespace fs = std::filesystem;
  fs::path root = fs::path(PLCFI_SOURCE_DIR) / "driver" / "st";
  std::ifstream cat_file(root / "DIAGNOSTICS.md");
  std::stringstream cat;
  cat << cat_file.rdbuf();
  ASSERT_FALSE(cat.str().empty());
  std::set<std::string> codes;
  const std::regex code("\"(ST[0-9]{3})\"");
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.path().extension() != ".cpp" && e.path().extension() != ".hpp") continue;
    std::ifstream f(e.path());
    std::stringstream ss;
    ss << f.rdbuf();
    std::string text = ss.str();
    for (auto it = std::sregex_iterator(text.begin(), text.end(), code); it != std::sregex_iterator(); ++it)
      codes.insert((*it)[1]);
  }
  EXPECT_GT(codes.size(), 50u);
  for (const auto& c : codes) EXPECT_NE(cat.str().find("| " + c + " |"), std::string::npos) << c << " is not in DIAGNOSTICS.md";
}
