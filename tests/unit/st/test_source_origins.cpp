// Generated ST whose lines came from the user's files (monitors, preconditions): a
// diagnostic in a generated line is reported where the text came from, with the context,
// the user's line and caret; identical diagnostics are reported once.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "engine.hpp"

namespace plcfi::st {
namespace {

struct SpecFile {
  SpecFile() {
    path = (std::filesystem::temp_directory_path() / ("plcfi_origins_" + std::to_string(::getpid()) + ".yaml")).string();
    std::ofstream(path) << "requirements:\n  - id: R1\n    reaction: \"Main.ready AND Main.nothing\"\n";
  }
  ~SpecFile() { std::filesystem::remove(path); }
  std::string path;
};

const char* kProgram = "PROGRAM Main\nVAR ready : BOOL; END_VAR\nEND_PROGRAM\n";

// Line 3 of the generated program is `  r := Main.ready AND Main.nothing;`: the formula is
// copied at column 8 (7 columns of prefix) from column 16 of line 3 of the spec file, so
// 'nothing' (generated column 28) is at column 36 there.
const char* kGenerated = "PROGRAM Mon\nVAR r : BOOL; END_VAR\n  r := Main.ready AND Main.nothing;\nEND_PROGRAM\n";

LineOrigin formula_line(const std::string& path) {
  LineOrigin o;
  o.path = path;
  o.line = 3;
  o.col = 16;
  o.prefix = 7;
  o.context = "in requirement R1";
  return o;
}

TEST(SourceOrigins, ADiagnosticInGeneratedTextPointsIntoTheUsersFile) {
  SpecFile spec;
  std::vector<LineOrigin> origins(2);
  origins.push_back(formula_line(spec.path));
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{}, {{"<monitors>", kGenerated, origins}});
  ASSERT_FALSE(b->ok());
  ASSERT_EQ(b->diags.all().size(), 1u) << b->diags.render_all();
  EXPECT_EQ(b->diags.render_all(), spec.path + ":3:36: error[ST207]: 'Main' has no member 'nothing' (in requirement R1)\n"
                                               "      reaction: \"Main.ready AND Main.nothing\"\n"
                                               "                                     ^\n");
}

TEST(SourceOrigins, RewrittenTextMapsColumnsThroughTheMap) {
  SpecFile spec;
  LineOrigin o = formula_line(spec.path);
  // The copy is 'Main.ready AND Main.nothing' with 'AND' written '&' in the file: every
  // offset past the operator is two less in the user's text.
  for (uint32_t k = 0; k < 27; ++k) o.col_map.push_back(k < 14 ? k : k - 2);
  std::vector<LineOrigin> origins(2);
  origins.push_back(o);
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{}, {{"<monitors>", kGenerated, origins}});
  ASSERT_EQ(b->diags.all().size(), 1u);
  EXPECT_EQ(b->diags.all()[0].loc.line, 3u);
  EXPECT_EQ(b->diags.all()[0].loc.col, 34u);  // 'nothing' is 20 columns into the copy, 18 into the user's text
}

TEST(SourceOrigins, InexactColumnsPointAtTheCopysStart) {
  SpecFile spec;
  LineOrigin o = formula_line(spec.path);
  o.exact_columns = false;
  std::vector<LineOrigin> origins(2);
  origins.push_back(o);
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{}, {{"<monitors>", kGenerated, origins}});
  ASSERT_EQ(b->diags.all().size(), 1u);
  EXPECT_EQ(b->diags.all()[0].loc.col, 16u);
  EXPECT_EQ(b->sm.file(b->diags.all()[0].loc.file).path, spec.path);
}

TEST(SourceOrigins, AnUnreadableOriginLeavesTheGeneratedLocation) {
  LineOrigin o = formula_line("/nonexistent-dir/spec.yaml");
  std::vector<LineOrigin> origins(2);
  origins.push_back(o);
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{}, {{"<monitors>", kGenerated, origins}});
  ASSERT_EQ(b->diags.all().size(), 1u);
  EXPECT_EQ(b->sm.file(b->diags.all()[0].loc.file).path, "<monitors>");
  EXPECT_EQ(b->diags.all()[0].loc.line, 3u);
}

TEST(SourceOrigins, OneUserFormulaInstantiatedTwiceIsReportedOnce) {
  SpecFile spec;
  // Two generated lines (two test cases) copy the same formula: one message, counted once.
  std::string gen = "PROGRAM Mon\nVAR r : BOOL; END_VAR\n  r := Main.ready AND Main.nothing;\n  r := Main.ready AND Main.nothing;\nEND_PROGRAM\n";
  std::vector<LineOrigin> origins(2);
  origins.push_back(formula_line(spec.path));
  origins.push_back(formula_line(spec.path));
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{}, {{"<monitors>", gen, origins}});
  EXPECT_EQ(b->diags.all().size(), 1u) << b->diags.render_all();
  EXPECT_EQ(b->diags.error_count(), 1u);
}

TEST(DiagEngine, IdenticalDiagnosticsAreStoredAndCountedOnce) {
  SourceManager sm;
  uint32_t f = sm.add("a.st", "x\n");
  DiagEngine d(sm);
  d.error("ST200", SourceLoc{f, 1, 1}, "unknown identifier 'x'");
  d.error("ST200", SourceLoc{f, 1, 1}, "unknown identifier 'x'");
  d.error("ST200", SourceLoc{f, 1, 2}, "unknown identifier 'x'");  // another column: another diagnostic
  d.warning("ST300", SourceLoc{f, 1, 1}, "unused");
  EXPECT_EQ(d.all().size(), 3u);
  EXPECT_EQ(d.error_count(), 2u);
  EXPECT_EQ(d.warning_count(), 1u);
}

}  // namespace
}  // namespace plcfi::st
