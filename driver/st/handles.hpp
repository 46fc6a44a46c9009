// Variable handles: a path (`Main.seq.step`, `GVL.x`, `%IX0.3`) resolved once to a typed
// location, then read and written in O(1), as numbers or as ST text. Part of the engine's
// front door (engine.hpp).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vm/program.hpp"
#include "vm/vm.hpp"

namespace plcfi::st {

// A variable resolved once from its path (`Main.seq.step`, `GVL.x`, `x`, `%IX0.3`,
// `Main.buf[3].v`, `Main.w.2`) to a typed location; reads and writes are O(1).
struct VarHandle {
  std::string path;
  const Type* type = nullptr;
  uint32_t addr = 0;
  uint8_t bit = 0;
  bool is_bit = false;  // a single bit of a byte (located BOOL, bit access)
};
std::optional<VarHandle> resolve(const Application& app, std::string_view path, std::string* err);

// Elementary access. Values convert like an assignment would (a BOOL reads 0/1).
bool read_bool(const Machine& m, const VarHandle& h);
int64_t read_int(const Machine& m, const VarHandle& h);     // integers, enums, TIME (ns), bits
double read_real(const Machine& m, const VarHandle& h);      // any number
void write_bool(Machine& m, const VarHandle& h, bool v);
void write_int(Machine& m, const VarHandle& h, int64_t v);   // wraps to the type's width
void write_real(Machine& m, const VarHandle& h, double v);
// Text form as ST would write it (TRUE, 42, 1.5, T#1s500ms, 'abc', Red, ...).
std::string format(const Machine& m, const VarHandle& h);
// Parses an ST literal (or an enumeration value name) and writes it.
bool write_text(Machine& m, const VarHandle& h, std::string_view text, std::string* err);

}  // namespace plcfi::st
