// The interpreter's and the native tier's memory compared byte by byte, the compiler
// temporaries aside (native.hpp, scratch_ranges): the native tier leaves out stores of
// temporaries nobody reads back, so those bytes may hold an older value.
#pragma once

#include <gtest/gtest.h>

#include "native/native.hpp"
#include "vm/vm.hpp"

namespace plcfi::st {

inline ::testing::AssertionResult same_memory(const Application& app, const Machine& a, const Machine& n) {
  uint64_t i = first_difference(scratch_ranges(app), a.mem(), n.mem(), a.mem_size());
  if (i == a.mem_size()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "memory differs at address " << i << ": " << int{a.mem()[i]} << " (interpreter) vs "
                                       << int{n.mem()[i]} << " (native)";
}

}  // namespace plcfi::st
