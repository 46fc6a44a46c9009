#include "suites.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include <fmt/format.h>

#include "common/duration.hpp"

namespace plcfi::testing {

namespace {

std::string where(const st::Build& b, st::SourceLoc loc) { return loc.valid() ? b.app->where(b.sm.origin(loc)) : ""; }

}  // namespace

std::vector<TestSuite> test_file_suites(const std::vector<TestResult>& results) {
  std::vector<TestSuite> out;
  for (const auto& r : results) {
    if (out.empty() || out.back().name != r.file) {
      TestSuite s;
      s.name = r.file;
      out.push_back(std::move(s));
    }
    TestCase c;
    c.name = r.name;
    c.verdict = r.passed ? Verdict::Pass : Verdict::Fail;
    if (!r.passed) c.findings.push_back(Finding{r.where, r.message});
    c.seconds = r.seconds;
    out.back().seconds += r.seconds;
    out.back().cases.push_back(std::move(c));
  }
  return out;
}

std::vector<TestSuite> tcunit_suites(const TcUnitReport& rep, const st::Build& b) {
  std::vector<TestSuite> out;
  for (const auto& s : rep.suites) {
    if (s.tests.empty() && s.filtered > 0) continue;  // --filter selected none of its tests
    TestSuite suite;
    suite.name = s.path;
    suite.heading = s.path + " (" + s.type->name + ", " + where(b, s.type->loc) + ")";
    suite.seconds = s.seconds;
    for (const auto& t : s.tests) {
      TestCase c;
      c.name = t.name;
      c.seconds = t.seconds;
      c.verdict = t.disabled ? Verdict::Disabled : t.failed ? Verdict::Fail : Verdict::Pass;
      for (const auto& f : t.failures) c.findings.push_back(Finding{where(b, f.where), f.line});
      if (!t.problem.empty()) c.findings.push_back(Finding{where(b, t.problem_at), t.problem});
      c.properties = {{"status", t.disabled ? "SKIP" : t.failed ? "FAIL" : "PASS"}, {"asserts", std::to_string(t.asserts)}};
      if (!t.type.empty()) c.properties.emplace_back("type", t.type);  // TcUnit's, for its xUnit file
      if (t.failed) c.properties.emplace_back("message", !t.message.empty() ? t.message : c.summary());
      suite.cases.push_back(std::move(c));
    }
    if (s.tests.empty())
      suite.notes.push_back(s.started ? "(no tests)"
                                      : "(not started: RUN_IN_SEQUENCE starts a suite when the one before it is done)");
    out.push_back(std::move(suite));
  }
  return out;
}

std::vector<TestSuite> fb_assert_suites(const UntilReport& rep, const st::Build& b) {
  std::vector<TestSuite> out;
  for (const auto& e : rep.log) {
    const std::string unit = e.unit.empty() ? "(FB_ASSERT without a name)" : e.unit;
    auto it = std::find_if(out.begin(), out.end(), [&](const TestSuite& s) { return s.name == unit; });
    if (it == out.end()) {
      TestSuite s;
      s.name = unit;
      out.push_back(std::move(s));
      it = out.end() - 1;
    }
    TestCase c;
    c.name = fmt::format("state {}", e.state);
    c.seconds = e.seconds;
    if (e.passed) {
      c.note = e.message;
    } else {
      c.verdict = Verdict::Fail;
      c.findings.push_back(Finding{where(b, e.where), e.message});
    }
    it->cases.push_back(std::move(c));
  }
  return out;
}

std::vector<std::string> list_test_files(const st::Application& app, const Filter& f) {
  std::vector<std::string> out;
  for (const auto& t : app.tests) {
    const std::string file = t.loc.file < app.file_paths.size() ? app.file_paths[t.loc.file] : "";
    if (f.selects(file, t.name)) out.push_back(file + "/" + t.name);
  }
  return out;
}

namespace {

// TEST('name') and TEST_ORDERED('name') in the text of a POU (comments skipped).
void tests_in(const std::string& text, std::vector<std::string>* out) {
  size_t i = 0;
  auto word_at = [&](size_t p, const char* w) {
    const size_t n = std::char_traits<char>::length(w);
    if (p + n > text.size()) return false;
    for (size_t k = 0; k < n; ++k)
      if (std::toupper(static_cast<unsigned char>(text[p + k])) != w[k]) return false;
    return p == 0 || !(std::isalnum(static_cast<unsigned char>(text[p - 1])) || text[p - 1] == '_' || text[p - 1] == '.');
  };
  while (i < text.size()) {
    if (text.compare(i, 2, "(*") == 0) {
      const size_t e = text.find("*)", i + 2);
      i = e == std::string::npos ? text.size() : e + 2;
      continue;
    }
    if (text.compare(i, 2, "//") == 0) {
      const size_t e = text.find('\n', i);
      i = e == std::string::npos ? text.size() : e;
      continue;
    }
    if (text[i] == '\'') {  // a string that is not a test's name
      const size_t e = text.find('\'', i + 1);
      i = e == std::string::npos ? text.size() : e + 1;
      continue;
    }
    size_t after = 0;
    if (word_at(i, "TEST_ORDERED")) after = i + 12;
    else if (word_at(i, "TEST") && !word_at(i, "TEST_")) after = i + 4;
    if (!after) {
      ++i;
      continue;
    }
    size_t p = after;
    while (p < text.size() && std::isspace(static_cast<unsigned char>(text[p]))) ++p;
    if (p < text.size() && text[p] == '(') {
      ++p;
      while (p < text.size() && std::isspace(static_cast<unsigned char>(text[p]))) ++p;
      if (text.compare(p, 10, "TestName :") == 0 || text.compare(p, 10, "TestName:=") == 0) p = text.find('\'', p);
      if (p != std::string::npos && p < text.size() && text[p] == '\'') {
        const size_t e = text.find('\'', p + 1);
        if (e != std::string::npos) {
          std::string name = text.substr(p + 1, e - p - 1);
          const auto b = name.find_first_not_of(" \t"), l = name.find_last_not_of(" \t");
          name = b == std::string::npos ? "" : name.substr(b, l - b + 1);
          if (name.size() > 9) {
            std::string low = name.substr(0, 9);
            for (char& ch : low) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
            if (low == "disabled_") name = name.substr(9) + " (disabled)";
          }
          if (!name.empty() && std::find(out->begin(), out->end(), name) == out->end()) out->push_back(name);
          i = e + 1;
          continue;
        }
      }
    }
    i = after;
  }
}

}  // namespace

std::vector<std::string> list_tcunit(const st::Build& b, const Filter& f) {
  std::vector<std::string> out;
  for (const auto& [path, type] : tcunit_suite_instances(*b.app)) {
    std::vector<std::string> names;
    // The suite's FB and its bases below FB_TestSuite (a base suite's tests run too).
    for (const st::PouInfo* p = type; p && !p->is_stdlib; p = p->base)
      for (const auto& u : b.units)
        for (const auto& pou : u->pous)
          if (pou->kind == st::PouKind::FunctionBlock && st::iequals(pou->name.text, p->name) && pou->loc.file == pou->end_loc.file &&
              pou->loc.file < b.sm.size()) {
            const st::SourceFile& file = b.sm.file(pou->loc.file);
            const std::string& text = file.text;
            auto offset = [&](st::SourceLoc l) -> size_t {
              if (l.line == 0 || l.line > file.line_starts.size()) return text.size() + 1;
              return file.line_starts[l.line - 1] + (l.col ? l.col - 1 : 0);
            };
            const size_t from = offset(pou->loc), to = offset(pou->end_loc);
            if (from < to && to <= text.size()) tests_in(text.substr(from, to - from), &names);
          }
    for (const auto& n : names) {
      const std::string plain = n.size() > 11 && n.compare(n.size() - 11, 11, " (disabled)") == 0 ? n.substr(0, n.size() - 11) : n;
      if (f.selects(path, plain)) out.push_back(path + "/" + n);
    }
  }
  return out;
}

}  // namespace plcfi::testing
