// EDTL verdicts as JUnit (see edtl.hpp).
#include "report/edtl.hpp"

#include <fmt/format.h>

namespace plcfi::report {

JunitSuite edtl_junit(const std::string& suite, const std::vector<monitor::Verdict>& verdicts) {
  JunitSuite s;
  s.name = suite;
  for (const auto& v : verdicts) {
    JunitCase c;
    c.classname = suite;
    c.name = v.id + (v.text.empty() ? "" : ": " + v.text);
    if (v.violated()) {
      c.outcome = JunitCase::Outcome::Fail;
      const auto& x = v.violations.front();
      c.message = fmt::format("violated at state {} (t={:.3f} s): {}", x.state, static_cast<double>(x.time_ns) * 1e-9,
                              monitor::cause_text(x.cause));
      c.detail = monitor::format_verdicts({v});
    }
    c.properties = {{"triggers", std::to_string(v.triggers)}, {"pending", std::to_string(v.pending)}};
    if (!v.severity.empty()) c.properties.emplace_back("severity", v.severity);
    s.cases.push_back(c);
  }
  return s;
}

}  // namespace plcfi::report
