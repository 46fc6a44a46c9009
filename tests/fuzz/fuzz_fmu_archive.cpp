// Fuzz target: an .fmu archive (zip): unpacking with libzip, the entry-name checks, the
// modelDescription.xml inside, the search for the linux64 binary.
#include <cstdint>
#include <string>

#include "common/yaml.hpp"
#include "fuzz_support.hpp"
#include "plant_model/fmu/fmu.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const std::string path = fuzz::write_temp("plant.fmu", fuzz::as_text(data, size));
  try {
    auto fmu = plant::fmu::FmuArchive::open(path);
    (void)fmu->resource_uri();
  } catch (const common::InputError&) {
  }
  return 0;
}
