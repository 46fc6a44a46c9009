// Opens the plant a command or a campaign names: a built-in model by name ("stamping") or a
// plant file ("conveyor.yaml": a built-in model, an FMU or an ST program, with its map).
#pragma once

#include <memory>
#include <string>

#include "plant_model/plant.hpp"

namespace plcfi::io {

// `config_path`: the parameter file of a built-in plant named directly (may be empty; a
// plant file names its own). Returns null and fills *err (file:line:col where there is one)
// when the plant cannot be opened: an unknown name, a bad plant file, an FMU that does not
// load or initialize, an ST plant that does not compile.
std::unique_ptr<plant::Plant> open_plant(const std::string& name_or_file, const std::string& config_path,
                                         std::string* err);

}  // namespace plcfi::io
