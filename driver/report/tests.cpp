#include "tests.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "common/duration.hpp"

namespace plcfi::report {

namespace {

std::string property(const std::vector<std::pair<std::string, std::string>>& props, const char* key) {
  for (const auto& [k, v] : props)
    if (k == key) return v;
  return "";
}


// TcUnit's extended results (LogExtendedResults), as its log has them after a suite ended.
void print_tcunit_extended(std::ostream& out, const testing::TcUnitReport& rep) {
  for (size_t i = 0; i < rep.suites.size(); ++i) {
    const auto& s = rep.suites[i];
    if (s.tests.empty() && s.filtered > 0) continue;  // --filter selected none of its tests
    size_t failed = 0;
    for (const auto& t : s.tests) failed += t.failed;
    out << fmt::format("| Test suite ID={} '{}'\n| ID={} number of tests={}, number of failed tests={}, duration={}\n", i,
                             s.path, i, s.tests.size(), failed, tcunit_seconds(s.seconds));
    for (const auto& t : s.tests) {
      out << "| Test name=" << t.name << "\n| Test class name=" << s.path << "\n"
                << fmt::format("| Test status={}, number of asserts={}, duration={}\n",
                               t.disabled ? "SKIP" : t.failed ? "FAIL" : "PASS", t.asserts, tcunit_seconds(t.seconds));
      if (!t.message.empty()) out << "| Test assert message=" << t.message << "\n";
      if (!t.type.empty()) out << "| Test assert type=" << t.type << "\n";
    }
  }
}

const char* word(testing::Verdict v) {
  switch (v) {
    case testing::Verdict::Pass: return "PASS";
    case testing::Verdict::Fail: return "FAIL";
    case testing::Verdict::Disabled: return "DISABLED";
    case testing::Verdict::Undecidable: return "UNDECIDABLE";
  }
  return "?";
}

}  // namespace

std::string tcunit_seconds(double s) {
  std::string t = fmt::format("{}", s);
  if (t.find_first_of(".eni") == std::string::npos) t += ".0";
  return t;
}

// What TcUnit prints besides the tests: its own messages and the program's (TCUNIT_ADSLOGSTR,
// ADSLOGSTR) in order (the failed assertions are shown with their tests), its errors, the
// extended results when asked, its summary. Returns false when TcUnit reported an error of
// its own (a name used twice, more tests or assertions than the parameters allow, stopped).
bool print_tcunit_summary(std::ostream& out, const testing::TcUnitReport& rep, bool extended) {
  constexpr size_t kShown = 200;  // a message logged in every cycle of a long run
  size_t shown = 0, more = 0;
  for (const auto& l : rep.log) {
    if (l.text.rfind("FAILED TEST '", 0) == 0) continue;
    if (shown == kShown) {
      ++more;
      continue;
    }
    if (shown++ == 0) out << "TcUnit log:\n";
    out << "  " << l.level << ": " << l.text << "\n";
  }
  if (more) out << "  (" << more << " more messages not shown)\n";
  bool ok = rep.own_errors == 0;
  for (const auto& s : rep.suites)
    if (s.registered > rep.max_tests) {
      ok = false;
      out << fmt::format("Tests failed because the number of tests ({}) in the test suite '{}' are more than is defined "
                               "in parameter 'GVL_Param_TcUnit.MaxNumberOfTestsForEachTestSuite' ({}). Please increase this "
                               "parameter.\n",
                               s.registered, s.path, rep.max_tests);
    }
  if (extended) print_tcunit_extended(out, rep);
  size_t suites = 0, tests = 0, failed = 0;
  for (const auto& s : rep.suites) {
    suites += !(s.tests.empty() && s.filtered > 0);  // --filter selected none of its tests
    for (const auto& t : s.tests) {
      ++tests;
      failed += t.failed;
    }
  }
  out << "| ==========TESTS FINISHED RUNNING==========\n"
            << "| Test suites: " << suites << "\n"
            << "| Tests: " << tests << "\n"
            << "| Successful tests: " << tests - failed << "\n"
            << "| Failed tests: " << failed << "\n"
            << "| Duration: " << tcunit_seconds(rep.seconds) << "\n"
            << "| ======================================\n";
  out << fmt::format("TcUnit: {} of virtual time, {} cycles{}\n", common::format_duration(rep.virtual_ns), rep.cycles,
                           rep.timed_out ? "; the time-out ended the run" : rep.aborted ? "; TcUnit stopped" : "");
  return ok;
}

std::string test_duration(double seconds) {
  auto ns = static_cast<int64_t>(std::llround(seconds * 1e9));
  if (ns <= 0) return "0s";
  std::string out;
  const int64_t h = ns / 3'600'000'000'000, m = ns / 60'000'000'000 % 60, s = ns / 1'000'000'000 % 60;
  const int64_t ms = ns / 1'000'000 % 1000, us = ns / 1000 % 1000, rest = ns % 1000;
  if (h) out += fmt::format("{}h", h);
  if (m) out += fmt::format("{}m", m);
  if (s) out += fmt::format("{}s", s);
  if (ms) out += fmt::format("{}ms", ms);
  if (us) out += fmt::format("{}us", us);
  if (rest) out += fmt::format("{}ns", rest);
  return out;
}

void print_tests(std::ostream& out, const std::vector<testing::TestSuite>& suites) {
  for (const auto& s : suites) {
    out << "[" << (s.heading.empty() ? s.name : s.heading) << "]\n";
    for (const auto& c : s.cases) {
      out << "  " << word(c.verdict) << ": " << c.name;
      if (!c.note.empty()) out << ": " << c.note;
      if (c.verdict != testing::Verdict::Disabled && c.seconds >= 0) out << " (" << test_duration(c.seconds) << ")";
      out << "\n";
      if (c.verdict == testing::Verdict::Pass) continue;
      for (const auto& f : c.findings) out << "    " << (f.where.empty() ? f.text : f.where + ": " + f.text) << "\n";
    }
    for (const auto& n : s.notes) out << "  " << n << "\n";
  }
}

std::string totals_line(const testing::Totals& t) {
  std::string s = fmt::format("{} passed, {} failed", t.passed, t.failed);
  if (t.disabled) s += fmt::format(", {} disabled", t.disabled);
  if (t.undecidable) s += fmt::format(", {} undecidable", t.undecidable);
  return s;
}

std::vector<JunitSuite> junit_suites(const std::vector<testing::TestSuite>& suites) {
  std::vector<JunitSuite> out;
  for (const auto& s : suites) {
    JunitSuite j;
    j.name = s.name;
    j.properties = s.properties;
    for (const auto& c : s.cases) {
      JunitCase k;
      k.classname = s.name;
      k.name = c.note.empty() ? c.name : c.name + ": " + c.note;
      k.seconds = c.seconds < 0 ? 0 : c.seconds;
      k.properties = c.properties;
      switch (c.verdict) {
        case testing::Verdict::Pass: break;
        case testing::Verdict::Fail:
          k.outcome = JunitCase::Outcome::Fail;
          k.message = c.summary();
          for (const auto& f : c.findings) k.detail += (k.detail.empty() ? "" : "\n") + (f.where.empty() ? f.text : f.where + ": " + f.text);
          break;
        case testing::Verdict::Disabled:
          k.outcome = JunitCase::Outcome::Skipped;
          k.message = "disabled";
          break;
        case testing::Verdict::Undecidable:
          k.outcome = JunitCase::Outcome::Skipped;
          k.message = c.summary().empty() ? "undecidable" : "undecidable: " + c.summary();
          break;
      }
      j.cases.push_back(std::move(k));
    }
    out.push_back(std::move(j));
  }
  return out;
}

bool write_test_junit(const std::string& path, const std::vector<testing::TestSuite>& suites, std::string* err) {
  return write_junit(path, junit_suites(suites), err);
}

std::string tcunit_xunit_xml(const std::vector<testing::TestSuite>& suites, double seconds) {
  size_t failed = 0, tests = 0;
  for (const auto& s : suites)
    for (const auto& c : s.cases) {
      ++tests;
      failed += c.verdict == testing::Verdict::Fail;
    }
  // TcUnit's "tests" of the whole run counts its successful tests.
  std::string out = fmt::format("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites disabled=\"\" failures=\"{}\" "
                                "tests=\"{}\" time=\"{}\">\n",
                                failed, tests - failed, tcunit_seconds(seconds));
  for (size_t i = 0; i < suites.size(); ++i) {
    const auto& s = suites[i];
    size_t f = 0;
    for (const auto& c : s.cases) f += c.verdict == testing::Verdict::Fail;
    out += fmt::format("  <testsuite id=\"{}\" name=\"{}\" tests=\"{}\" failures=\"{}\" time=\"{}\">\n", i,
                       xml_escape(s.name), s.cases.size(), f, tcunit_seconds(s.seconds));
    for (const auto& c : s.cases) {
      const char* status = c.verdict == testing::Verdict::Fail       ? "FAIL"
                           : c.verdict == testing::Verdict::Disabled ? "SKIP"
                                                                     : "PASS";
      out += fmt::format("    <testcase name=\"{}\" classname=\"{}\" time=\"{}\" status=\"{}\"", xml_escape(c.name),
                         xml_escape(s.name), tcunit_seconds(c.seconds < 0 ? 0 : c.seconds), status);
      if (c.verdict == testing::Verdict::Fail) {
        out += fmt::format(">\n      <failure message=\"{}\" type=\"{}\"/>\n    </testcase>\n",
                           xml_escape(property(c.properties, "message")), xml_escape(property(c.properties, "type")));
      } else {
        out += "></testcase>\n";
      }
    }
    out += "  </testsuite>\n";
  }
  return out + "</testsuites>\n";
}

bool write_tcunit_xunit(const std::string& path, const std::vector<testing::TestSuite>& suites, double seconds,
                        std::string* err) {
  return write_file_atomically(path, tcunit_xunit_xml(suites, seconds), err);
}

}  // namespace plcfi::report
