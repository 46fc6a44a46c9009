// JSON for the commands' --json output: the project's one JSON library (common/json.hpp).
#pragma once

#include "common/json.hpp"

namespace plcfi::cli {

using common::Json;
using common::json_line;

}  // namespace plcfi::cli
