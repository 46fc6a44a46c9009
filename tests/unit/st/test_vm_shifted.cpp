// Bitwise operations on a shifted operand: "a OP SHL(x, n)" and "a OP SHR(x, n)" (OP AND,
// OR or XOR, either operand order, n a constant 0 < n < width) are one instruction
// (ANDSHL_T ... XORSHR_T). Each must give what the shift and the operation give as two
// statements, for every integer and bit-string width, signed or not, in both tiers; other
// counts, variable counts and mixed types stay two instructions.
#include <gtest/gtest.h>

#include <string>

#include "engine.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::occurrences;

struct Width {
  const char* type;
  int bits;
};
constexpr Width kWidths[] = {{"BYTE", 8},  {"WORD", 16}, {"DWORD", 32}, {"LWORD", 64},
                             {"SINT", 8},  {"INT", 16},  {"DINT", 32},  {"LINT", 64}};

// Per type T: x and a drawn from a 64-bit xorshift state each scan; for every operation,
// shift and count (1, the middle, width - 1), f := a OP SHIFT(x, n) and g := SHIFT(x, n)
// OP a, compared with the shift and the operation as two statements (u). `bad` counts
// the differences; the sums keep every result for the comparison of the two tiers.
std::string program() {
  std::string vars, body = "state := state XOR SHL(state, 13);\nstate := state XOR SHR(state, 7);\n"
                           "state := state XOR SHL(state, 17);\n";
  for (const Width& w : kWidths) {
    const std::string T = w.type, v = "_" + T;
    vars += "  x" + v + ", a" + v + ", f" + v + ", g" + v + ", t" + v + ", u" + v + ", sum" + v + " : " + T + ";\n";
    body += "x" + v + " := LWORD_TO_" + T + "(state);\n";
    body += "a" + v + " := LWORD_TO_" + T + "(SHR(state, 23) XOR SHL(state, 5));\n";
    for (const char* op : {"AND", "OR", "XOR"})
      for (const char* sh : {"SHL", "SHR"})
        for (int n : {1, w.bits / 2 + 1, w.bits - 1}) {
          const std::string shift = std::string(sh) + "(x" + v + ", " + std::to_string(n) + ")";
          body += "f" + v + " := a" + v + " " + op + " " + shift + ";\n";
          body += "g" + v + " := " + shift + " " + op + " a" + v + ";\n";
          body += "t" + v + " := " + shift + ";\n";
          body += "u" + v + " := a" + v + " " + op + " t" + v + ";\n";
          body += "IF f" + v + " <> u" + v + " OR g" + v + " <> u" + v + " THEN\n  bad := bad + 1;\nEND_IF;\n";
          body += "sum" + v + " := sum" + v + " XOR f" + v + ";\n";
        }
  }
  return "PROGRAM P\nVAR\n  state : LWORD := 16#9E3779B97F4A7C15;\n  bad : DINT;\n" + vars + "END_VAR\n" + body +
         "END_PROGRAM\n";
}

TEST(VmShifted, EveryOperationShiftAndWidthGivesWhatTwoStatementsGive) {
  vmtest::VmRun r(program(), CompileOptions{}, "shifted.st");
  ASSERT_TRUE(r.ok());
  const std::string dis = r.disasm();
  // f and g fused for 8 types x 3 operations x 2 shifts x 3 counts; u's two statements not.
  size_t fused = 0;
  for (const char* name : {" ANDSHL_", " ANDSHR_", " ORSHL_", " ORSHR_", " XORSHL_", " XORSHR_"}) fused += occurrences(dis, name);
  // + 3: the state's xorshift steps; + 8: a's SHL (after SHR(state, 23), which stays).
  EXPECT_EQ(2u * 8 * 3 * 2 * 3 + 3 + 8, fused) << dis;
  for (int scan = 0; scan < 20; ++scan) {
    ASSERT_TRUE(r.scan()) << r.m->trap().message;
    ASSERT_EQ(0, r.get("P.bad")) << "after scan " << scan;
  }
}

TEST(VmShifted, TheNativeTierComputesTheSame) { same_in_both_tiers("shifted.st", program(), 10); }

// Values a reader can check by hand, and the forms that stay a shift and an operation.
TEST(VmShifted, OtherCountsAndMixedTypesStayTwoInstructions) {
  vmtest::VmRun r(R"(PROGRAM P
VAR
  w : WORD := 16#0F0F; a : WORD := 16#00F0; k : DINT := 4; b : BYTE := 16#81; d : DWORD := 16#80000001;
  s : INT := -2;
  r1, r2, r3, r4, r5, r6 : WORD; r7 : DWORD; r8 : INT; r9 : DWORD;
END_VAR
r1 := a XOR SHL(w, 4);
r2 := SHR(w, 8) OR a;
r3 := a OR SHL(w, 0);
r4 := a OR SHL(w, 16);
r5 := a XOR SHL(w, k);
r6 := a AND SHR(w, 20);
r7 := d XOR SHL(BYTE_TO_DWORD(b), 31);
r8 := s AND SHR(s, 1);
r9 := SHL(d, 1) XOR SHR(d, 31);
END_PROGRAM
)",
                  CompileOptions{}, "shifted.st");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan()) << r.m->trap().message;
  EXPECT_EQ(0xF000, r.get("P.r1"));   // 16#00F0 XOR 16#F0F0
  EXPECT_EQ(0x00FF, r.get("P.r2"));   // 16#000F OR 16#00F0
  EXPECT_EQ(0x0FFF, r.get("P.r3"));   // a count of 0: w itself
  EXPECT_EQ(0x00F0, r.get("P.r4"));   // the width: 0
  EXPECT_EQ(0xF000, r.get("P.r5"));   // a count in a variable
  EXPECT_EQ(0x0000, r.get("P.r6"));   // more than the width
  EXPECT_EQ(0x00000001, r.get("P.r7"));  // 16#80000001 XOR 16#80000000
  EXPECT_EQ(-2 & 0x7FFF, r.get("P.r8"));  // SHR of an INT is logical: 16#7FFF AND 16#FFFE
  EXPECT_EQ(0x00000003, r.get("P.r9"));  // a rotation by 1 written as two shifts
  const std::string dis = r.disasm();
  // Fused: r1, r2, r7 (the shift is DWORD, after the conversion), r8, r9 (the SHR).
  EXPECT_EQ(2u, occurrences(dis, " XORSHL_")) << dis;
  EXPECT_EQ(1u, occurrences(dis, " ORSHR_U16")) << dis;
  EXPECT_EQ(1u, occurrences(dis, " ANDSHR_I16")) << dis;
  EXPECT_EQ(1u, occurrences(dis, " XORSHR_U32")) << dis;
  // Not fused: r3 and r4 (counts 0 and 16), r5 (SHLD, a variable count), r6 (20), r9's SHL.
  EXPECT_EQ(2u, occurrences(dis, " SHL_U16")) << dis;
  EXPECT_EQ(1u, occurrences(dis, " SHLD_U16")) << dis;
  EXPECT_EQ(1u, occurrences(dis, " SHR_U16")) << dis;
  EXPECT_EQ(1u, occurrences(dis, " SHL_U32")) << dis;
}

}  // namespace
}  // namespace plcfi::st
