// Kinds shared by the syntax tree and the compiled program: what a POU is, which section
// a variable was declared in. The compiled program (vm/program.hpp) needs these and
// nothing else of the syntax tree.
#pragma once

namespace plcfi::st {

enum class PouKind { Program, FunctionBlock, Function, Method, Interface };
enum class Access { Public, Private, Protected, Internal };

enum class VarSection {
  Var,        // VAR
  Input,      // VAR_INPUT
  Output,     // VAR_OUTPUT
  InOut,      // VAR_IN_OUT
  Temp,       // VAR_TEMP
  Global,     // VAR_GLOBAL
  External,   // VAR_EXTERNAL
  Stat,       // VAR_STAT (CODESYS): one variable per POU, shared by its instances and calls
  Inst,       // VAR_INST (CODESYS): a METHOD's variable kept in its FB instance between calls
  Config,     // VAR_CONFIG (parsed, not used)
};

}  // namespace plcfi::st
