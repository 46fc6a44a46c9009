// The CPTest+ test-script language (.cpt): one command a line, read into a Script.
//
//   [NN:] SET var | RESET var | ASSIGN var value
//   [NN:] WAIT n MS | S | C              (C: n cycles of the program's task)
//   [NN:] LOG text
//   [NN:] ASSERT op var [value]          op: EQ NEQ LT LTE GT GTE ISTRUE ISFALSE
//   [NN:] ASSERT_COM op var [value]
//   [NN:] FAULT LINK device FOR n MS | S  (a broken link to a device, for a while)
//
// Keywords in any case; `//` starts a comment (except in LOG text, which is the rest of
// the line as written); blank lines are allowed. A value is an ST literal (TRUE, 42, 1.5,
// T#2s, 'text', an enumeration value) checked against the variable's type when the
// script is bound to a program (script/bind.hpp), not here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace plcfi::script {

enum class CmdKind : uint8_t { Set, Reset, Assign, Wait, Log, Assert, AssertCom, FaultLink };
enum class CmpOp : uint8_t { Eq, Neq, Lt, Lte, Gt, Gte, IsTrue, IsFalse };
enum class WaitUnit : uint8_t { Ms, S, Cycles };

struct Pos {
  uint32_t line = 0, col = 0;  // 1-based
};

struct Command {
  CmdKind kind = CmdKind::Log;
  Pos at;                 // the command word
  std::string number;     // the optional line number as written ("01"), else empty
  std::string text;       // the line as written, without its number and comment
  std::string var;        // SET, RESET, ASSIGN, ASSERT*
  Pos var_at;
  CmpOp op = CmpOp::Eq;   // ASSERT*
  bool has_value = false;
  std::string value;      // ASSIGN, ASSERT* with a comparison
  Pos value_at;
  int64_t amount = 0;     // WAIT, FAULT LINK: the number
  WaitUnit unit = WaitUnit::Ms;
  std::string device;     // FAULT LINK
  Pos device_at;
  std::string message;    // LOG
};

struct Script {
  std::string path;  // as given
  std::string name;  // the file name without directory and .cpt: the test's name
  std::vector<Command> commands;
};

// Parses a script's text. False with "PATH:LINE:COL: message" in err at the first error.
bool parse_script(const std::string& path, const std::string& text, Script* out, std::string* err);
// Reads (size-limited) and parses a script file.
bool load_script(const std::string& path, Script* out, std::string* err);

const char* op_name(CmpOp op);          // "EQ", ...
bool op_takes_value(CmpOp op);          // all but ISTRUE, ISFALSE
const char* unit_name(WaitUnit u);      // "MS", "S", "C"
// Nanoseconds of `amount` MS or S; -1 when it does not fit.
int64_t duration_ns(int64_t amount, WaitUnit u);

}  // namespace plcfi::script
