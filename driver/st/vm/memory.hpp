// Typed loads and stores on VM memory (unaligned-safe, no aliasing violations: the
// compiler turns each into one move).
#pragma once

#include <cstdint>
#include <cstring>

namespace plcfi::st {

template <class T>
inline T load_as(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

template <class T>
inline void store_as(uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}

}  // namespace plcfi::st
