// The IEC 61131-3 implicit-conversion lattice: implicitly_converts and common_type, with the conversions that must be explicit.
#include <gtest/gtest.h>

#include "sema/types.hpp"

namespace plcfi::st {
namespace {

class TypeLattice : public ::testing::Test {
 protected:
  const Type* t(TypeKind k) const { return tt.elementary(k); }
  bool conv(TypeKind from, TypeKind to) const { return implicitly_converts(t(from), t(to)); }
  TypeKind common(TypeKind a, TypeKind b) const {
    const Type* c = common_type(tt, t(a), t(b));
    return c ? c->kind : TypeKind::Void;
  }
  TypeTable tt;
};

TEST_F(TypeLattice, EveryElementaryTypeConvertsToItself) {
  for (TypeKind k : {TypeKind::Bool, TypeKind::SInt, TypeKind::Int, TypeKind::DInt, TypeKind::LInt, TypeKind::USInt,
                     TypeKind::UInt, TypeKind::UDInt, TypeKind::ULInt, TypeKind::Byte, TypeKind::Word, TypeKind::DWord,
                     TypeKind::LWord, TypeKind::Real, TypeKind::LReal, TypeKind::Time, TypeKind::String})
    EXPECT_TRUE(conv(k, k)) << t(k)->name;
}

TEST_F(TypeLattice, SignedIntegersWidenButNeverNarrow) {
  EXPECT_TRUE(conv(TypeKind::SInt, TypeKind::Int));
  EXPECT_TRUE(conv(TypeKind::SInt, TypeKind::LInt));
  EXPECT_TRUE(conv(TypeKind::Int, TypeKind::DInt));
  EXPECT_TRUE(conv(TypeKind::DInt, TypeKind::LInt));
  EXPECT_FALSE(conv(TypeKind::DInt, TypeKind::Int));
  EXPECT_FALSE(conv(TypeKind::LInt, TypeKind::DInt));
  EXPECT_FALSE(conv(TypeKind::Int, TypeKind::SInt));
}

TEST_F(TypeLattice, UnsignedWidensToUnsignedAndToLargerSigned) {
  EXPECT_TRUE(conv(TypeKind::USInt, TypeKind::UInt));
  EXPECT_TRUE(conv(TypeKind::UInt, TypeKind::ULInt));
  EXPECT_TRUE(conv(TypeKind::USInt, TypeKind::Int));
  EXPECT_TRUE(conv(TypeKind::UInt, TypeKind::DInt));
  EXPECT_TRUE(conv(TypeKind::UDInt, TypeKind::LInt));
  EXPECT_FALSE(conv(TypeKind::USInt, TypeKind::SInt));  // same width: 200 does not fit
  EXPECT_FALSE(conv(TypeKind::UDInt, TypeKind::DInt));
  EXPECT_FALSE(conv(TypeKind::ULInt, TypeKind::LInt));
  EXPECT_FALSE(conv(TypeKind::Int, TypeKind::UInt));  // signed never becomes unsigned
  EXPECT_FALSE(conv(TypeKind::SInt, TypeKind::ULInt));
  EXPECT_FALSE(conv(TypeKind::UInt, TypeKind::USInt));
}

TEST_F(TypeLattice, BitStringsWidenAlongTheirChain) {
  EXPECT_TRUE(conv(TypeKind::Byte, TypeKind::Word));
  EXPECT_TRUE(conv(TypeKind::Word, TypeKind::DWord));
  EXPECT_TRUE(conv(TypeKind::Byte, TypeKind::LWord));
  EXPECT_TRUE(conv(TypeKind::Bool, TypeKind::Byte));
  EXPECT_FALSE(conv(TypeKind::Word, TypeKind::Byte));
  EXPECT_FALSE(conv(TypeKind::LWord, TypeKind::DWord));
  EXPECT_FALSE(conv(TypeKind::Byte, TypeKind::Bool));
  EXPECT_FALSE(conv(TypeKind::Word, TypeKind::Int));  // bit string to signed needs WORD_TO_INT
  EXPECT_FALSE(conv(TypeKind::Int, TypeKind::Word));
}

TEST_F(TypeLattice, IntegersToRealsOnlyWhenExact) {
  EXPECT_TRUE(conv(TypeKind::SInt, TypeKind::LReal));
  EXPECT_TRUE(conv(TypeKind::SInt, TypeKind::Real));
  EXPECT_TRUE(conv(TypeKind::Int, TypeKind::Real));
  EXPECT_TRUE(conv(TypeKind::UInt, TypeKind::Real));
  EXPECT_TRUE(conv(TypeKind::DInt, TypeKind::LReal));
  EXPECT_TRUE(conv(TypeKind::UDInt, TypeKind::LReal));
  EXPECT_TRUE(conv(TypeKind::Real, TypeKind::LReal));
  EXPECT_FALSE(conv(TypeKind::DInt, TypeKind::Real));  // 24-bit mantissa
  EXPECT_FALSE(conv(TypeKind::UDInt, TypeKind::Real));
  EXPECT_FALSE(conv(TypeKind::LInt, TypeKind::LReal));  // 53-bit mantissa
  EXPECT_FALSE(conv(TypeKind::ULInt, TypeKind::LReal));
  EXPECT_FALSE(conv(TypeKind::LReal, TypeKind::Real));
  EXPECT_FALSE(conv(TypeKind::Real, TypeKind::DInt));
  EXPECT_FALSE(conv(TypeKind::LReal, TypeKind::LInt));
  EXPECT_FALSE(conv(TypeKind::Byte, TypeKind::Real));
}

TEST_F(TypeLattice, TimeDateStringAndBoolDoNotMixWithNumbers) {
  EXPECT_TRUE(conv(TypeKind::Time, TypeKind::LTime));
  EXPECT_FALSE(conv(TypeKind::LTime, TypeKind::Time));
  EXPECT_FALSE(conv(TypeKind::Time, TypeKind::LInt));
  EXPECT_FALSE(conv(TypeKind::LInt, TypeKind::Time));
  EXPECT_FALSE(conv(TypeKind::Date, TypeKind::DateTime));
  EXPECT_FALSE(conv(TypeKind::Bool, TypeKind::Int));
  EXPECT_FALSE(conv(TypeKind::Int, TypeKind::Bool));
  EXPECT_FALSE(conv(TypeKind::String, TypeKind::WString));
  EXPECT_FALSE(conv(TypeKind::Int, TypeKind::String));
  EXPECT_FALSE(implicitly_converts(nullptr, t(TypeKind::Int)));
}

TEST_F(TypeLattice, StringsOfAnyLengthConvert) {
  const Type* s10 = tt.string_type(10, false);
  EXPECT_TRUE(implicitly_converts(s10, t(TypeKind::String)));
  EXPECT_TRUE(implicitly_converts(t(TypeKind::String), s10));
  EXPECT_FALSE(implicitly_converts(s10, tt.string_type(10, true)));
  EXPECT_EQ("STRING[10]", s10->name);
  EXPECT_EQ(11u, s10->size);
}

TEST_F(TypeLattice, SubrangeConvertsToAndFromItsBase) {
  Type* sub = tt.make(TypeKind::Int, "INT (0..100)");
  sub->ranged = true;
  sub->lo = 0;
  sub->hi = 100;
  sub->size = 2;
  EXPECT_TRUE(implicitly_converts(sub, t(TypeKind::Int)));
  EXPECT_TRUE(implicitly_converts(t(TypeKind::Int), sub));
  EXPECT_TRUE(implicitly_converts(sub, t(TypeKind::DInt)));
  EXPECT_EQ(TypeKind::Int, common_type(tt, sub, t(TypeKind::SInt))->kind);
  EXPECT_FALSE(common_type(tt, sub, t(TypeKind::SInt))->ranged);
}

TEST_F(TypeLattice, EnumerationsConvertOnlyToThemselves) {
  Type* a = tt.make(TypeKind::Enum, "Color");
  a->base = t(TypeKind::Int);
  Type* b = tt.make(TypeKind::Enum, "Mode");
  b->base = t(TypeKind::Int);
  EXPECT_TRUE(implicitly_converts(a, a));
  EXPECT_FALSE(implicitly_converts(a, b));
  EXPECT_FALSE(implicitly_converts(a, t(TypeKind::Int)));
  EXPECT_FALSE(implicitly_converts(t(TypeKind::Int), a));
  EXPECT_EQ(a, common_type(tt, a, a));
  EXPECT_EQ(nullptr, common_type(tt, a, b));
}

TEST_F(TypeLattice, CommonTypeIsTheSmallestBothWidenTo) {
  EXPECT_EQ(TypeKind::Int, common(TypeKind::SInt, TypeKind::Int));
  EXPECT_EQ(TypeKind::Int, common(TypeKind::Int, TypeKind::SInt));
  EXPECT_EQ(TypeKind::Int, common(TypeKind::USInt, TypeKind::Int));
  EXPECT_EQ(TypeKind::Int, common(TypeKind::SInt, TypeKind::USInt));
  EXPECT_EQ(TypeKind::DInt, common(TypeKind::UInt, TypeKind::Int));
  EXPECT_EQ(TypeKind::LInt, common(TypeKind::UDInt, TypeKind::DInt));
  EXPECT_EQ(TypeKind::UDInt, common(TypeKind::USInt, TypeKind::UDInt));
  EXPECT_EQ(TypeKind::Word, common(TypeKind::Byte, TypeKind::Word));
  EXPECT_EQ(TypeKind::LReal, common(TypeKind::Real, TypeKind::LReal));
  EXPECT_EQ(TypeKind::Real, common(TypeKind::Int, TypeKind::Real));
  EXPECT_EQ(TypeKind::LReal, common(TypeKind::DInt, TypeKind::Real));  // both widen to LREAL
  EXPECT_EQ(TypeKind::Time, common(TypeKind::Time, TypeKind::Time));
}

TEST_F(TypeLattice, CommonTypeIsNullWhenNoneExists) {
  EXPECT_EQ(TypeKind::Void, common(TypeKind::ULInt, TypeKind::LInt));
  EXPECT_EQ(TypeKind::Void, common(TypeKind::LInt, TypeKind::Real));
  EXPECT_EQ(TypeKind::Void, common(TypeKind::Time, TypeKind::DInt));
  EXPECT_EQ(TypeKind::Void, common(TypeKind::Bool, TypeKind::Int));
  EXPECT_EQ(TypeKind::Void, common(TypeKind::String, TypeKind::Int));
  EXPECT_EQ(TypeKind::Void, common(TypeKind::Word, TypeKind::Int));
}

TEST_F(TypeLattice, LayoutOfElementaryTypes) {
  EXPECT_EQ(1u, t(TypeKind::Bool)->size);
  EXPECT_EQ(2u, t(TypeKind::Int)->size);
  EXPECT_EQ(4u, t(TypeKind::Real)->size);
  EXPECT_EQ(8u, t(TypeKind::Time)->size);
  EXPECT_EQ(81u, t(TypeKind::String)->size);
  EXPECT_EQ(Storage::I16, t(TypeKind::Int)->storage());
  EXPECT_EQ(Storage::U16, t(TypeKind::Word)->storage());
  EXPECT_EQ(Storage::I64, t(TypeKind::Time)->storage());
  EXPECT_EQ(16u, t(TypeKind::Word)->bit_width());
  EXPECT_EQ(1u, t(TypeKind::Bool)->bit_width());
  EXPECT_EQ(t(TypeKind::TimeOfDay), tt.by_name("tod"));
  EXPECT_EQ(t(TypeKind::DInt), tt.by_name("DInt"));
  EXPECT_EQ(nullptr, tt.by_name("Motor"));
}

}  // namespace
}  // namespace plcfi::st
