// A script bound to a compiled program: every variable resolved to a typed location,
// every value parsed for its variable's type, every device checked, before anything
// runs. Errors point into the script (PATH:LINE:COL).
#pragma once

#include <string>
#include <vector>

#include "engine.hpp"
#include "script/cpt.hpp"

namespace plcfi::script {

// A value of a variable, comparable whatever the type: BOOL, integers, bit strings,
// enumerations and times as an integer (times in ns), REAL/LREAL as a double, strings in
// their ST text form.
struct Operand {
  enum class K : uint8_t { Int, Real, Str } k = K::Int;
  int64_t i = 0;
  double r = 0.0;
  std::string s;
};

struct BoundCommand {
  const Command* cmd = nullptr;
  st::VarHandle var;  // SET, RESET, ASSIGN, ASSERT*
  Operand value;      // ASSERT* with a comparison
};

struct BoundScript {
  const Script* script = nullptr;
  std::vector<BoundCommand> cmds;
  std::vector<std::string> var_paths;  // the variables the script names, each once, as written
};

// Binds s to the program of app. `devices`: the names FAULT LINK may use (offline:
// "plant"). False with "PATH:LINE:COL: message" in err.
bool bind_script(const st::Application& app, const Script& s, const std::vector<std::string>& devices, BoundScript* out,
                 std::string* err);

// The variable's current value as an Operand of its kind.
Operand read_operand(const st::Machine& m, const st::VarHandle& h);
// `value op expected` (ISTRUE/ISFALSE ignore expected).
bool compare(const Operand& value, CmpOp op, const Operand& expected);
// The ST text of an operand (TRUE, 42, 1.5, T#2s, 'abc'), for messages and logs.
std::string operand_text(const st::Machine& m, const st::VarHandle& h);

}  // namespace plcfi::script
