// Fuzz target: the plant file reader (builtin, fmu or st; step, parameters, map, scale).
// Plants named by an accepted file are not opened: the FMU and ST loaders have targets of
// their own (fmu_archive, fmu_model_description, st_frontend).
#include <cstdint>
#include <string>

#include "common/yaml.hpp"
#include "fuzz_support.hpp"
#include "plant_model/plant_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const std::string path = fuzz::write_temp("plant.yaml", fuzz::as_text(data, size));
  try {
    auto pf = plant::read_plant_file(path);
    for (const auto& m : pf.map)
      if (m.scale) (void)m.scale->to_plant(m.scale->to_image(1.0));
  } catch (const common::InputError&) {
  } catch (const YAML::Exception&) {
  }
  return 0;
}
