// WSTRING text (vm/wide.hpp): UTF-8 <-> UTF-16 at the engine's boundaries, and the
// layout of WSTRING[N] in memory.
#include <gtest/gtest.h>

#include <vector>

#include "sema/types.hpp"
#include "vm/ops.hpp"
#include "vm/wide.hpp"

namespace plcfi::st {
namespace {

TEST(Wide, Utf8ToUtf16CountsCodeUnits) {
  EXPECT_EQ(utf8_to_utf16("abc"), u"abc");
  EXPECT_EQ(utf8_to_utf16("äö◦"), u"äö◦");
  EXPECT_EQ(utf8_to_utf16("äö◦").size(), 3u);
  EXPECT_EQ(utf8_to_utf16("😀"), std::u16string({char16_t(0xD83D), char16_t(0xDE00)}));
}

TEST(Wide, InvalidUtf8BytesAreLatin1) {
  EXPECT_EQ(utf8_to_utf16("\xE4"), u"\u00E4");
  EXPECT_EQ(utf8_to_utf16("a\xC3"), u"a\u00C3");       // a sequence cut short
  EXPECT_EQ(utf8_to_utf16("\xC0\x80"), u"\u00C0\u0080");  // overlong
}

TEST(Wide, RoundTripsThroughUtf8) {
  for (std::u16string s : {std::u16string(u"Grüße ◦"), std::u16string({char16_t(0xD83D), char16_t(0xDE00), u'x'}),
                           std::u16string({char16_t(0xD800)}), std::u16string({char16_t(0xDC00), u'a'})})
    EXPECT_EQ(utf8_to_utf16(utf16_to_utf8(s)), s);
  EXPECT_EQ(utf16_to_utf8(u"äö◦"), "äö◦");
  EXPECT_EQ(utf16_to_utf8(std::u16string({char16_t(0xD83D), char16_t(0xDE00)})), "😀");
}

TEST(Wide, StoreTruncatesAndTerminates) {
  std::vector<uint8_t> mem(2 * (3 + 1) + 1, 0xAA);
  store_wstring(mem.data() + 1, 3, u"äöüß");  // odd address: no aligned loads
  EXPECT_EQ(ops::wunit(mem.data() + 1, 0), 0x00E4);
  EXPECT_EQ(ops::wunit(mem.data() + 1, 3), 0);
  EXPECT_EQ(load_wstring(mem.data() + 1, 3), u"äöü");
  EXPECT_EQ(ops::wstrnlen(mem.data() + 1, 100), 3u);
}

TEST(Wide, CompareByCodeUnits) {
  std::vector<uint8_t> a(8), b(8);
  store_wstring(a.data(), 3, u"äb");
  store_wstring(b.data(), 3, u"äc");
  EXPECT_LT(ops::wscmp(a.data(), b.data()), 0);
  EXPECT_EQ(ops::wscmp(a.data(), a.data()), 0);
  store_wstring(b.data(), 3, u"ä");
  EXPECT_GT(ops::wscmp(a.data(), b.data()), 0);  // a prefix is less
}

TEST(Wide, WStringLayoutIsUtf16) {
  TypeTable tt;
  const Type* w10 = tt.string_type(10, true);
  EXPECT_EQ(w10->size, 22u);
  EXPECT_EQ(w10->align, 2u);
  EXPECT_EQ(tt.elementary(TypeKind::WString)->size, 162u);
  EXPECT_EQ(tt.string_type(10, false)->size, 11u);
}

}  // namespace
}  // namespace plcfi::st
