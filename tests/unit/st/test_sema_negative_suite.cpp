// Semantic negative suite: each tests/negative/sema_*.st must fail to compile with every
// diagnostic its `expect: STnnn @ LINE` comments name (code and line).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "engine.hpp"

namespace plcfi::st {
namespace {

TEST(SemaNegativeSuite, EveryFileReportsItsExpectedDiagnostics) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(PLCFI_NEGATIVE_DIR))
    if (e.path().filename().string().rfind("sema_", 0) == 0 && e.path().extension() == ".st") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 30u);
  const std::regex expect_re(R"(expect:\s*(ST\d+)\s*@\s*(\d+))");
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    std::ifstream in(f);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    std::vector<std::pair<std::string, uint32_t>> expected;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), expect_re); it != std::sregex_iterator(); ++it)
      expected.emplace_back((*it)[1].str(), static_cast<uint32_t>(std::stoul((*it)[2].str())));
    ASSERT_FALSE(expected.empty()) << "no expect: comment";
    auto b = build_files({f.string()}, CompileOptions{});
    EXPECT_FALSE(b->ok()) << "compiled although it is invalid";
    std::string rendered = b->diags.render_all();
    for (const auto& [code, line] : expected) {
      bool found = false;
      for (const auto& d : b->diags.all())
        if (d.code == code && d.loc.line == line && d.severity == Severity::Error) found = true;
      EXPECT_TRUE(found) << "missing " << code << " at line " << line << "; reported:\n" << rendered;
    }
  }
}

}  // namespace
}  // namespace plcfi::st
