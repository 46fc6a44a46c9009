// Fuzz target: the stamping plant's parameter file reader (load_stamping_params).
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "plant_model/stamping/stamping_params.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("stamping.yaml", fuzz::as_text(data, size));
  plant::StampingParams params;
  std::string err;
  (void)plant::load_stamping_params(path, &params, &err);
  return 0;
}
