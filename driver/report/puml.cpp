// PlantUML text for the diagrams of a test case.
#include "puml.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace plcfi::report {

namespace {

std::string ms(int64_t ns) {
  if (ns >= 1'000'000'000 && ns % 100'000'000 == 0) return fmt::format("{:g} s", static_cast<double>(ns) * 1e-9);
  if (ns % 1'000'000 == 0) return fmt::format("{} ms", ns / 1'000'000);
  return fmt::format("{:.3f} ms", static_cast<double>(ns) * 1e-6);
}

// PlantUML reads some characters in messages as markup; keep the text literal.
std::string text(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

}  // namespace

std::string sequence_diagram(const PumlCase& c) {
  std::string o;
  o += fmt::format("@startuml {}_sequence\n", c.id);
  o += fmt::format("title {} (RPN {}, fault class {})\\n{}\n", c.id, c.rpn, c.fault_class, text(c.title));
  o += "participant \"Test system\\n(plcfi driver)\" as TS\n";
  o += "participant \"SUT\\n(PLC program)\" as SUT\n";
  o += "participant \"Plant\" as P\n";
  o += "== Start & init: wait for the precondition ==\n";
  o += fmt::format("TS -> SUT : cold start, scan cycle running\n");
  o += "TS -> P : reset to the initial state\n";
  o += "loop every scan, before the program runs\n";
  o += fmt::format("  TS -> TS : check precondition\\n{}\n", text(c.precondition));
  o += "end\n";
  o += "== Injection and monitoring ==\n";
  o += fmt::format("TS -> SUT : inject fault on {}: {}\n", text(c.target), text(c.fault));
  o += "note right of TS : the fault acts on the I/O image overlay only\n";
  if (!c.start.empty()) o += fmt::format("SUT -> P : {} (start of the timing)\n", text(c.start));
  else o += "P -> SUT : previous transition (start of the timing)\n";
  for (const auto& t : c.transitions) {
    if (t.faulted)
      o += fmt::format("P -[#red]x SUT : {} -> {} expected within {} (suppressed by the fault)\n", t.lifeline, t.to,
                       ms(t.max_ns));
    else
      o += fmt::format("P -> SUT : {} -> {} within {}\n", t.lifeline, t.to, ms(t.max_ns));
  }
  o += fmt::format("activate TS\nTS -> TS : monitor after each scan\\n{}\n", text(c.reaction));
  o += fmt::format("SUT -> TS : reaction within {} of the start?\n", ms(c.deadline_ns));
  o += fmt::format("note over TS : PASS: reaction in time\\nFAIL: deadline missed, forbidden reaction\\nor test longer than {}\n",
                   ms(c.max_duration_ns));
  o += "deactivate TS\n";
  o += "== Completion ==\n";
  o += "TS -> TS : log verdict (journal, JUnit, VCD)\n";
  o += "TS -> SUT : withdraw the fault\n";
  o += fmt::format("TS -> SUT : stop, {} restart\n", c.restart);
  o += "TS -> P : reset (re-initialize)\n";
  o += "TS -> TS : mark the case tested\n";
  o += "@enduml\n";
  return o;
}

std::string timing_diagram(const PumlCase& c) {
  std::string o;
  o += fmt::format("@startuml {}_timing\n", c.id);
  o += fmt::format("title {}: expected transitions after {}\n", c.id, c.start.empty() ? "the precondition" : text(c.start));
  std::vector<std::string> names;
  for (size_t i = 0; i < c.transitions.size(); ++i) {
    names.push_back(fmt::format("L{}", i));
    o += fmt::format("robust \"{}{}\" as L{}\n", c.transitions[i].lifeline, c.transitions[i].faulted ? " (faulted)" : "", i);
  }
  o += "concise \"Test\" as T\n";
  o += "@0\n";
  o += "T is \"start\"\n";
  for (size_t i = 0; i < c.transitions.size(); ++i) o += fmt::format("L{} is \"{}\"\n", i, c.transitions[i].from);
  // Draw each transition at its latest allowed time; min and max as constraints.
  std::vector<std::pair<int64_t, size_t>> at;
  for (size_t i = 0; i < c.transitions.size(); ++i) at.push_back({c.transitions[i].max_ns, i});
  std::sort(at.begin(), at.end());
  int64_t last = -1;
  for (const auto& [t, i] : at) {
    const auto& tr = c.transitions[i];
    if (t != last) o += fmt::format("@{}\n", t / 1'000'000);
    last = t;
    std::string to = tr.tolerance > 0 ? fmt::format("{} +/- {}", tr.to, tr.tolerance) : tr.to;
    o += fmt::format("L{} is \"{}\"\n", i, to);
  }
  int64_t end = std::max<int64_t>(c.deadline_ns, at.empty() ? 0 : at.back().first);
  o += fmt::format("@{}\nT is \"deadline\"\n", end / 1'000'000);
  for (size_t i = 0; i < c.transitions.size(); ++i) {
    const auto& tr = c.transitions[i];
    o += fmt::format("L{}@0 <-> @{} : max {}\n", i, tr.max_ns / 1'000'000, ms(tr.max_ns));
    if (tr.min_ns > 0) o += fmt::format("L{}@0 <-> @{} : min {}\n", i, tr.min_ns / 1'000'000, ms(tr.min_ns));
  }
  o += fmt::format("T@0 <-> @{} : reaction deadline {}\n", end / 1'000'000, ms(c.deadline_ns));
  o += "@enduml\n";
  return o;
}

}  // namespace plcfi::report
