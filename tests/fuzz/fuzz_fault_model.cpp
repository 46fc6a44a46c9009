// Fuzz target: the fault-model parser (stuck_at(1), drift(100/s), delayed(T#200ms), ...).
#include <cstdint>
#include <string>

#include "faults/fault_model.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  faults::FaultSpec spec;
  std::string err;
  uint32_t col = 0;
  std::string text(fuzz::as_text(data, size));
  if (!faults::parse_fault(text, &spec, &err, &col) && col > text.size()) {
    // The column locates the error in the text: one past the end at most.
    __builtin_trap();
  }
  return 0;
}
