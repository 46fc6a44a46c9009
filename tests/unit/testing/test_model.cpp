// The test model's filter, totals and reports (testing/, report/tests).
#include <gtest/gtest.h>

#include <sstream>

#include "report/tests.hpp"
#include "testing/filter.hpp"

namespace plcfi {
namespace {

TEST(TestFilter, MatchesSuiteTestOrBoth) {
  const ::plcfi::testing::Filter none;
  EXPECT_TRUE(none.selects("PRG_TEST.fbSum", "OnePlusOne"));
  const ::plcfi::testing::Filter f({"*Array*", "PRG_TEST.fbBlink", "tests/a.st/exact name"});
  EXPECT_TRUE(f.selects("PRG_TEST.fbSum", "ArraysDiffer"));        // the test's name
  EXPECT_TRUE(f.selects("PRG_TEST.fbBlink", "Anything"));          // the suite's
  EXPECT_TRUE(f.selects("tests/a.st", "exact name"));              // SUITE/TEST
  EXPECT_FALSE(f.selects("tests/a.st", "exact name too"));
  EXPECT_FALSE(f.selects("PRG_TEST.fbSum", "OnePlusOne"));
  const ::plcfi::testing::Filter g({"PRG_TEST.fbBlink/*"});
  EXPECT_TRUE(g.names_suite("PRG_TEST.fbBlink"));
  EXPECT_FALSE(g.names_suite("PRG_TEST.fbSum"));
  EXPECT_FALSE(f.names_suite("PRG_TEST.fbSum"));  // *Array* names tests, not this suite
  EXPECT_TRUE(f.names_suite("tests/a.st"));
}

TEST(TestReport, TotalsDurationsAndListing) {
  ::plcfi::testing::TestSuite s;
  s.name = "suite";
  ::plcfi::testing::TestCase pass, fail, off;
  pass.name = "p";
  pass.seconds = 0.02;
  fail.name = "f";
  fail.verdict = ::plcfi::testing::Verdict::Fail;
  fail.findings = {{"a.st:3:1", "expected 1, actual 2"}, {"", "second"}};
  fail.seconds = 1.5;
  off.name = "d";
  off.verdict = ::plcfi::testing::Verdict::Disabled;
  s.cases = {pass, fail, off};
  const auto t = ::plcfi::testing::totals({s});
  EXPECT_EQ(t.passed, 1u);
  EXPECT_EQ(t.failed, 1u);
  EXPECT_EQ(t.disabled, 1u);
  EXPECT_EQ(report::totals_line(t), "1 passed, 1 failed, 1 disabled");
  EXPECT_EQ(report::test_duration(0), "0s");
  EXPECT_EQ(report::test_duration(1.5), "1s500ms");
  EXPECT_EQ(report::test_duration(3725.000001), "1h2m5s1us");
  std::ostringstream out;
  report::print_tests(out, {s});
  EXPECT_EQ(out.str(),
            "[suite]\n  PASS: p (20ms)\n  FAIL: f (1s500ms)\n    a.st:3:1: expected 1, actual 2\n    second\n  DISABLED: d\n");
  const auto junit = report::junit_suites({s});
  ASSERT_EQ(junit.size(), 1u);
  EXPECT_EQ(junit[0].cases[1].message, "a.st:3:1: expected 1, actual 2");
  EXPECT_EQ(junit[0].cases[2].outcome, report::JunitCase::Outcome::Skipped);
  const std::string x = report::tcunit_xunit_xml({s}, 2.0);
  EXPECT_NE(x.find("<testsuites disabled=\"\" failures=\"1\" tests=\"2\" time=\"2.0\">"), std::string::npos) << x;
  EXPECT_NE(x.find("<testcase name=\"d\" classname=\"suite\" time=\"0.0\" status=\"SKIP\">"), std::string::npos) << x;
}

}  // namespace
}  // namespace plcfi
