// The trace readers' fuzz body, shared by the CSV and VCD targets: read the input in
// memory as `plcfi edtl check` reads a trace before compiling monitors, build the trace
// program of its columns, pull the states and check the reader's contract.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "monitor/trace_reader.hpp"

namespace plcfi::fuzz {

// States pulled per input: a resampled trace may hold many (#0, then #1000000000 with a
// 1 ns cycle); the reader is linear in them, the fuzzer needs speed.
constexpr int kMaxTraceStates = 10'000;

inline int fuzz_trace(const uint8_t* data, size_t size, monitor::TraceFormat format, const char* name) {
  if (size == 0) return 0;
  // The first byte picks the cycle: 0 (one state per time stamp / no time column) or 1..255 ns.
  int64_t cycle_ns = data[0];
  std::string err;
  auto reader = monitor::TraceReader::from_text(name, std::string(as_text(data + 1, size - 1)), format, cycle_ns, &err);
  if (!reader) {
    if (err.empty()) __builtin_trap();  // a failure always says why
    return 0;
  }
  std::string program;
  (void)monitor::trace_program(reader->columns(), &program, &err);
  int64_t t = 0, prev = INT64_MIN;
  std::vector<double> values;
  err.clear();
  for (int n = 0; n < kMaxTraceStates && reader->next(&t, &values, &err); ++n) {
    // The reader's contract: one value per column, time never going back.
    if (values.size() != reader->columns().size() || t < prev) __builtin_trap();
    prev = t;
  }
  return 0;
}

}  // namespace plcfi::fuzz
