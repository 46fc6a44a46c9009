// The ST engine's front door: load, parse and compile files; resolve variable paths to
// typed handles; read and write values; disassemble; report branch coverage.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "codegen/compiler.hpp"
#include "syntax/ast.hpp"
#include "syntax/diag.hpp"
#include "vm/program.hpp"
#include "vm/vm.hpp"

namespace plcfi::st {

// Everything one compilation owns. Sources and test files may come in any order: a file
// whose first keyword is TEST, SETUP or TEARDOWN is a test file.
struct Build {
  SourceManager sm;
  DiagEngine diags{sm};
  std::vector<std::unique_ptr<CompilationUnit>> units;
  std::vector<std::unique_ptr<TestFile>> tests;
  std::vector<std::unique_ptr<CompilationUnit>> late;  // monitors
  std::unique_ptr<Application> app;
  std::vector<std::string> io_errors;  // files that could not be read
  std::vector<LibraryParam> library_params;  // set by the projects read (TwinCAT's library parameters)

  bool ok() const { return app != nullptr; }
};

using NamedSources = std::vector<std::pair<std::string, std::string>>;
// Generated ST (requirement monitors, preconditions) with, per line, where its text came
// from: diagnostics in it point into the user's files.
struct GeneratedSource {
  GeneratedSource(std::string n, std::string t, std::vector<LineOrigin> o = {})
      : name(std::move(n)), text(std::move(t)), origins(std::move(o)) {}
  std::string name, text;
  std::vector<LineOrigin> origins;
};
using GeneratedSources = std::vector<GeneratedSource>;
// Reads and compiles files. Returns the build; check ok(), diags and io_errors. `late`
// sources (requirement monitors) are then linked onto the program (link_generated).
std::unique_ptr<Build> build_files(const std::vector<std::string>& paths, const CompileOptions& opt,
                                   const GeneratedSources& late = {});
// Same from in-memory sources (name, text): tests, benchmarks, trace programs.
std::unique_ptr<Build> build_sources(const NamedSources& sources, const CompileOptions& opt, const GeneratedSources& late = {});
// Links generated ST (monitors, preconditions, probes) onto a build whose program
// compiled: the sources join the build's, and are compiled against the program's symbols
// (see link_units), not together with it. False, with the diagnostics in b.diags and the
// program as it was, when they do not compile.
bool link_generated(Build& b, const GeneratedSources& late, const CompileOptions& opt);

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

// Bytecode listing with source lines, one POU after another.
std::string disassemble(const Application& app, const Build* build = nullptr);

// Branch coverage per file: taken / total and the arms never taken (file:line).
std::string coverage_report(const Application& app, const std::vector<uint64_t>& covered);

// `file:line:col: runtime error[ST5nn]: message` for a trap.
std::string describe_trap(const Application& app, const Trap& t);
// The same without the location: `runtime error[ST5nn]: message` (for output that shows
// the location already).
std::string describe_trap_kind(const Trap& t);
const char* trap_code(TrapKind k);

}  // namespace plcfi::st
