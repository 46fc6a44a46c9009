// Coverage exports: scan counts per arm (Machine::set_count_hits), their mapping onto
// decisions and lines, and the lcov and Cobertura texts, checked exactly on a small program.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "engine.hpp"
#include "report/coverage_export.hpp"
#include "vm/vm.hpp"

namespace plcfi::report {
namespace {

// Line numbers matter: the expectations below name them.
const char* kProgram = R"(PROGRAM Main
VAR x : INT; y : INT; i : INT; s : INT; mode : INT; t : TON; END_VAR
IF x = 0 THEN
  y := 1;
ELSIF x = 1 THEN
  y := 2;
ELSE
  y := 3;
END_IF;
CASE mode OF
  1: y := y + 10;
  2: y := y + 20;
END_CASE;
IF x > 5 THEN
  FOR i := 1 TO 3 DO
    s := s + i;
  END_FOR;
END_IF;
t(IN := x = 1, PT := T#1s);
END_PROGRAM
)";

// A generated unit (like a campaign's preconditions) with branches of its own.
const char* kGenerated = R"(PROGRAM Probe
VAR_OUTPUT seen : BOOL; END_VAR
IF Main.y > 0 THEN
  seen := TRUE;
END_IF;
END_PROGRAM
)";

struct Counted {
  std::unique_ptr<st::Build> b;
  std::unique_ptr<st::Machine> m;

  explicit Counted(bool count) {
    b = st::build_sources({{"cov.st", kProgram}}, st::CompileOptions{}, {st::GeneratedSource("<probe>", kGenerated)});
    if (!b->ok()) {
      ADD_FAILURE() << b->diags.render_all();
      return;
    }
    m = std::make_unique<st::Machine>(*b->app);
    m->set_count_hits(count);
  }
  void set(const char* path, int64_t v) {
    std::string err;
    auto h = st::resolve(*b->app, path, &err);
    ASSERT_TRUE(h) << err;
    st::write_int(*m, *h, v);
  }
  // One scan of every program and observer, as the runtime merges it.
  void scan(int64_t x, int64_t mode) {
    set("Main.x", x);
    set("Main.mode", mode);
    m->clear_taken();
    for (const auto* list : {&b->app->programs, &b->app->observers})
      for (const auto& p : *list) ASSERT_TRUE(m->call(p.pou->entry, p.addr)) << st::describe_trap(*b->app, m->trap());
    m->merge_coverage();
  }
  void run() {
    scan(0, 1);
    scan(1, 1);
    scan(0, 0);
    scan(0, 3);
  }
};

TEST(CoverageExport, CountsAreOffByDefault) {
  Counted c(false);
  ASSERT_TRUE(c.m);
  c.run();
  EXPECT_TRUE(c.m->hits().empty());
}

TEST(CoverageExport, OnlyTheProgramsOwnFilesAreReported) {
  Counted c(true);
  ASSERT_TRUE(c.m);
  const auto files = coverage_files(*c.b);
  ASSERT_EQ(1u, files.size());
  EXPECT_EQ("cov.st", c.b->app->file_paths[files[0]]);
  // The generated unit and the standard library (TON) have branch points, taken ones too.
  bool generated = false, library = false;
  for (size_t id = 0; id < c.b->app->branches.size(); ++id) {
    const std::string& path = c.b->app->file_paths[c.b->app->branches[id].loc.file];
    generated |= path == "<probe>";
    library |= path == "<stdlib>";
  }
  EXPECT_TRUE(generated);
  EXPECT_TRUE(library);
  c.run();
  const auto cov = coverage_by_file(*c.b->app, c.m->hits(), files);
  ASSERT_EQ(1u, cov.size());
  EXPECT_EQ(std::filesystem::absolute("cov.st").lexically_normal().string(), cov[0].path);
}

TEST(CoverageExport, LcovCountsScansPerArmAndLine) {
  Counted c(true);
  ASSERT_TRUE(c.m);
  c.run();
  const auto cov = coverage_by_file(*c.b->app, c.m->hits(), coverage_files(*c.b));
  const std::string path = std::filesystem::absolute("cov.st").lexically_normal().string();
  // IF/ELSIF/ELSE (complete): 3, 1, 0 scans. CASE without ELSE: labels 1 and 2 (no id for
  // "no label matched"). IF x > 5: evaluated, never TRUE: 0. The FOR inside it never ran: "-".
  EXPECT_EQ("TN:unit_test_1\n"
            "SF:" + path + "\n"
            "BRDA:3,0,0,3\nBRDA:3,0,1,1\nBRDA:3,0,2,0\n"
            "BRDA:10,0,0,2\nBRDA:10,0,1,0\n"
            "BRDA:14,0,0,0\n"
            "BRDA:15,0,0,-\n"
            "BRF:7\nBRH:3\n"
            "DA:3,3\nDA:4,3\nDA:5,1\nDA:6,1\nDA:7,0\nDA:8,0\n"
            "DA:10,2\nDA:11,2\nDA:12,0\n"
            "DA:14,0\nDA:15,0\nDA:16,0\n"
            "LF:12\nLH:6\n"
            "end_of_record\n",
            lcov_tracefile(cov, "unit-test 1"));
}

TEST(CoverageExport, AScanCountsOnceHoweverOftenTheArmRan) {
  Counted c(true);
  ASSERT_TRUE(c.m);
  c.scan(7, 0);  // FOR body: three iterations, one scan
  c.scan(7, 0);
  const auto cov = coverage_by_file(*c.b->app, c.m->hits(), coverage_files(*c.b));
  ASSERT_EQ(1u, cov.size());
  const std::string lcov = lcov_tracefile(cov, "t");
  EXPECT_NE(std::string::npos, lcov.find("BRDA:14,0,0,2\nBRDA:15,0,0,2\n")) << lcov;
  EXPECT_NE(std::string::npos, lcov.find("DA:16,2\n")) << lcov;
  // CASE without a matching label and no ELSE: not "-", the statement may have run.
  EXPECT_NE(std::string::npos, lcov.find("BRDA:10,0,0,0\nBRDA:10,0,1,0\n")) << lcov;
  // The IF with ELSE took its ELSE: its other arms count 0, not "-".
  EXPECT_NE(std::string::npos, lcov.find("BRDA:3,0,0,0\nBRDA:3,0,1,0\nBRDA:3,0,2,2\n")) << lcov;
}

TEST(CoverageExport, CoberturaTotalsRatesAndConditions) {
  Counted c(true);
  ASSERT_TRUE(c.m);
  c.run();
  const auto cov = coverage_by_file(*c.b->app, c.m->hits(), coverage_files(*c.b));
  const std::string xml = cobertura_xml(cov, 1700000000000);
  const std::string dir = std::filesystem::absolute("cov.st").lexically_normal().parent_path().string();
  EXPECT_NE(std::string::npos,
            xml.find("<coverage line-rate=\"0.5000\" branch-rate=\"0.4286\" lines-covered=\"6\" lines-valid=\"12\" "
                     "branches-covered=\"3\" branches-valid=\"7\" complexity=\"0\" version=\"plcfi\" timestamp=\"1700000000000\">"))
      << xml;
  EXPECT_NE(std::string::npos, xml.find("<source>" + dir + "</source>")) << xml;
  EXPECT_NE(std::string::npos, xml.find("<package name=\".\" line-rate=\"0.5000\" branch-rate=\"0.4286\" complexity=\"0\">")) << xml;
  EXPECT_NE(std::string::npos,
            xml.find("<class name=\"cov\" filename=\"cov.st\" line-rate=\"0.5000\" branch-rate=\"0.4286\" complexity=\"0\">"))
      << xml;
  EXPECT_NE(std::string::npos, xml.find("<line number=\"3\" hits=\"3\" branch=\"true\" condition-coverage=\"66% (2/3)\"/>")) << xml;
  EXPECT_NE(std::string::npos, xml.find("<line number=\"4\" hits=\"3\" branch=\"false\"/>")) << xml;
  EXPECT_NE(std::string::npos, xml.find("<line number=\"10\" hits=\"2\" branch=\"true\" condition-coverage=\"50% (1/2)\"/>")) << xml;
  EXPECT_NE(std::string::npos, xml.find("<line number=\"15\" hits=\"0\" branch=\"true\" condition-coverage=\"0% (0/1)\"/>")) << xml;
  EXPECT_EQ(std::string::npos, xml.find("probe")) << xml;
  EXPECT_EQ(std::string::npos, xml.find("stdlib")) << xml;
}

TEST(CoverageExport, UnwritablePathIsAnError) {
  std::string err;
  EXPECT_FALSE(write_coverage_file("/nonexistent-plcfi-dir/cov.info", "x", &err));
  EXPECT_EQ(0u, err.find("/nonexistent-plcfi-dir/cov.info: cannot write")) << err;
  const auto path = std::filesystem::temp_directory_path() / ("plcfi_cov_" + std::to_string(::getpid()) + ".info");
  ASSERT_TRUE(write_coverage_file(path.string(), "TN:x\n", &err)) << err;
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ("TN:x\n", ss.str());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace plcfi::report
