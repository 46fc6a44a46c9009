#include "wide.hpp"

#include <algorithm>

#include "ops.hpp"

namespace plcfi::st {

namespace {
bool continuation(std::string_view s, size_t i) {
  return i < s.size() && (static_cast<unsigned char>(s[i]) & 0xC0) == 0x80;
}

// The code point of the UTF-8 sequence at s[i] and its length, or 0 when none starts there.
size_t decode(std::string_view s, size_t i, uint32_t* cp) {
  const auto b = static_cast<unsigned char>(s[i]);
  size_t n = b < 0x80 ? 1 : (b & 0xE0) == 0xC0 ? 2 : (b & 0xF0) == 0xE0 ? 3 : (b & 0xF8) == 0xF0 ? 4 : 0;
  if (n == 0) return 0;
  uint32_t v = n == 1 ? b : b & (0x7Fu >> n);
  for (size_t k = 1; k < n; ++k) {
    if (!continuation(s, i + k)) return 0;
    v = (v << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3Fu);
  }
  static constexpr uint32_t kMin[] = {0, 0, 0x80, 0x800, 0x10000};
  if (v < kMin[n] || v > 0x10FFFF) return 0;  // overlong or beyond Unicode
  *cp = v;
  return n;
}
}  // namespace

std::u16string utf8_to_utf16(std::string_view s) {
  std::u16string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size();) {
    uint32_t cp = 0;
    size_t n = decode(s, i, &cp);
    if (n == 0) {
      cp = static_cast<unsigned char>(s[i]);
      n = 1;
    }
    i += n;
    if (cp < 0x10000) {
      out += static_cast<char16_t>(cp);
    } else {
      cp -= 0x10000;
      out += static_cast<char16_t>(0xD800 + (cp >> 10));
      out += static_cast<char16_t>(0xDC00 + (cp & 0x3FF));
    }
  }
  return out;
}

std::string utf16_to_utf8(std::u16string_view s) {
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    uint32_t cp = s[i];
    if (cp >= 0xD800 && cp < 0xDC00 && i + 1 < s.size() && s[i + 1] >= 0xDC00 && s[i + 1] < 0xE000)
      cp = 0x10000 + ((cp - 0xD800) << 10) + (s[++i] - 0xDC00u);
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }
  return out;
}

std::u16string load_wstring(const uint8_t* p, size_t cap) {
  const size_t n = ops::wstrnlen(p, cap);
  std::u16string out(n, u'\0');
  for (size_t i = 0; i < n; ++i) out[i] = static_cast<char16_t>(ops::wunit(p, i));
  return out;
}

void store_wstring(uint8_t* p, size_t cap, std::u16string_view s) {
  const size_t n = std::min(s.size(), cap);
  // Built first: s may lie in the memory it is stored to (s := LEFT(s, 2)).
  std::u16string units(s.substr(0, n));
  for (size_t i = 0; i < n; ++i) ops::st<uint16_t>(p + 2 * i, units[i]);
  ops::st<uint16_t>(p + 2 * n, 0);
}

}  // namespace plcfi::st
