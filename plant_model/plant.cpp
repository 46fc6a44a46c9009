// Plant factory: maps a plant name and an optional parameter file to a plant model.
#include "plant_model/plant.hpp"

#include "plant_model/bead_dispenser/bead_dispenser.hpp"
#include "plant_model/stamping/stamping_plant.hpp"

namespace plcfi::plant {

std::unique_ptr<Plant> make_builtin_plant(const std::string& name, const std::string& config_path, std::string* err) {
  if (name == "stamping") {
    StampingParams params;
    if (!config_path.empty() && !load_stamping_params(config_path, &params, err)) return nullptr;
    return std::make_unique<StampingPlant>(std::move(params));
  }
  if (name == "bead_dispenser") {
    BeadParams params;
    if (!config_path.empty() && !load_bead_params(config_path, &params, err)) return nullptr;
    return std::make_unique<BeadDispenserPlant>(params);
  }
  if (err) {
    std::string known;
    for (const auto& n : builtin_plant_names()) known += (known.empty() ? "" : ", ") + n;
    *err = "unknown plant '" + name + "' (known: " + known + ")";
  }
  return nullptr;
}

std::vector<std::string> builtin_plant_names() { return {"stamping", "bead_dispenser"}; }

}  // namespace plcfi::plant
