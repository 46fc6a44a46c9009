// One bit of a word as a BOOL, (SHR(x, n) AND 1) = 1 and its three other spellings, is one
// GETBITD instruction: every width, every count from negative to past the width, each
// spelling and operand order gives what SHR and AND give computed apart, in the
// interpreter and the native tier.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "engine.hpp"
#include "native/native.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

// For a type T and a value x: fused[f, n] from the one-line forms, apart[f, n] from SHR
// stored first (another statement, so nothing fuses), for n in -3..70.
std::string program(const std::string& type, const std::string& x) {
  return R"(PROGRAM P
VAR
  x : )" + type + " := " + x + R"(;
  s : )" + type + R"(;
  n : DINT;
  fused : ARRAY [0..5, -3..70] OF BOOL;
  apart : ARRAY [0..5, -3..70] OF BOOL;
END_VAR
FOR n := -3 TO 70 DO
  fused[0, n] := (SHR(x, n) AND 1) = 1;
  fused[1, n] := (SHR(x, n) AND 1) <> 0;
  fused[2, n] := (SHR(x, n) AND 1) = 0;
  fused[3, n] := (SHR(x, n) AND 1) <> 1;
  fused[4, n] := 1 = (1 AND SHR(x, n));
  fused[5, n] := 0 <> (1 AND SHR(x, n));
  s := SHR(x, n);
  apart[0, n] := (s AND 1) = 1;
  apart[1, n] := (s AND 1) <> 0;
  apart[2, n] := (s AND 1) = 0;
  apart[3, n] := (s AND 1) <> 1;
  apart[4, n] := 1 = (1 AND s);
  apart[5, n] := 0 <> (1 AND s);
END_FOR;
END_PROGRAM
)";
}

struct Width {
  const char* type;
  const char* x;
  uint64_t value;
  int bits;
};
const Width kWidths[] = {
    {"BYTE", "16#A5", 0xA5, 8},
    {"WORD", "16#8001", 0x8001, 16},
    {"DWORD", "16#8000_4001", 0x80004001, 32},
    {"LWORD", "16#8000_0000_0001_0003", 0x8000000000010003ull, 64},
};

TEST(VmBits, ABitOfAWordIsOneInstructionForEverySpellingAndCount) {
  for (const Width& w : kWidths) {
    vmtest::VmRun p(program(w.type, w.x), {}, "bits.st");
    ASSERT_TRUE(p.ok()) << w.type;
    std::string dis = p.disasm();
    size_t fused = 0;
    for (size_t at = dis.find("GETBITD_"); at != std::string::npos; at = dis.find("GETBITD_", at + 1)) ++fused;
    EXPECT_EQ(6u, fused) << w.type << "\n" << dis;
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    for (int n = -3; n <= 70; ++n) {
      // SHR by a negative DINT count shifts by a huge one: everything out.
      const bool bit = n >= 0 && n < w.bits && ((w.value >> n) & 1u) != 0;
      const bool want[] = {bit, bit, !bit, !bit, bit, bit};
      for (int f = 0; f < 6; ++f) {
        const std::string at = "[" + std::to_string(f) + ", " + std::to_string(n) + "]";
        EXPECT_EQ(want[f] ? 1 : 0, p.get("P.fused" + at)) << w.type << " form " << f << " n " << n;
        EXPECT_EQ(want[f] ? 1 : 0, p.get("P.apart" + at)) << w.type << " form " << f << " n " << n;
      }
    }
  }
}

TEST(VmBits, BitsOfWordsAgreeWithTheNativeTier) {
  for (const Width& w : kWidths) {
    SCOPED_TRACE(w.type);
    same_in_both_tiers("bits.st", program(w.type, w.x), 1);
  }
}

// Left as they were: a mask other than 1, a comparison with 2, a count that is not a DINT
// variable, the parts in different statements.
TEST(VmBits, OtherMasksAndComparisonsAreNotABit) {
  vmtest::VmRun p(R"(PROGRAM P
VAR x : WORD := 16#00F6; k : DINT := 1; i : INT := 2; a, b, c : BOOL; END_VAR
a := (SHR(x, k) AND 3) = 3;
b := (SHR(x, k) AND 1) = 2;
c := (SHR(x, i) AND 1) = 1;
END_PROGRAM
)", {}, "bits.st");
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(std::string::npos, p.disasm().find("GETBITD")) << p.disasm();
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(1, p.get("P.a"));  // 16#7B AND 3 = 3
  EXPECT_EQ(0, p.get("P.b"));
  EXPECT_EQ(1, p.get("P.c"));  // 16#3D AND 1
}

// A comparison with 0 that is the whole condition of an IF stays SHRD and one JTZ/JTNZ
// (two instructions either way); with 1, or inside a larger condition, it is a GETBITD.
TEST(VmBits, AWholeConditionAgainstZeroStaysATestOfBits) {
  vmtest::VmRun p(R"(PROGRAM P
VAR x : WORD := 16#0006; k : DINT := 1; go : BOOL := TRUE; a, b, c : DINT; END_VAR
IF (SHR(x, k) AND 1) <> 0 THEN a := 1; END_IF;
IF (SHR(x, k) AND 1) = 1 THEN b := 1; END_IF;
IF go AND (SHR(x, k) AND 1) = 0 THEN c := 1; END_IF;
END_PROGRAM
)", {}, "bits.st");
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("JTZ_U16")) << dis;
  size_t fused = 0;
  for (size_t at = dis.find("GETBITD_U16"); at != std::string::npos; at = dis.find("GETBITD_U16", at + 1)) ++fused;
  EXPECT_EQ(2u, fused) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(1, p.get("P.a"));
  EXPECT_EQ(1, p.get("P.b"));
  EXPECT_EQ(0, p.get("P.c"));
}

}  // namespace
}  // namespace plcfi::st
