// Typed loads and stores on VM memory (unaligned-safe, no aliasing violations: the
// compiler turns each into one move).
#pragma once

#include <cstdint>

#include "ops.hpp"

namespace plcfi::st {

template <class T>
inline T load_as(const uint8_t* p) {
  return ops::ld<T>(p);
}

template <class T>
inline void store_as(uint8_t* p, T v) {
  ops::st<T>(p, v);
}

}  // namespace plcfi::st
