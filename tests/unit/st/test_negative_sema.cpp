// One test per tests/negative/sema_*.st: the file parses cleanly, fails semantic checking, and reports every `expect: ST2nn @ LINE` it lists.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "engine.hpp"

namespace plcfi::st {
namespace {

std::vector<std::string> sema_files() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(PLCFI_NEGATIVE_DIR, ec)) {
    std::string name = e.path().filename().string();
    if (name.rfind("sema_", 0) == 0 && e.path().extension() == ".st") out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

class NegativeSema : public ::testing::TestWithParam<std::string> {};

TEST_P(NegativeSema, ReportsEveryExpectedSemanticError) {
  const std::string& path = GetParam();
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  static const std::regex expect_re(R"(expect:\s*(ST\d+)\s*@\s*(\d+))");
  std::vector<std::pair<std::string, uint32_t>> expected;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), expect_re); it != std::sregex_iterator(); ++it)
    expected.emplace_back((*it)[1].str(), static_cast<uint32_t>(std::stoul((*it)[2].str())));
  ASSERT_FALSE(expected.empty()) << "no `// expect: STnnn @ LINE` line";

  CompileOptions opt;
  opt.test_mode = false;
  auto b = build_files({path}, opt);
  ASSERT_TRUE(b->io_errors.empty());
  const std::string rendered = b->diags.render_all();
  EXPECT_FALSE(b->ok()) << "compiled although it is invalid";
  for (const auto& d : b->diags.all())
    EXPECT_FALSE(d.code.size() == 5 && (d.code[2] == '0' || d.code[2] == '1'))
        << "a semantic test file must parse cleanly; got " << d.code << ":\n" << rendered;
  for (const auto& [code, line] : expected) {
    EXPECT_EQ('2', code[2]) << code << " is not a semantic error code";
    bool found = std::any_of(b->diags.all().begin(), b->diags.all().end(), [&, c = code, l = line](const Diagnostic& d) {
      return d.code == c && d.loc.line == l && d.severity == Severity::Error;
    });
    EXPECT_TRUE(found) << "missing " << code << " @ " << line << "; reported:\n" << rendered;
  }
}

INSTANTIATE_TEST_SUITE_P(Files, NegativeSema, ::testing::ValuesIn(sema_files()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return stem(i.param); });

TEST(NegativeSemaSuite, HasAtLeastTwentyFiles) { EXPECT_GE(sema_files().size(), 20u); }

}  // namespace
}  // namespace plcfi::st
