// A 64-bit FNV-1a hash of a sequence of strings, for fingerprints that must stay the same
// across runs and machines (journals, the run history of test scripts): not for security.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace plcfi::common {

class Fnv64 {
 public:
  // Adds one string; a separator after it keeps ("ab", "c") apart from ("a", "bc").
  Fnv64& add(std::string_view s) {
    for (unsigned char ch : s) h_ = (h_ ^ ch) * kPrime;
    h_ = (h_ ^ 0xff) * kPrime;
    return *this;
  }
  uint64_t value() const { return h_; }
  std::string hex() const { return fmt::format("{:016x}", h_); }

 private:
  static constexpr uint64_t kPrime = 1099511628211ull;
  uint64_t h_ = 1469598103934665603ull;
};

}  // namespace plcfi::common
