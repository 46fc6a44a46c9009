// Fuzz target: the campaign's fault_classes reader (load_fault_classes) on one file.
#include <cstdint>
#include <string>

#include "campaign/spec.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("fault_classes.yaml", fuzz::as_text(data, size));
  campaign::FaultClasses out;
  std::string err;
  (void)campaign::load_fault_classes(path, &out, &err);
  return 0;
}
