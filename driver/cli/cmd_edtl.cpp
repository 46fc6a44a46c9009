// plcfi edtl check: EDTL requirements checked offline on a recorded trace.
#include <iostream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "engine.hpp"
#include "json.hpp"
#include "options.hpp"
#include "monitor/edtl.hpp"
#include "report/edtl.hpp"
#include "runtime/schedule.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

Json verdicts_json(const std::vector<monitor::Verdict>& vs) {
  Json out = Json::array();
  for (const auto& v : vs) {
    Json r;
    r["id"] = v.id;
    r["text"] = v.text;
    r["verdict"] = v.violated() ? "VIOLATED" : "SATISFIED";
    r["triggers"] = v.triggers;
    r["held"] = v.holds;
    r["violated"] = v.violated_instances;
    r["pending"] = v.pending;
    r["violations"] = Json::array();
    for (const auto& x : v.violations) {
      Json w;
      w["trigger_state"] = x.trigger_state;
      w["trigger_time"] = static_cast<double>(x.trigger_time_ns) * 1e-9;
      w["state"] = x.state;
      w["time"] = static_cast<double>(x.time_ns) * 1e-9;
      w["cause"] = x.cause == monitor::Cause::Invariant ? "invariant" : "delay";
      r["violations"].push_back(std::move(w));
    }
    out.push_back(std::move(r));
  }
  return out;
}

int cmd_edtl(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::cout << "usage: plcfi edtl check REQS.yaml TRACE [--cycle-time 1s] [--junit F] [--json]\n"
                 "  Checks EDTL requirements on a CSV or VCD trace. Exit 1 when any is violated.\n";
    return args.empty() ? 2 : 0;
  }
  if (args[0] != "check") {
    std::cerr << "plcfi edtl: unknown subcommand '" << args[0] << "' (expected 'check')\n";
    return 2;
  }
  po::options_description desc("plcfi edtl check: EDTL requirements on a recorded trace");
  desc.add_options()("cycle-time", po::value<std::string>(), "time between states when the trace has no time column (default 1s); for VCD: sample every cycle")
      ("junit", po::value<std::string>(), "write JUnit XML")("json", "print the verdicts as JSON");
  po::variables_map vm;
  if (!parse_args(std::vector<std::string>(args.begin() + 1, args.end()), desc, vm,
                  "plcfi edtl check REQS.yaml TRACE [--cycle-time 1s] [--junit F] [--json]"))
    return 0;
  auto files = strings_of(vm, "files");
  if (files.size() != 2) {
    std::cerr << "plcfi edtl check: expected REQS.yaml and TRACE\n";
    return 2;
  }
  std::string err;
  int64_t cycle = 0;
  if (vm.count("cycle-time") && !rt::parse_duration(vm["cycle-time"].as<std::string>(), &cycle, &err)) {
    std::cerr << "plcfi edtl check: --cycle-time: " << err << "\n";
    return 2;
  }
  monitor::RequirementsFile reqs;
  if (!monitor::load_requirements(files[0], &reqs, &err)) {
    std::cerr << err << "\n";
    return 2;
  }
  monitor::TraceCheck result;
  if (!monitor::check_trace(reqs, files[1], cycle, &result, &err)) {
    std::cerr << err << (err.empty() || err.back() == '\n' ? "" : "\n");
    return 2;
  }
  uint64_t state = result.states;
  const auto& verdicts = result.verdicts;
  if (vm.count("json")) {
    Json j;
    j["trace"] = files[1];
    j["states"] = state;
    j["requirements"] = verdicts_json(verdicts);
    std::cout << json_line(j) << "\n";
  } else {
    std::cout << fmt::format("{}: {} states\n", files[1], state) << report::edtl_verdicts_text(verdicts);
  }
  if (vm.count("junit") && !report::write_junit(vm["junit"].as<std::string>(), {report::edtl_junit(files[0], verdicts)}, &err)) {
    std::cerr << "plcfi edtl check: " << err << "\n";
    return 2;
  }
  for (const auto& v : verdicts)
    if (v.violated()) return 1;
  return 0;
}

}  // namespace plcfi::cli
