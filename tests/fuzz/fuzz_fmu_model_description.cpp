// Fuzz target: the reader of an FMU's modelDescription.xml (in memory).
#include <cstdint>
#include <string>

#include "common/yaml.hpp"
#include "fuzz_support.hpp"
#include "plant_model/fmu/model_description.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  try {
    auto md = plant::fmu::parse_model_description(std::string(fuzz::as_text(data, size)), "fuzz.fmu/modelDescription.xml");
    (void)md.find("x");
  } catch (const common::InputError&) {
  }
  return 0;
}
