// Fuzz target: the plant parameter file readers (load_stamping_params, load_bead_params),
// both on every input.
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "plant_model/bead_dispenser/bead_dispenser.hpp"
#include "plant_model/stamping/stamping_params.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("stamping.yaml", fuzz::as_text(data, size));
  plant::StampingParams params;
  std::string err;
  (void)plant::load_stamping_params(path, &params, &err);
  plant::BeadParams bead;
  (void)plant::load_bead_params(path, &bead, &err);
  return 0;
}
