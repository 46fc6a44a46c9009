// The ST compiler: parsed units -> checked, laid-out and compiled Application.
#pragma once

#include <memory>
#include <vector>

#include "syntax/ast.hpp"
#include "syntax/diag.hpp"
#include "vm/program.hpp"

namespace plcfi::st {

struct CompileOptions {
  // Test builds: FBs count their calls and can be mocked, functions can be mocked,
  // the ASSERT_*/ADVANCE_TIME/MOCK_* built-ins are available.
  bool test_mode = false;
  bool warnings = true;
  uint32_t image_size_i = 4096, image_size_q = 4096, image_size_m = 16384;
};

// Compiles the units (and test files) together with the standard library. Returns null
// when any error was reported; diagnostics are in diags either way.
// `late` units (requirement monitors) are compiled after the program instances exist:
// inside them a path like Main.step names that instance's variable, and each of their
// PROGRAMs gets one instance in Application::observers (not run by any task).
std::unique_ptr<Application> compile(const SourceManager& sm, const std::vector<const CompilationUnit*>& units,
                                     const std::vector<const TestFile*>& tests, DiagEngine& diags,
                                     const CompileOptions& options,
                                     const std::vector<const CompilationUnit*>& late = {});

// The standard library's ST source (standard FBs), compiled with every application.
const char* stdlib_source();

}  // namespace plcfi::st
