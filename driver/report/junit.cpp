// JUnit XML rendering.
#include "junit.hpp"

#include <cstdio>
#include <fstream>

#include <fmt/format.h>

namespace plcfi::report {

namespace {

// Length of the well-formed UTF-8 sequence at s[i] (1..4), or 0 when it is not one
// (stray continuation byte, overlong form, surrogate, past U+10FFFF, truncated).
size_t utf8_length(const std::string& s, size_t i) {
  auto b = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  unsigned char c = b(i);
  if (c < 0x80) return 1;
  size_t n = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
  if (n == 0 || c > 0xF4 || i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((b(i + k) & 0xC0) != 0x80) return 0;
  if (n == 3 && ((c == 0xE0 && b(i + 1) < 0xA0) || (c == 0xED && b(i + 1) >= 0xA0))) return 0;  // overlong, surrogate
  if (n == 4 && ((c == 0xF0 && b(i + 1) < 0x90) || (c == 0xF4 && b(i + 1) >= 0x90))) return 0;  // overlong, > U+10FFFF
  return n;
}

}  // namespace

// Messages come from anywhere (ST strings, device errors, file names): whatever the bytes,
// the report stays well-formed XML 1.0 in UTF-8.
std::string xml_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size();) {
    char c = s[i];
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: {
        auto u = static_cast<unsigned char>(c);
        if (u < 0x20 && c != '\n' && c != '\t' && c != '\r') {
          out += fmt::format("\\x{:02x}", u);  // XML 1.0 cannot carry it, not even as &#N;
        } else if (size_t n = utf8_length(s, i); n == 0) {
          out += "\xEF\xBF\xBD";  // U+FFFD for a byte that is not UTF-8
        } else {
          out.append(s, i, n);
          i += n;
          continue;
        }
      }
    }
    ++i;
  }
  return out;
}

std::string junit_xml(const std::vector<JunitSuite>& suites) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n";
  for (const auto& s : suites) {
    size_t failures = 0, skipped = 0, errors = 0;
    double time = 0;
    for (const auto& c : s.cases) {
      failures += c.outcome == JunitCase::Outcome::Fail;
      skipped += c.outcome == JunitCase::Outcome::Skipped;
      errors += c.outcome == JunitCase::Outcome::Error;
      time += c.seconds;
    }
    out += fmt::format("  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"{}\" time=\"{:.6f}\">\n",
                       xml_escape(s.name), s.cases.size(), failures, errors, skipped, time);
    if (!s.properties.empty()) {
      out += "    <properties>\n";
      for (const auto& [k, v] : s.properties)
        out += fmt::format("      <property name=\"{}\" value=\"{}\"/>\n", xml_escape(k), xml_escape(v));
      out += "    </properties>\n";
    }
    for (const auto& c : s.cases) {
      out += fmt::format("    <testcase classname=\"{}\" name=\"{}\" time=\"{:.6f}\"", xml_escape(c.classname), xml_escape(c.name), c.seconds);
      if (c.outcome == JunitCase::Outcome::Pass && c.properties.empty()) {
        out += "/>\n";
        continue;
      }
      out += ">\n";
      if (!c.properties.empty()) {
        out += "      <properties>\n";
        for (const auto& [k, v] : c.properties)
          out += fmt::format("        <property name=\"{}\" value=\"{}\"/>\n", xml_escape(k), xml_escape(v));
        out += "      </properties>\n";
      }
      const char* tag = c.outcome == JunitCase::Outcome::Fail ? "failure" : c.outcome == JunitCase::Outcome::Skipped ? "skipped"
                        : c.outcome == JunitCase::Outcome::Error ? "error" : nullptr;
      if (tag) out += fmt::format("      <{} message=\"{}\">{}</{}>\n", tag, xml_escape(c.message), xml_escape(c.detail), tag);
      out += "    </testcase>\n";
    }
    out += "  </testsuite>\n";
  }
  out += "</testsuites>\n";
  return out;
}

// Writes atomically (temporary file + rename).
bool write_file_atomically(const std::string& path, const std::string& text, std::string* err) {
  std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) {
      *err = path + ": cannot write";
      return false;
    }
    f << text;
    if (!f.flush()) {
      *err = path + ": write failed";
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    *err = path + ": cannot rename the temporary file";
    return false;
  }
  return true;
}

bool write_junit(const std::string& path, const std::vector<JunitSuite>& suites, std::string* err) {
  return write_file_atomically(path, junit_xml(suites), err);
}

JunitSuite scan_run_junit(const ScanRunFacts& run) {
  JunitSuite suite;
  suite.name = "run";
  JunitCase jc;
  jc.classname = "run";
  jc.name = run.name;
  jc.seconds = run.seconds;
  if (run.failed) {
    jc.outcome = JunitCase::Outcome::Fail;
    jc.message = run.ended;
  }
  jc.properties.emplace_back("scans", std::to_string(run.scans));
  jc.properties.emplace_back("ended", run.ended);
  suite.properties = run.realtime;
  for (size_t n = 0; n < run.io_report.size(); ++n) suite.properties.emplace_back("io_" + std::to_string(n), run.io_report[n]);
  suite.cases.push_back(jc);
  return suite;
}

}  // namespace plcfi::report
