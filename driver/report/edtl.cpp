// EDTL verdicts as text and as JUnit (see edtl.hpp).
#include "report/edtl.hpp"

#include <fmt/format.h>

namespace plcfi::report {

std::string edtl_verdicts_text(const std::vector<monitor::Verdict>& verdicts) {
  std::string out;
  size_t violated = 0;
  for (const auto& v : verdicts) {
    violated += v.violated();
    out += fmt::format("{:<10} {}  {}\n", v.id, v.violated() ? "VIOLATED " : "SATISFIED", v.text);
    out += fmt::format("           triggers {}, held {}, violated {}, pending {}\n", v.triggers, v.holds, v.violated_instances,
                       v.pending);
    for (const auto& x : v.violations)
      out += fmt::format("           - trigger at state {} (t={:.3f} s), violated at state {} (t={:.3f} s): {}{}\n",
                         x.trigger_state, static_cast<double>(x.trigger_time_ns) * 1e-9, x.state,
                         static_cast<double>(x.time_ns) * 1e-9, monitor::cause_text(x.cause),
                         x.instances > 1 ? fmt::format(" ({} instances)", x.instances) : "");
    if (v.violated_instances > v.violations.size() && v.violations.size() == monitor::Verdict::kMaxListed)
      out += "           (further violations not listed)\n";
  }
  out += fmt::format("{} requirement(s): {} satisfied, {} violated\n", verdicts.size(), verdicts.size() - violated, violated);
  return out;
}

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
      c.detail = edtl_verdicts_text({v});
    }
    c.properties = {{"triggers", std::to_string(v.triggers)}, {"pending", std::to_string(v.pending)}};
    if (!v.severity.empty()) c.properties.emplace_back("severity", v.severity);
    s.cases.push_back(c);
  }
  return s;
}

}  // namespace plcfi::report
