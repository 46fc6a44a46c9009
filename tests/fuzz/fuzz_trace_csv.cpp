// Fuzz target: the CSV trace reader (in memory), its states and the trace program of
// its columns (tests/fuzz/fuzz_trace.hpp).
#include "fuzz_trace.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return plcfi::fuzz::fuzz_trace(data, size, plcfi::monitor::TraceFormat::Csv, "fuzz.csv");
}
