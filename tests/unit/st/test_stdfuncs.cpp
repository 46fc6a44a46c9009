// The standard function table and the conversion rules of sema/stdfuncs: lookup by name,
// argument counts, conversion names taken apart and the kind of each conversion.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "sema/stdfuncs.hpp"

namespace plcfi::st {
namespace {

TEST(StdFuncTable, EveryEntryIsFoundByItsOwnName) {
  ASSERT_FALSE(std_functions().empty());
  for (const StdFunc& f : std_functions()) {
    const StdFunc* found = find_std_function(f.name);
    // The same entry, not only one of that name: a duplicate name would shadow a row.
    EXPECT_EQ(found, &f) << f.name;
  }
}

TEST(StdFuncTable, NamesAreCanonicalAndUnique) {
  std::set<std::string> seen;
  for (const StdFunc& f : std_functions()) {
    std::string name(f.name);
    EXPECT_EQ(canon(name), name) << "lookups are by the canonical (upper-case) name";
    EXPECT_TRUE(seen.insert(name).second) << name << " twice";
  }
}

TEST(StdFuncTable, UnknownNamesAreNotFound) {
  for (std::string_view n : {"", "FOO", "SQRTX", "SQR", "sqrt", "INT_TO_REAL", "TO_DINT", "TRUNC", "ASSERT"})
    EXPECT_EQ(find_std_function(n), nullptr) << n;
}

TEST(StdFuncTable, FamiliesAndPayloads) {
  const StdFunc* sqrt = find_std_function("SQRT");
  ASSERT_NE(sqrt, nullptr);
  EXPECT_EQ(sqrt->family, StdFamily::Math);
  EXPECT_EQ(sqrt->native, Native::SQRT_F32);
  const StdFunc* ge = find_std_function("GE");
  ASSERT_NE(ge, nullptr);
  EXPECT_EQ(ge->family, StdFamily::Operator);
  EXPECT_EQ(ge->op, BinaryOp::Ge);
  const StdFunc* sub_dt = find_std_function("SUB_DT_DT");
  ASSERT_NE(sub_dt, nullptr);
  EXPECT_EQ(sub_dt->op, BinaryOp::Sub);
  const StdFunc* rol = find_std_function("ROL");
  ASSERT_NE(rol, nullptr);
  EXPECT_EQ(rol->shift, Shift::Rol);
  const StdFunc* limit = find_std_function("LIMIT");
  ASSERT_NE(limit, nullptr);
  EXPECT_EQ(limit->pick, Pick::Limit);
  ASSERT_EQ(limit->params.size(), 3u);
  EXPECT_STREQ(limit->params[1], "IN");
  const StdFunc* mid = find_std_function("MID");
  ASSERT_NE(mid, nullptr);
  EXPECT_EQ(mid->native, Native::S_MID);
  EXPECT_STREQ(mid->operands, "SII");
  EXPECT_FALSE(mid->int_result);
  EXPECT_TRUE(find_std_function("LEN")->int_result);
  EXPECT_EQ(find_std_function("MOCK_VERIFY_CALL_COUNT")->assert_kind, AssertKind::CallCount);
  EXPECT_EQ(find_std_function("PASSED")->temporal, Temporal::Passed);
  EXPECT_EQ(find_std_function("REF")->family, StdFamily::AddressOf);
}

TEST(StdFuncTable, ArgumentCounts) {
  for (const StdFunc& f : std_functions()) {
    EXPECT_LE(f.min_args, f.max_count()) << f.name;
    // Each string-function operand letter is one argument.
    if (f.family == StdFamily::String) {
      EXPECT_EQ(std::string_view(f.operands).size(), f.min_args) << f.name;
    }
  }
  EXPECT_EQ(find_std_function("LIMIT")->max_count(), 3u);
  EXPECT_EQ(find_std_function("ADD")->max_count(), SIZE_MAX);
  EXPECT_EQ(find_std_function("MUX")->max_count(), SIZE_MAX);
  EXPECT_EQ(find_std_function("ADD_TIME")->max_count(), 2u);  // the named time functions are binary
  EXPECT_EQ(find_std_function("SUB")->max_count(), 2u);
  EXPECT_EQ(find_std_function("REPLACE")->min_args, 4u);
  // Assertions: the values, then an optional message.
  const StdFunc* near = find_std_function("ASSERT_NEAR");
  EXPECT_EQ(near->min_args, 3u);
  EXPECT_EQ(near->max_count(), 4u);
  EXPECT_EQ(find_std_function("ASSERT_TRUE")->max_count(), 2u);
}

TEST(StdFuncTable, FlagsRestrictWhereANameIsKnown) {
  EXPECT_TRUE(find_std_function("RISING")->late_only());
  EXPECT_FALSE(find_std_function("RISING")->test_only());
  EXPECT_TRUE(find_std_function("ASSERT_EQ")->test_only());
  EXPECT_TRUE(find_std_function("ADVANCE_TIME")->test_only());
  EXPECT_FALSE(find_std_function("MAX")->late_only());
  EXPECT_FALSE(find_std_function("MAX")->test_only());
}

class Conversions : public ::testing::Test {
 protected:
  const Type* t(TypeKind k) const { return tt.elementary(k); }
  ConversionKind kind(TypeKind from, TypeKind to, bool trunc = false) const {
    return conversion_kind(t(from), t(to), trunc);
  }
  // "from>to", with "-" for no source type and a leading "~" for TRUNC; "none" when not a conversion.
  // "bcd<" / "bcd>" in front: decoding / encoding BCD.
  std::string parsed(std::string_view name) const {
    auto c = parse_conversion(tt, name);
    if (!c) return "none";
    const char* bcd = c->bcd == ConversionName::Bcd::Decode ? "bcd<" : c->bcd == ConversionName::Bcd::Encode ? "bcd>" : "";
    return std::string(bcd) + (c->trunc ? "~" : "") + (c->from ? c->from->name : "-") + ">" + c->to->name;
  }
  TypeTable tt;
};

TEST_F(Conversions, NamesParseToTheirTypes) {
  EXPECT_EQ(parsed("INT_TO_REAL"), "INT>REAL");
  EXPECT_EQ(parsed("TIME_TO_DINT"), "TIME>DINT");
  EXPECT_EQ(parsed("STRING_TO_INT"), "STRING>INT");
  EXPECT_EQ(parsed("LREAL_TO_LINT"), "LREAL>LINT");
  EXPECT_EQ(parsed("TO_DINT"), "->DINT");
  EXPECT_EQ(parsed("TO_STRING"), "->STRING");
  EXPECT_EQ(parsed("TRUNC"), "~->DINT");
  // Short names of the date types, and a long name holding "_OF_" (not "_TO_").
  EXPECT_EQ(parsed("DT_TO_DATE"), "DATE_AND_TIME>DATE");
  EXPECT_EQ(parsed("TOD_TO_STRING"), "TIME_OF_DAY>STRING");
  EXPECT_EQ(parsed("TIME_OF_DAY_TO_DT"), "TIME_OF_DAY>DATE_AND_TIME");
  // TRUNC into a named type, from any or a named real type.
  EXPECT_EQ(parsed("TRUNC_INT"), "~->INT");
  EXPECT_EQ(parsed("REAL_TRUNC_INT"), "~REAL>INT");
  EXPECT_EQ(parsed("LREAL_TRUNC_ULINT"), "~LREAL>ULINT");
  // BCD: the standard's forms, the generic ones and the library-style INT_TO_BCD (into the
  // bit string of the integer's width).
  EXPECT_EQ(parsed("WORD_BCD_TO_UINT"), "bcd<WORD>UINT");
  EXPECT_EQ(parsed("UINT_TO_BCD_WORD"), "bcd>UINT>WORD");
  EXPECT_EQ(parsed("BCD_TO_INT"), "bcd<->INT");
  EXPECT_EQ(parsed("TO_BCD_DWORD"), "bcd>->DWORD");
  EXPECT_EQ(parsed("INT_TO_BCD"), "bcd>INT>WORD");
  EXPECT_EQ(parsed("USINT_TO_BCD"), "bcd>USINT>BYTE");
}

TEST_F(Conversions, OtherNamesAreNoConversion) {
  for (std::string_view n : {"FOO_TO_INT", "INT_TO_FOO", "TO_", "TO_FOO", "SQRT", "INT_TRUNC_INT", "TRUNC_REAL",
                             "TRUNC_FOO", "REAL_BCD_TO_INT", "INT_TO_BCD_REAL", "BCD_TO_REAL", "REAL_TO_BCD",
                             "ADD_TIME", "CONCAT_DATE_TOD", "SUB_TOD_TOD", ""})
    EXPECT_EQ(parsed(n), "none") << n;
}

// Table names are tried before conversion names: none may read as both.
TEST_F(Conversions, NoStandardFunctionNameIsAConversion) {
  for (const StdFunc& f : std_functions()) EXPECT_EQ(parsed(f.name), "none") << f.name;
}

TEST_F(Conversions, KindsOfRepresentativePairs) {
  using K = ConversionKind;
  EXPECT_EQ(kind(TypeKind::Int, TypeKind::Real), K::Numeric);
  EXPECT_EQ(kind(TypeKind::DInt, TypeKind::Int), K::Numeric);
  EXPECT_EQ(kind(TypeKind::Byte, TypeKind::Word), K::Numeric);
  EXPECT_EQ(kind(TypeKind::Real, TypeKind::Int), K::Round);
  EXPECT_EQ(kind(TypeKind::LReal, TypeKind::DWord), K::Round);
  EXPECT_EQ(kind(TypeKind::Real, TypeKind::LReal), K::Numeric);
  EXPECT_EQ(kind(TypeKind::Real, TypeKind::DInt, true), K::Trunc);
  EXPECT_EQ(kind(TypeKind::Int, TypeKind::String), K::ToString);
  EXPECT_EQ(kind(TypeKind::Time, TypeKind::String), K::ToString);
  EXPECT_EQ(kind(TypeKind::String, TypeKind::Int), K::FromString);
  EXPECT_EQ(kind(TypeKind::String, TypeKind::Bool), K::FromString);
  EXPECT_EQ(kind(TypeKind::String, TypeKind::Time), K::FromString);
  EXPECT_EQ(kind(TypeKind::String, TypeKind::WString), K::StringCopy);
  EXPECT_EQ(kind(TypeKind::DateTime, TypeKind::Date), K::DtToDate);
  EXPECT_EQ(kind(TypeKind::DateTime, TypeKind::TimeOfDay), K::DtToTod);
  EXPECT_EQ(kind(TypeKind::Time, TypeKind::LTime), K::Retype);
  EXPECT_EQ(kind(TypeKind::Date, TypeKind::DateTime), K::Retype);
  EXPECT_EQ(kind(TypeKind::Bool, TypeKind::Bool), K::Retype);
  EXPECT_EQ(kind(TypeKind::Int, TypeKind::Bool), K::ToBool);
  EXPECT_EQ(kind(TypeKind::Real, TypeKind::Bool), K::ToBool);
  EXPECT_EQ(kind(TypeKind::Time, TypeKind::Bool), K::ToBool);
  EXPECT_EQ(kind(TypeKind::Time, TypeKind::DInt), K::TimeToNumber);
  EXPECT_EQ(kind(TypeKind::Time, TypeKind::Real), K::TimeToNumber);
  EXPECT_EQ(kind(TypeKind::DInt, TypeKind::Time), K::NumberToTime);
  EXPECT_EQ(kind(TypeKind::LReal, TypeKind::Time), K::NumberToTime);
  EXPECT_EQ(kind(TypeKind::Bool, TypeKind::Int), K::Numeric);
}

TEST_F(Conversions, ImpossiblePairsAreNone) {
  using K = ConversionKind;
  EXPECT_EQ(kind(TypeKind::Int, TypeKind::DInt, true), K::None);  // TRUNC of an integer
  EXPECT_EQ(kind(TypeKind::String, TypeKind::Date), K::None);
  EXPECT_EQ(kind(TypeKind::String, TypeKind::TimeOfDay), K::None);
  Type* s = tt.make(TypeKind::Struct, "S");
  EXPECT_EQ(conversion_kind(s, t(TypeKind::Int)), K::None);
  EXPECT_EQ(conversion_kind(s, t(TypeKind::String)), K::None);
  EXPECT_EQ(conversion_kind(t(TypeKind::Int), s), K::None);
}

TEST_F(Conversions, AnEnumerationConvertsAsItsBaseType) {
  Type* e = tt.make(TypeKind::Enum, "E");
  e->base = t(TypeKind::Int);
  EXPECT_EQ(conversion_kind(e, t(TypeKind::DInt)), ConversionKind::Numeric);
  EXPECT_EQ(conversion_kind(e, t(TypeKind::String)), ConversionKind::ToString);
}

}  // namespace
}  // namespace plcfi::st
