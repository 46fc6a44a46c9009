// The ST compiler: parsed units -> checked, laid-out and compiled Application.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "syntax/ast.hpp"
#include "syntax/diag.hpp"
#include "vm/program.hpp"

namespace plcfi::st {

// Which tools' ST the front end accepts. Iec: IEC 61131-3 (3rd edition) as written.
// Codesys: what CODESYS and TwinCAT 3 accept besides, chiefly implicit conversions between
// elementary types (each one a warning naming the conversion; `strict` makes them errors).
enum class Dialect : uint8_t { Iec, Codesys };
const char* dialect_name(Dialect d);
// "iec" or "codesys" (any case); false for anything else.
bool parse_dialect(std::string_view text, Dialect* out);

struct CompileOptions {
  Dialect dialect = Dialect::Iec;
  bool strict = false;  // the dialect's implicit conversions are errors, not warnings
  // Test builds: FBs count their calls and can be mocked, functions can be mocked,
  // the ASSERT_*/ADVANCE_TIME/MOCK_* built-ins are available.
  bool test_mode = false;
  bool warnings = true;
  // FOR loops set the row offsets of rank-2 accesses once per entry (ROWS, LDXR/STXR);
  // off, each access computes its whole offset (tests compare the two).
  bool row_offsets = true;
  // Every branch arm marks its bit of the branch coverage as it is entered (COV). Off, the
  // arms are still numbered (Application::branches) but mark nothing: for runs that report
  // no coverage (`plcfi run` without --coverage), which then spend nothing on it.
  bool coverage = true;
  // An IF or CASE that ends a loop body ends its arms with a copy of the loop's bottom
  // (LOOPUP, the WHILE or UNTIL test) instead of a jump to it (see loop_tail_), one that
  // only a few short assignments follow with a copy of them and the bottom (see stmts);
  // off, with the jump (tests compare the two; mutation analysis patches one store per
  // assignment).
  bool loop_tails = true;
  // An IF, WHILE or REPEAT condition that is an AND or OR of terms, whose later terms only
  // read variables and cannot fail, is a chain of conditional jumps (see cond_branch);
  // off, one value and one jump on it (mutation analysis patches that jump).
  bool condition_jumps = true;
  // An IF whose condition tests bits (an element of a BOOL array, a bit of a word, (x AND
  // mask) or x MOD 2^k compared with 0) and whose arms assign one variable values that only read
  // variables and cannot fail is one select instruction, without a jump (see select_if);
  // only without coverage (the arms mark nothing then). Off, jumps (mutation analysis
  // negates the IF's one jump; the native tier leaves the choice to the C compiler).
  bool if_selects = true;
  // An ELSIF condition that reads the array element the condition before it compared
  // reads the value that comparison loaded, without loading it again (see if_stmt); off,
  // it loads it (mutation analysis patches one condition at a time).
  bool elsif_reuse = true;
  // With loop_tails (off for mutation analysis): an arm that ends a WHILE body whose
  // condition is a BOOL variable, on a path that cannot have written it, jumps back
  // without testing it (see while_stmt); off, it tests it (tests compare the two).
  bool flag_loops = true;
  // With loop_tails, and without coverage: in the IF that ends a loop body, an arm that
  // leaves the loop (EXIT, RETURN, or a literal assigned to a variable the WHILE or UNTIL
  // condition reads) is placed after the other arms, so the passes that go on through the
  // loop do not jump over it (see if_stmt); off, the arms stay in source order.
  bool cold_arms = true;
  uint32_t image_size_i = 4096, image_size_q = 4096, image_size_m = 16384;
  // The source files of libraries (--library; see library_sources in import/import.hpp),
  // read by build_files before the program's own and compiled with them as library code.
  std::vector<std::string> library_files;
  // TcUnit's parameters set on the command line (--tcunit-param KEY=VALUE), after the
  // project's own: checked with tcunit_param_error before.
  std::vector<std::pair<std::string, std::string>> tcunit_params;
};

// Compiles the units (and test files) together with the standard library. Returns null
// when any error was reported; diagnostics are in diags either way.
std::unique_ptr<Application> compile(const SourceManager& sm, const std::vector<const CompilationUnit*>& units,
                                     const std::vector<const TestFile*>& tests, DiagEngine& diags,
                                     const CompileOptions& options);

// Links a second compilation unit (requirement monitors, preconditions, probes) onto a
// program compiled before, against that program's own symbol table: the units' POUs may
// call its POUs, use its types and globals, and name its program instances' variables
// by path (Main.step); each of their PROGRAMs gets one instance in
// Application::observers (run by no task). The program's syntax tree is not needed.
// `sm` holds the program's files and then the units' (file indices continue). Returns
// false, with the program as it was, when any error was reported.
bool link_units(Application& app, const SourceManager& sm, const std::vector<const CompilationUnit*>& units,
                DiagEngine& diags, const CompileOptions& options);

// The standard library's ST source (standard FBs) for a dialect, compiled with every
// application.
const char* stdlib_source(Dialect d);
// The TcUnit framework's ST source (FB_TestSuite, RUN), compiled with an application whose
// sources use it (stdlib/tcunit.cpp).
const char* tcunit_source();
// A library parameter a project sets (TwinCAT's library manager writes them into the
// .plcproj): list and key as written (TwinCAT upper-cases them), the value's text, and
// where the setting is.
struct LibraryParam {
  std::string list, key, value;
  SourceLoc loc;
};

// TcUnit's parameter list GVL_Param_TcUnit (loaded as "<TcUnit>/GVL_Param_TcUnit", whose
// stem is the list's name): TcUnit's defaults, or the values given by key (any case, as a
// project's <Parameters> or --tcunit-param set them). Check each one first with
// tcunit_param_error.
std::string tcunit_params_source(const std::vector<std::pair<std::string, std::string>>& values = {});
// Why TcUnit's parameter `key` cannot take `value` ("" when it can).
std::string tcunit_param_error(const std::string& key, const std::string& value);
// FB_ASSERT (the assertion-FB style of TwinCAT unit tests), compiled with an application
// whose sources use it (stdlib/tcunit.cpp).
const char* fb_assert_source();
// A data type of Beckhoff's Tc2 libraries (T_MaxString, TIMESTRUCT, ...) and its ST
// declaration (stdlib/tc2.cpp).
struct Tc2Type {
  const char* name;
  const char* source;
};
const std::vector<Tc2Type>& tc2_types();
// What of Beckhoff's Tc2_System plcfi provides in ST: the ADSLOG constants,
// MAX_STRING_LENGTH, PVOID, BIT, GETCURTASKINDEX, GETCPUCOUNTER, F_GetCpuCounterAs64bit
// (stdlib/tc2_system.cpp), each item loaded as the Tc2 types are. MEMCPY, ADSLOGSTR and
// the other functions on memory and the log are built-ins (sema/stdfuncs.cpp).
struct Tc2Item {
  const char* name;
  const char* source;
  const char* needs;  // another item the source uses, or nullptr
};
const std::vector<Tc2Item>& tc2_system_items();
// The vendor library a name belongs to when plcfi does not provide it ("FB_FileOpen" ->
// "Tc2_System"), for the message that says so; nullptr for any other name.
const char* unprovided_library(std::string_view name);
// The location a TcUnit assertion's hidden input _tcuAt holds (codegen/tcunit.cpp).
SourceLoc unpack_location(int64_t packed);
// The libraries plcfi brings, loaded under these names: no warnings, mocks, coverage or
// listing of their own. (Other sources in memory have names in angle brackets too.)
inline bool is_library_path(const std::string& path) {
  return path == "<stdlib>" || path == "<TcUnit>" || path == "<TcUnit>/GVL_Param_TcUnit" || path == "<FB_ASSERT>" ||
         path == "<Tc2>" || path == "<Tc2_System>";
}

}  // namespace plcfi::st
