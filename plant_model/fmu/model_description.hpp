// modelDescription.xml of an FMI 2.0 co-simulation FMU: what plcfi needs of it (identity,
// the co-simulation capabilities, the default experiment and the scalar variables).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace plcfi::plant::fmu {

enum class VarType : uint8_t { Real, Integer, Boolean, String, Enumeration };
enum class Causality : uint8_t { Parameter, CalculatedParameter, Input, Output, Local, Independent };
enum class Variability : uint8_t { Constant, Fixed, Tunable, Discrete, Continuous };

const char* type_name(VarType t);
const char* causality_name(Causality c);

struct ScalarVariable {
  std::string name;
  uint32_t value_reference = 0;
  std::string description;
  Causality causality = Causality::Local;
  Variability variability = Variability::Continuous;
  VarType type = VarType::Real;
  std::optional<std::string> start;  // as written in the file
  uint32_t line = 0, col = 0;        // of the ScalarVariable element
};

struct ModelDescription {
  std::string fmi_version;
  std::string model_name;
  std::string guid;
  std::string description;
  std::string generation_tool;
  // CoSimulation element
  std::string model_identifier;
  bool can_handle_variable_step = false;
  bool can_interpolate_inputs = false;
  bool needs_execution_tool = false;
  // DefaultExperiment (absent: nullopt)
  std::optional<double> default_start, default_stop, default_step;
  std::vector<ScalarVariable> variables;

  // The variable of this name, or null.
  const ScalarVariable* find(const std::string& name) const;
};

// Parses the text of a modelDescription.xml. `where` names the file in messages (e.g.
// "tank.fmu/modelDescription.xml"). Throws common::InputError with "WHERE:LINE:COL: message"
// for an XML syntax error, a wrong FMI version, a missing CoSimulation element, a bad or
// duplicate variable, ... A ModelExchange-only or FMI 1.0/3.0 description is an error
// that says so.
ModelDescription parse_model_description(const std::string& text, const std::string& where);

}  // namespace plcfi::plant::fmu
