// Parser entry points: source text -> AST, reporting every syntax error it can find.
#pragma once

#include <memory>

#include "ast.hpp"
#include "diag.hpp"

namespace plcfi::st {

// Parses a program source file (POUs, TYPEs, VAR_GLOBAL, CONFIGURATION). Never throws;
// errors go to diags and the parser recovers at statement and END_* boundaries, so the
// result is always a (possibly partial) unit.
std::unique_ptr<CompilationUnit> parse_unit(const SourceManager& sm, uint32_t file, DiagEngine& diags);

// Parses a unit-test file (SETUP/TEARDOWN/TEST blocks, plus POUs and TYPEs of its own).
std::unique_ptr<TestFile> parse_test_file(const SourceManager& sm, uint32_t file, DiagEngine& diags);

// True when the file's first significant token is SETUP, TEARDOWN or TEST: lets the CLI
// accept sources and test files in any order on one command line.
bool is_test_file(const SourceManager& sm, uint32_t file);

// Parses a single expression (used by --set/--print paths, requirement formulas, asserts
// typed by the user). Trailing tokens are an error.
ExprPtr parse_expression(const SourceManager& sm, uint32_t file, DiagEngine& diags);

}  // namespace plcfi::st
