// The one fake I/O backend of the tests and benchmarks: inputs come from a function the
// test sets, outputs are kept as they were last written, and every call is counted (and
// logged, for tests of the scan order).
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "runtime/backend.hpp"

namespace plcfi::testing_support {

class FakeBackend final : public rt::IoBackend {
 public:
  // Bytes of %I and %Q the backend exchanges, from the start of each area.
  FakeBackend(uint32_t input_bytes, uint32_t output_bytes, std::string name = "fake")
      : outputs(output_bytes, 0), name_(std::move(name)), in_extent_(input_bytes) {}

  // Fills the input bytes at each read (the area is zeroed before); unset: all zero.
  std::function<void(uint8_t* inputs, int64_t now_ns)> on_read;
  // Makes read()/write() fail with this error while set (communication trouble).
  std::string fail_with;

  const std::string& name() const override { return name_; }
  uint32_t input_extent() const override { return in_extent_; }
  uint32_t output_extent() const override { return static_cast<uint32_t>(outputs.size()); }
  bool read(uint8_t* inputs, int64_t now_ns) override {
    ++reads;
    if (record_log) log += "read@" + std::to_string(now_ns / 1'000'000) + " ";
    if (!fail_with.empty()) return fail();
    if (in_extent_) std::memset(inputs, 0, in_extent_);
    if (on_read) on_read(inputs, now_ns);
    return true;
  }
  bool write(const uint8_t* out, int64_t, int64_t dt_ns) override {
    ++writes;
    if (record_log) log += "write ";
    if (!fail_with.empty()) return fail();
    if (!outputs.empty()) std::memcpy(outputs.data(), out, outputs.size());  // no %Q: out may be null
    last_dt = dt_ns;
    return true;
  }
  void reset(uint64_t seed) override {
    ++resets;
    last_seed = seed;
  }
  const std::string& last_error() const override { return error_; }

  // Little-endian helpers for the tests' scripts and checks.
  static void put_u16(uint8_t* p, uint16_t v) {
    p[0] = static_cast<uint8_t>(v & 0xff);
    p[1] = static_cast<uint8_t>(v >> 8);
  }
  int16_t output_i16(size_t byte) const { return static_cast<int16_t>(outputs[byte] | (outputs[byte + 1] << 8)); }

  std::vector<uint8_t> outputs;  // as last written
  bool record_log = false;
  std::string log;
  int64_t last_dt = 0;
  uint64_t last_seed = 0;
  int reads = 0, writes = 0, resets = 0;

 private:
  bool fail() {
    error_ = fail_with;
    return false;
  }
  std::string name_;
  uint32_t in_extent_;
  std::string error_;
};

}  // namespace plcfi::testing_support
