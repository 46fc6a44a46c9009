// Building an application: files and in-memory sources are read, parsed and compiled
// with the standard library (and the vendor libraries they use); generated ST (monitors,
// preconditions) is linked onto a compiled program. Part of the engine's front door
// (engine.hpp).
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

}  // namespace plcfi::st
