// Deep and long input, generated: long operator chains compile and compute right, and every
// kind of nesting the parser, the compiler or the native tier would follow by recursion ends
// in a precise diagnostic instead of a stack overflow (CI runs this under ASan too).
#include <gtest/gtest.h>

#include <string>

#include "engine.hpp"
#include "native/native.hpp"

namespace plcfi::st {
namespace {

std::string repeat(const std::string& s, int n, const std::string& sep = "") {
  std::string out;
  for (int i = 0; i < n; ++i) out += (i ? sep : "") + s;
  return out;
}

std::string program(const std::string& vars, const std::string& body) {
  return "PROGRAM Main\nVAR\n" + vars + "\nEND_VAR\n" + body + "\nEND_PROGRAM\n";
}

// Compiles, runs one scan of Main and returns the variable's value.
int64_t run_and_read(const std::string& src, const std::string& var, bool native = false) {
  auto b = build_sources({{"deep.st", src}}, CompileOptions{});
  EXPECT_TRUE(b->ok()) << b->diags.render_all().substr(0, 2000);
  if (!b->ok()) return INT64_MIN;
  Machine m(*b->app);
  std::unique_ptr<NativeCode> nc;
  if (native) {
    std::string err;
    nc = NativeCode::build(*b->app, NativeOptions{}, &err);
    EXPECT_TRUE(nc) << err;
    if (!nc) return INT64_MIN;
    m.set_native(nc.get());
  }
  const auto& inst = b->app->programs.at(0);
  EXPECT_TRUE(m.call(inst.pou->entry, inst.addr));
  std::string err;
  auto h = resolve(*b->app, "Main." + var, &err);
  EXPECT_TRUE(h.has_value()) << err;
  return h ? read_int(m, *h) : INT64_MIN;
}

// The first error's code and line (or "ok").
std::string first_error(const std::string& src) {
  auto b = build_sources({{"deep.st", src}}, CompileOptions{});
  for (const auto& d : b->diags.all())
    if (d.severity == Severity::Error) return d.code + ":" + std::to_string(d.loc.line);
  return b->ok() ? "ok" : "failed without an error";
}

constexpr int kTerms = 10000;

// ------------------------------------------------------------------ long chains compile

TEST(DeepInput, AdditionChainOfTenThousandTermsComputes) {
  EXPECT_EQ(kTerms, run_and_read(program("x : DINT; y : DINT := 1;", "x := " + repeat("y", kTerms, " + ") + ";"), "x"));
}

TEST(DeepInput, ConstantChainFoldsAndInitializes) {
  EXPECT_EQ(kTerms, run_and_read(program("x : DINT;", "x := " + repeat("1", kTerms, " + ") + ";"), "x"));
  EXPECT_EQ(kTerms - 2, run_and_read(program("x : DINT := " + repeat("1", kTerms, " + ") + " - 2;", ""), "x"));
}

TEST(DeepInput, BooleanChainsCompute) {
  std::string vars = "b : BOOL; t : BOOL := TRUE; f : BOOL;";
  EXPECT_EQ(1, run_and_read(program(vars, "b := " + repeat("t", kTerms, " AND ") + ";"), "b"));
  EXPECT_EQ(0, run_and_read(program(vars, "b := " + repeat("t", kTerms, " AND ") + " AND f;"), "b"));
  EXPECT_EQ(1, run_and_read(program(vars, "b := " + repeat("f", kTerms, " OR ") + " OR t;"), "b"));
  EXPECT_EQ(0, run_and_read(program(vars, "b := " + repeat("t", kTerms, " XOR ") + ";"), "b"));
}

TEST(DeepInput, MixedPrecedenceChainComputes) {
  // Each term is y * 3 - y = 2 (multiplication binds tighter); comparisons and OR on top.
  EXPECT_EQ(2 * kTerms, run_and_read(program("x : DINT; y : DINT := 1;", "x := " + repeat("y * 3 - y", kTerms, " + ") + ";"), "x"));
  EXPECT_EQ(1, run_and_read(program("b : BOOL; y : DINT := 1;", "b := " + repeat("y > 2 AND y < 0", kTerms, " OR ") + " OR y = 1;"), "b"));
}

TEST(DeepInput, ChainInAnIfConditionAndInCallArguments) {
  std::string src =
      "FUNCTION Id : DINT\nVAR_INPUT a : DINT; END_VAR\nId := a;\nEND_FUNCTION\n" +
      program("x : DINT; y : DINT := 1;", "IF " + repeat("y", kTerms, " + ") + " = " + std::to_string(kTerms) +
                                              " THEN x := Id(a := " + repeat("y", kTerms, " - ") + "); END_IF;");
  EXPECT_EQ(2 - kTerms, run_and_read(src, "x"));
}

TEST(DeepInput, NativeTierTranslatesALongChain) {
  // The whole chain is translated; a shorter one is also compiled and run (the system
  // compiler's time grows with the function's length, not the translation's).
  auto b = build_sources({{"deep.st", program("x : DINT; y : DINT := 1;", "x := " + repeat("y", kTerms, " + ") + ";")}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all().substr(0, 2000);
  std::vector<uint32_t> entries, skipped;
  std::string cpp = native_source(*b->app, &entries, &skipped);
  EXPECT_TRUE(skipped.empty());
  EXPECT_GT(cpp.size(), static_cast<size_t>(kTerms) * 10);
  EXPECT_EQ(500, run_and_read(program("x : DINT; y : DINT := 1;", "x := " + repeat("y", 500, " + ") + ";"), "x", true));
}

// ------------------------------------------------------------------ true nesting is limited

TEST(DeepInput, LongPostfixChainsStopAtTheDepthLimit) {
  EXPECT_EQ("ST117:5", first_error(program("x : DINT; p : REF_TO DINT;", "x := p" + repeat("^", kTerms) + ";")));
  EXPECT_EQ("ST117:5", first_error(program("x : DINT; s : INT;", "x := s" + repeat(".m", kTerms) + ";")));
  EXPECT_EQ("ST117:5", first_error(program("x : DINT; a : ARRAY[0..1] OF DINT;", "x := a" + repeat("[0]", kTerms) + ";")));
  EXPECT_EQ("ST117:5", first_error(program("x : DINT;", "x := f" + repeat("()", kTerms) + ";")));
}

TEST(DeepInput, UnaryChainsStopAtTheDepthLimit) {
  EXPECT_EQ("ST117:5", first_error(program("b : BOOL; c : BOOL;", "b := " + repeat("NOT ", kTerms) + "c;")));
  EXPECT_EQ("ST117:5", first_error(program("x : DINT;", "x := " + repeat("- ", kTerms) + "1;")));
  EXPECT_EQ("ST117:5", first_error(program("x : DINT;", "x := " + repeat("(", kTerms) + "1" + repeat(")", kTerms) + ";")));
}

TEST(DeepInput, FunctionBlocksNestedTenThousandDeep) {
  std::string src;
  for (int i = 0; i < kTerms; ++i) src += "FUNCTION_BLOCK FB" + std::to_string(i) + "\nVAR m : FB" + std::to_string(i + 1) + "; END_VAR\nEND_FUNCTION_BLOCK\n";
  src += "FUNCTION_BLOCK FB" + std::to_string(kTerms) + "\nVAR v : INT; END_VAR\nEND_FUNCTION_BLOCK\n";
  src += program("f : FB0;", "");
  EXPECT_EQ("ST117", first_error(src).substr(0, 5));
}

TEST(DeepInput, FunctionsCallingFunctionsTenThousandDeep) {
  // Each FUNCTION is compiled when its caller needs its frame: a call chain nests the
  // compiler as deep as it is long.
  auto chain = [](int n) {
    std::string src;
    for (int i = 0; i < n; ++i)
      src += "FUNCTION F" + std::to_string(i) + " : DINT\nVAR_INPUT a : DINT; END_VAR\nF" + std::to_string(i) + " := F" +
             std::to_string(i + 1) + "(a := a + 1);\nEND_FUNCTION\n";
    src += "FUNCTION F" + std::to_string(n) + " : DINT\nVAR_INPUT a : DINT; END_VAR\nF" + std::to_string(n) + " := a;\nEND_FUNCTION\n";
    return src + program("x : DINT;", "x := F0(a := 0);");
  };
  EXPECT_EQ(100, run_and_read(chain(100), "x"));
  EXPECT_EQ("ST117", first_error(chain(kTerms)).substr(0, 5));
}

TEST(DeepInput, StructsNestedTwentyThousandDeep) {
  const int n = 2 * kTerms;
  std::string src = "TYPE\n";
  for (int i = 0; i < n; ++i) src += "S" + std::to_string(i) + " : STRUCT m : S" + std::to_string(i + 1) + "; END_STRUCT;\n";
  src += "S" + std::to_string(n) + " : STRUCT v : INT; END_STRUCT;\nEND_TYPE\n" + program("s : S0;", "");
  EXPECT_EQ("ST117", first_error(src).substr(0, 5));
}

TEST(DeepInput, ArraysOfArraysNestedDeep) {
  std::string named = "TYPE\n";
  for (int i = 0; i < kTerms; ++i) named += "A" + std::to_string(i) + " : ARRAY[0..0] OF A" + std::to_string(i + 1) + ";\n";
  named += "A" + std::to_string(kTerms) + " : ARRAY[0..0] OF INT;\nEND_TYPE\n" + program("a : A0;", "");
  EXPECT_EQ("ST117", first_error(named).substr(0, 5));
  EXPECT_EQ("ST117:3", first_error(program("a : " + repeat("ARRAY[0..1] OF ", kTerms) + "INT;", "")));
}

TEST(DeepInput, TypeAliasAndConstantChains) {
  std::string alias = "TYPE\n";
  for (int i = 0; i < kTerms; ++i) alias += "T" + std::to_string(i) + " : T" + std::to_string(i + 1) + ";\n";
  alias += "T" + std::to_string(kTerms) + " : INT;\nEND_TYPE\n" + program("t : T0;", "");
  EXPECT_EQ("ST117", first_error(alias).substr(0, 5));
  std::string consts = "VAR_GLOBAL CONSTANT\n";
  for (int i = 0; i < kTerms; ++i) consts += "C" + std::to_string(i) + " : DINT := C" + std::to_string(i + 1) + " + 1;\n";
  consts += "C" + std::to_string(kTerms) + " : DINT := 0;\nEND_VAR\n" + program("x : DINT;", "x := C0;");
  EXPECT_EQ("ST117", first_error(consts).substr(0, 5));
  std::string cycle = "VAR_GLOBAL CONSTANT\nA : DINT := B + 1;\nB : DINT := A + 1;\nEND_VAR\n" + program("x : DINT;", "x := A;");
  EXPECT_EQ("ST117", first_error(cycle).substr(0, 5));
}

// ------------------------------------------------------------------ cycles

TEST(DeepInput, InterfaceExtendingItself) {
  std::string itf = "INTERFACE I EXTENDS I\nMETHOD M : INT\nEND_METHOD\nEND_INTERFACE\n";
  std::string fb = "FUNCTION_BLOCK F IMPLEMENTS I\nMETHOD M : INT\nM := 1;\nEND_METHOD\nEND_FUNCTION_BLOCK\n";
  EXPECT_EQ("ST226:1", first_error(itf + fb + program("f : F; i : I;", "i := f;")));
}

TEST(DeepInput, InterfacesExtendingEachOther) {
  std::string itfs = "INTERFACE I EXTENDS J\nMETHOD M : INT\nEND_METHOD\nEND_INTERFACE\nINTERFACE J EXTENDS I\nEND_INTERFACE\n";
  std::string fb = "FUNCTION_BLOCK F IMPLEMENTS I\nMETHOD M : INT\nM := 1;\nEND_METHOD\nEND_FUNCTION_BLOCK\n";
  EXPECT_EQ("ST226:1", first_error(itfs + fb + program("f : F; i : I; j : J;", "i := f; j := f;")));
}

TEST(DeepInput, LongInterfaceChainStillWorks) {
  std::string src;
  const int n = 2000;
  for (int i = 0; i < n; ++i) src += "INTERFACE I" + std::to_string(i) + " EXTENDS I" + std::to_string(i + 1) + "\nEND_INTERFACE\n";
  src += "INTERFACE I" + std::to_string(n) + "\nMETHOD M : DINT\nEND_METHOD\nEND_INTERFACE\n";
  src += "FUNCTION_BLOCK F IMPLEMENTS I0\nMETHOD M : DINT\nM := 7;\nEND_METHOD\nEND_FUNCTION_BLOCK\n";
  src += program("f : F; i : I" + std::to_string(n) + "; x : DINT;", "i := f; x := i.M();");
  EXPECT_EQ(7, run_and_read(src, "x"));
}

TEST(DeepInput, FunctionBlocksExtendingEachOther) {
  std::string src = "FUNCTION_BLOCK A EXTENDS B\nEND_FUNCTION_BLOCK\nFUNCTION_BLOCK B EXTENDS A\nEND_FUNCTION_BLOCK\n";
  EXPECT_EQ("ST226", first_error(src + program("a : A;", "")).substr(0, 5));
}

TEST(DeepInput, StructContainingItself) {
  EXPECT_EQ("ST201:1", first_error("TYPE S : STRUCT v : INT; s : S; END_STRUCT; END_TYPE\n" + program("s : S;", "s.v := 1;")));
  EXPECT_EQ("ST201:1", first_error("TYPE S : STRUCT v : INT; a : ARRAY[0..1] OF S; END_STRUCT; END_TYPE\n" + program("s : S;", "s.v := 1;")));
  EXPECT_EQ("ST201", first_error("TYPE\nS : STRUCT v : INT; t : T; END_STRUCT;\nT : STRUCT s : S; END_STRUCT;\nEND_TYPE\n" +
                                 program("s : S;", "s.v := 1;")).substr(0, 5));
  // A link back through REF_TO is fine.
  EXPECT_EQ("ok", first_error("TYPE S : STRUCT v : INT; next : REF_TO S; END_STRUCT; END_TYPE\n" + program("s : S;", "s.v := 1;")));
}

// ------------------------------------------------------------------ wide input

TEST(WideInput, VarBlockOfFortyThousandVariables) {
  std::string vars;
  for (int i = 0; i < 40000; ++i) vars += "v" + std::to_string(i) + " : DINT := " + std::to_string(i) + ";\n";
  EXPECT_EQ(39999 + 1, run_and_read(program(vars, "v0 := v39999 + 1;"), "v0"));
  // Duplicates are still found, whatever the case.
  EXPECT_EQ("ST202:40003", first_error(program(vars + "V20000 : INT;", "")));
}

TEST(WideInput, StructOfFortyThousandMembers) {
  std::string members;
  for (int i = 0; i < 40000; ++i) members += "m" + std::to_string(i) + " : INT;\n";
  std::string type = "TYPE S : STRUCT\n" + members + "END_STRUCT; END_TYPE\n";
  EXPECT_EQ(7, run_and_read(type + program("s : S; x : DINT;", "s.m39999 := 7; x := s.m39999;"), "x"));
  EXPECT_EQ("ST202:40002", first_error("TYPE S : STRUCT\n" + members + "M7 : INT;\nEND_STRUCT; END_TYPE\n" + program("s : S;", "")));
}

}  // namespace
}  // namespace plcfi::st
