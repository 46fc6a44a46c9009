// JUnit XML rendering.
#include "junit.hpp"

#include <cstdio>
#include <fstream>

#include <fmt/format.h>

namespace plcfi::report {

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') out += fmt::format("&#{};", static_cast<int>(c));
        else out += c;
    }
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

bool write_junit(const std::string& path, const std::vector<JunitSuite>& suites, std::string* err) {
  std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) {
      *err = path + ": cannot write";
      return false;
    }
    f << junit_xml(suites);
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

}  // namespace plcfi::report
