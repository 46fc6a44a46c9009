// The arithmetic of the VM's instructions: wraparound, saturating conversions, shifts and
// rotations, division by a constant. Shared by the interpreter (vm.cpp) and by the
// native tier, whose generated C++ includes this file verbatim (so it depends on the
// standard library only): both execute an instruction with the same code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

namespace plcfi::st::ops {

template <class T>
inline T ld(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
template <class T>
inline void st(uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}

// A block move whose size is only known at run time (a structure, an array slice): up to
// 16 bytes as two overlapping loads and two stores, the loads first, so that overlapping
// source and destination behave as memmove; larger blocks go to memmove. Structures of a
// few fields are the common case, and a call to the C library costs more than the move.
inline void move_block(uint8_t* dst, const uint8_t* src, size_t n) {
  if (n >= 8 && n <= 16) {
    const uint64_t head = ld<uint64_t>(src), tail = ld<uint64_t>(src + n - 8);
    st<uint64_t>(dst, head);
    st<uint64_t>(dst + n - 8, tail);
  } else if (n >= 4 && n < 8) {
    const uint32_t head = ld<uint32_t>(src), tail = ld<uint32_t>(src + n - 4);
    st<uint32_t>(dst, head);
    st<uint32_t>(dst + n - 4, tail);
  } else if (n > 0 && n < 4) {
    const uint8_t b0 = src[0], b1 = src[n / 2], b2 = src[n - 1];
    dst[0] = b0;
    dst[n / 2] = b1;
    dst[n - 1] = b2;
  } else if (n > 16) {
    std::memmove(dst, src, n);
  }
}

// move_block for a structure element of an array (LDXB, STXB): 9 to 15 bytes go as 8
// bytes and the rest in pieces of 4, 2 and 1 that do not overlap. An element stored this
// way and read back soon this way (an insertion sort's shifts; a temporary copied back)
// is forwarded from the store buffer piece by piece, where move_block's two overlapping
// 8-byte pieces (bytes 0-7 and 4-11 of 12) make each read wait for both stores to reach
// the cache. struct_sort: -6 % in time; elsewhere move_block's fewer branches win.
inline void move_element(uint8_t* dst, const uint8_t* src, size_t n) {
  if (n <= 8 || n >= 16) return move_block(dst, src, n);
  const size_t r = n - 8;
  // Every load before the first store: the two may overlap.
  const uint64_t head = ld<uint64_t>(src);
  const uint32_t w4 = (r & 4) ? ld<uint32_t>(src + 8) : 0;
  const uint16_t w2 = (r & 2) ? ld<uint16_t>(src + 8 + (r & 4)) : 0;
  const uint8_t w1 = (r & 1) ? src[8 + (r & 6)] : 0;
  st<uint64_t>(dst, head);
  if (r & 4) st<uint32_t>(dst + 8, w4);
  if (r & 2) st<uint16_t>(dst + 8 + (r & 4), w2);
  if (r & 1) dst[8 + (r & 6)] = w1;
}

__extension__ typedef unsigned __int128 U128;  // one MUL on x86-64 and AArch64

// Two's-complement wraparound without undefined behaviour (IEC integer overflow wraps).
template <class T>
using Wide = std::conditional_t<(sizeof(T) < 4), uint32_t, std::make_unsigned_t<T>>;
template <class T>
inline T wadd(T a, T b) {
  if constexpr (std::is_floating_point_v<T>) return a + b;
  else return static_cast<T>(static_cast<Wide<T>>(static_cast<std::make_unsigned_t<T>>(a)) +
                             static_cast<Wide<T>>(static_cast<std::make_unsigned_t<T>>(b)));
}
template <class T>
inline T wsub(T a, T b) {
  if constexpr (std::is_floating_point_v<T>) return a - b;
  else return static_cast<T>(static_cast<Wide<T>>(static_cast<std::make_unsigned_t<T>>(a)) -
                             static_cast<Wide<T>>(static_cast<std::make_unsigned_t<T>>(b)));
}
template <class T>
inline T wmul(T a, T b) {
  if constexpr (std::is_floating_point_v<T>) return a * b;
  else return static_cast<T>(static_cast<Wide<T>>(static_cast<std::make_unsigned_t<T>>(a)) *
                             static_cast<Wide<T>>(static_cast<std::make_unsigned_t<T>>(b)));
}
template <class T>
inline T wneg(T a) {
  if constexpr (std::is_floating_point_v<T>) return -a;
  else return wsub<T>(T(0), a);
}
template <class T>
inline T wdiv(T a, T b) {  // b != 0 checked by the caller for integers
  if constexpr (std::is_signed_v<T> && std::is_integral_v<T>) {
    if (b == T(-1)) return wneg(a);
  }
  return static_cast<T>(a / b);
}
template <class T>
inline T wmod(T a, T b) {
  if constexpr (std::is_signed_v<T>) {
    if (b == T(-1)) return T(0);
  }
  return static_cast<T>(a % b);
}
template <class T>
inline T wabs(T a) {
  if constexpr (std::is_same_v<T, float>) return __builtin_fabsf(a);
  else if constexpr (std::is_floating_point_v<T>) return __builtin_fabs(a);
  else if constexpr (std::is_signed_v<T>) return a < 0 ? wneg(a) : a;
  else return a;
}
// Conversions saturate where C++ would be undefined (float to integer out of range, NaN).
template <class To, class From>
inline To cvt(From v) {
  if constexpr (std::is_integral_v<To> && std::is_floating_point_v<From>) {
    if (__builtin_isnan(v)) return To(0);
    if (v <= static_cast<From>(std::numeric_limits<To>::min())) return std::numeric_limits<To>::min();
    if (v >= static_cast<From>(std::numeric_limits<To>::max())) return std::numeric_limits<To>::max();
    return static_cast<To>(v);
  } else {
    return static_cast<To>(v);
  }
}
template <class T>
inline T shl(T v, uint64_t n) {
  using U = std::make_unsigned_t<T>;
  if (n >= sizeof(T) * 8) return T(0);
  return static_cast<T>(static_cast<U>(static_cast<Wide<T>>(static_cast<U>(v)) << n));
}
template <class T>
inline T shr(T v, uint64_t n) {
  using U = std::make_unsigned_t<T>;
  if (n >= sizeof(T) * 8) return T(0);
  return static_cast<T>(static_cast<U>(static_cast<U>(v) >> n));
}
// A DINT shift count as SHL/SHR/ROL/ROR see it after the count's conversion to ULINT
// (sign-extended: a negative count is a huge one).
inline uint64_t dint_count(int32_t n) { return static_cast<uint64_t>(static_cast<int64_t>(n)); }
template <class T>
inline T rol(T v, uint64_t n) {
  constexpr uint64_t w = sizeof(T) * 8;
  n %= w;
  if (n == 0) return v;
  return static_cast<T>(shl(v, n) | shr(v, w - n));
}
template <class T>
inline T ror(T v, uint64_t n) {
  constexpr uint64_t w = sizeof(T) * 8;
  n %= w;
  if (n == 0) return v;
  return static_cast<T>(shr(v, n) | shl(v, w - n));
}
// REAL/LREAL to integer (IEC 61131-3 Table 22, the IEC 60559 convention): the nearest
// integer, exact halves to the even one (2.5 -> 2, 3.5 -> 4, -2.5 -> -2). nearbyint
// under the default rounding mode, which plcfi never changes.
template <class T>
inline T round_even(T v) {
  if constexpr (sizeof(T) == 4) return __builtin_nearbyintf(v);
  else return __builtin_nearbyint(v);
}
// REAL/LREAL towards zero. The compiler's built-ins, not <cmath>: the native tier's
// generated code includes this file, and <cmath> alone doubles a small unit's compile.
template <class T>
inline T trunc_real(T v) {
  if constexpr (sizeof(T) == 4) return __builtin_truncf(v);
  else return __builtin_trunc(v);
}
inline float f32_bits(uint32_t b) {
  float f;
  std::memcpy(&f, &b, 4);
  return f;
}
inline double f64_bits(uint64_t b) {
  double d;
  std::memcpy(&d, &b, 8);
  return d;
}

// DIVK/MODK, |K| >= 2: the quotient of n by |K| is floor(n * M / 2^S), plus 1 for a
// negative n, with l = ceil(log2 |K|), M = 1 + floor(2^(31 + l) / |K|) and S = 31 + l
// (Granlund and Montgomery, "Division by invariant integers using multiplication", 1994,
// figure 5.2 with N = 32): exact for every 32-bit n, M at most 2^32 so that the product
// fits 64 bits. The sign flips for a negative K (IEC truncates toward zero). One 64-bit
// multiply, a shift and a subtraction on the dividend's path. `ms`: M in bits 0 to 39,
// S from bit 40 (divk_constants).
template <class T, bool IsMod>
inline T divk(T nv, uint64_t ms, int32_t kv) {
  const int64_t n = nv;
  const auto magic = static_cast<int64_t>(ms & ((uint64_t(1) << 40) - 1));
  const auto shift = static_cast<unsigned>(ms >> 40);
  int64_t q = ((n * magic) >> shift) - (n >> 63);
  const int64_t flip = int64_t{kv} >> 63;  // -1 for a negative K, else 0
  q = (q ^ flip) - flip;
  return static_cast<T>(IsMod ? n - q * kv : q);
}

// The word DIVK and MODK carry for a divisor K (|K| from 2 to 2^31): M and S as divk
// reads them.
inline uint64_t divk_constants(int64_t k) {
  const uint64_t ak = static_cast<uint64_t>(k < 0 ? -k : k);
  unsigned l = 0;  // ceil(log2 |K|)
  while ((uint64_t(1) << l) < ak) ++l;
  const uint64_t m = 1 + (uint64_t(1) << (31 + l)) / ak;
  return m | (uint64_t{31 + l} << 40);
}

// WSTRING: UTF-16 code units, ended by a 0 unit, at any address (memcpy, no aligned
// 16-bit loads). The interpreter's WSCPY and WSCMP and the native tier's run these.
inline uint16_t wunit(const uint8_t* p, size_t i) { return ld<uint16_t>(p + 2 * i); }
// The code units before the terminator, at most cap.
inline size_t wstrnlen(const uint8_t* p, size_t cap) {
  size_t n = 0;
  while (n < cap && wunit(p, n) != 0) ++n;
  return n;
}
// dst (capacity cap units) := src, truncated; the two may overlap.
inline void wscpy(uint8_t* dst, const uint8_t* src, size_t cap) {
  size_t n = wstrnlen(src, cap);
  std::memmove(dst, src, 2 * n);
  st<uint16_t>(dst + 2 * n, 0);
}
// -1, 0 or 1 by the first differing code unit (unsigned), as strcmp does by bytes.
inline int wscmp(const uint8_t* a, const uint8_t* b) {
  for (size_t i = 0;; ++i) {
    uint16_t x = wunit(a, i), y = wunit(b, i);
    if (x != y) return x < y ? -1 : 1;
    if (x == 0) return 0;
  }
}

// STRING: bytes ended by a 0 byte, in a variable of capacity cap (cap + 1 bytes). The
// standard functions work on the variables in place, with no heap: the interpreter's
// C++ functions (cpp_functions.cpp) and the native tier's generated code call these. A result may
// be written over an argument (s := LEFT(s, 2), s := CONCAT(s, t), s := CONCAT(t, s)):
// every copy is a memmove, made in the order that reads each source before it is
// overwritten. Lengths and positions are clamped as cpp_functions.cpp documents.
inline size_t slen(const uint8_t* p) { return std::strlen(reinterpret_cast<const char*>(p)); }
inline void sput(uint8_t* dst, uint32_t cap, const uint8_t* src, size_t n) {
  if (n > cap) n = cap;
  std::memmove(dst, src, n);
  dst[n] = 0;
}
inline size_t sclamp(int64_t v, size_t max) { return v < 0 ? 0 : static_cast<uint64_t>(v) < max ? static_cast<size_t>(v) : max; }
inline void str_len(uint8_t* a, const uint8_t* b) { st<int16_t>(a, static_cast<int16_t>(slen(b))); }
inline void str_left(uint8_t* a, uint32_t cap, const uint8_t* b, int64_t l) { sput(a, cap, b, sclamp(l, slen(b))); }
inline void str_right(uint8_t* a, uint32_t cap, const uint8_t* b, int64_t l) {
  size_t n = slen(b), k = sclamp(l, n);
  sput(a, cap, b + (n - k), k);
}
inline void str_mid(uint8_t* a, uint32_t cap, const uint8_t* b, int64_t l, int64_t p) {
  size_t n = slen(b);
  if (p < 1 || static_cast<uint64_t>(p) > n) {
    a[0] = 0;
    return;
  }
  size_t from = static_cast<size_t>(p - 1), k = sclamp(l, n);
  sput(a, cap, b + from, k < n - from ? k : n - from);
}
inline void str_concat(uint8_t* a, uint32_t cap, const uint8_t* b, const uint8_t* c) {
  size_t nb = slen(b), nc = slen(c);
  if (nb > cap) nb = cap;
  if (nc > cap - nb) nc = cap - nb;
  std::memmove(a + nb, c, nc);  // first: the result may be written over c
  if (a != b) std::memmove(a, b, nb);
  a[nb + nc] = 0;
}
// FIND: the 1-based position of c's first occurrence in b, 0 when absent or c is empty.
inline void str_find(uint8_t* a, const uint8_t* b, const uint8_t* c) {
  const char* s = reinterpret_cast<const char*>(b);
  const char* t = reinterpret_cast<const char*>(c);
  const char* at = *t ? std::strstr(s, t) : nullptr;
  st<int16_t>(a, at ? static_cast<int16_t>(at - s + 1) : int16_t(0));
}
// A signed integer's decimal text (INT_TO_STRING and the other signed conversions).
inline void str_of_i64(uint8_t* a, uint32_t cap, int64_t v) {
  char buf[24];
  char* end = buf + sizeof buf;
  char* p = end;
  uint64_t u = v < 0 ? uint64_t{0} - static_cast<uint64_t>(v) : static_cast<uint64_t>(v);
  do {
    *--p = static_cast<char>('0' + u % 10);
    u /= 10;
  } while (u);
  if (v < 0) *--p = '-';
  sput(a, cap, reinterpret_cast<const uint8_t*>(p), static_cast<size_t>(end - p));
}

}  // namespace plcfi::st::ops
