// Parts shared by the campaign spec loaders (campaign file, TSD, FMEA CSV, fault
// classes): one .cpp per file format, errors as common::InputError "FILE:LINE:COL: ...".
#pragma once

#include <string>

#include "campaign/spec.hpp"
#include "common/yaml.hpp"

namespace plcfi::campaign::detail {

// Where a node is, as a spec location.
Loc loc_of(const common::YamlDoc& doc, const YAML::Node& n);
// An ST expression of a spec with the position of its first character.
monitor::FormulaSource formula(const common::YamlDoc& doc, const YAML::Node& n, const std::string& what);
// An IEC identifier: a letter or '_', then letters, digits and '_'.
bool valid_name(const std::string& s);

// The loaders proper; they throw common::InputError.
void parse_tsd(const common::YamlDoc& f, Tsd* out);
void parse_fmea(const std::string& path, Fmea* out);
void parse_classes(const common::YamlDoc& f, FaultClasses* out);

}  // namespace plcfi::campaign::detail
