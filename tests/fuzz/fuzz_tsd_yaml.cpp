// Fuzz target: the campaign's tsd reader (load_tsd) on one file.
#include <cstdint>
#include <string>

#include "campaign/spec.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("tsd.yaml", fuzz::as_text(data, size));
  campaign::Tsd out;
  std::string err;
  (void)campaign::load_tsd(path, &out, &err);
  return 0;
}
