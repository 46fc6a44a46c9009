// Fuzz target: the campaign's fmea reader (load_fmea) on one file.
#include <cstdint>
#include <string>

#include "campaign/spec.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("fmea.csv", fuzz::as_text(data, size));
  campaign::Fmea out;
  std::string err;
  (void)campaign::load_fmea(path, &out, &err);
  return 0;
}
