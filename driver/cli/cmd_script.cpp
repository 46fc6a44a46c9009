// plcfi script: CPTest+ test scripts against a PLC program on a plant model in virtual
// time, with ASSERT_COM, link faults, the undecidable verdict and the run history;
// plcfi history: that history, newest first.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "common/duration.hpp"
#include "engine.hpp"
#include "io/devices/device_io.hpp"
#include "io/io_config.hpp"
#include "io/link_fault.hpp"
#include "io/sim/plant_factory.hpp"
#include "io/sim/sim_backend.hpp"
#include "options.hpp"
#include "plant_model/plant.hpp"
#include "report/junit.hpp"
#include "report/script.hpp"
#include "report/tests.hpp"
#include "report/trace.hpp"
#include "runtime/realtime.hpp"
#include "runtime/schedule.hpp"
#include "script/bind.hpp"
#include "script/cpt.hpp"
#include "script/history.hpp"
#include "script/runner.hpp"
#include "testing/filter.hpp"
#include "testing/model.hpp"
#include "trace_hook.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
  return true;
}

// Writes a report text to path; false with "PATH: ..." in *err.
bool write_log(const std::string& path, const std::string& text, std::string* err) {
  std::ofstream o(path);
  if (!o) {
    *err = path + ": cannot write";
    return false;
  }
  o << text;
  if (!o) {
    *err = path + ": write error";
    return false;
  }
  return true;
}

double number_option(const po::variables_map& vm, const char* key) { return vm[key].as<double>(); }

// --filter, --list, --test-timeout and --timeout: which scripts run, and for how long.
struct Selection {
  testing::Filter filter;
  bool list = false;
  int64_t test_timeout_ns = 0;  // per script, on its scan clock; 0: none
  int64_t timeout_ns = 0;       // all scripts together; 0: none
};

// An optional duration option that must be positive.
bool positive_duration(const po::variables_map& vm, const char* key, int64_t* ns) {
  if (!vm.count(key)) return true;
  const std::string text = vm[key].as<std::string>();
  std::string err;
  if (rt::parse_duration(text, ns, &err) && *ns > 0) return true;
  std::cerr << "plcfi script: --" << key << ": " << (err.empty() ? "must be positive, got '" + text + "'" : err) << "\n";
  return false;
}

bool selection_of(const po::variables_map& vm, Selection* sel) {
  if (vm.count("filter")) sel->filter = testing::Filter(vm["filter"].as<std::vector<std::string>>());
  sel->list = vm.count("list") > 0;
  return positive_duration(vm, "test-timeout", &sel->test_timeout_ns) && positive_duration(vm, "timeout", &sel->timeout_ns);
}

// The scripts --filter selects: the suite is the script's path as given, the test its name.
std::vector<size_t> selected_scripts(const std::vector<script::Script>& parsed, const testing::Filter& filter) {
  std::vector<size_t> out;
  for (size_t i = 0; i < parsed.size(); ++i)
    if (filter.selects(parsed[i].path, parsed[i].name)) out.push_back(i);
  return out;
}

// The scan-clock time a script may take, into ro: the per-test time-out or what is left of
// the run's, whichever is less. False when the run's is used up: the script does not start.
bool limit_time(const Selection& sel, int64_t used_ns, script::RunOptions* ro) {
  ro->time_limit_ns = sel.test_timeout_ns;
  ro->time_limit_reason =
      fmt::format("did not finish within the per-test time-out ({})", common::format_duration(sel.test_timeout_ns));
  if (sel.timeout_ns == 0) return true;
  const int64_t left = sel.timeout_ns - used_ns;
  if (left <= 0) return false;
  if (ro->time_limit_ns == 0 || left < ro->time_limit_ns) {
    ro->time_limit_ns = left;
    ro->time_limit_reason = fmt::format("did not finish within the run's time-out ({})", common::format_duration(sel.timeout_ns));
  }
  return true;
}

std::string not_started(const Selection& sel) {
  return fmt::format("the run's time-out ({}) ran out before this script started", common::format_duration(sel.timeout_ns));
}

script::HistoryRow history_row(const script::Script& s, const script::ScriptResult& r, const std::string& prog_hash,
                               const std::string& pou_hash) {
  script::HistoryRow row;
  row.test = s.name;
  row.verdict = script::verdict_name(r.verdict);
  row.time = script::utc_now();
  for (const auto& a : r.asserts)
    if (a.has_mci) {
      row.mci = a.mci;
      row.cycles = a.cycles;
    }
  row.program_hash = prog_hash;
  row.pou_hash = pou_hash;
  row.reason = r.reason;
  return row;
}

// The options of `plcfi script`.
void add_script_options(po::options_description& desc) {
  desc.add_options()
      ("plant", po::value<std::string>(), "plant model (stamping, bead_dispenser; default stamping)")
      ("io", po::value<std::string>(), "run on bench I/O instead (a file with an io: section), paced in real time")
      ("realtime", "pace the scans in real time (always on with --io)")
      ("plant-config", po::value<std::string>(), "plant parameters (YAML)")
      ("seed", po::value<Count>()->default_value(Count{1}, "1"), "seed of the plant's random variation")
      ("cycle-time", po::value<std::string>()->default_value("10ms"), "cycle time when the program has no CONFIGURATION")
      ("history", po::value<std::string>(), "run history (SQLite; default $PLCFI_HISTORY or ~/.local/state/plcfi/history.sqlite)")
      ("log", po::value<std::string>(), "folder for each run's log: TEST.log (text), TEST.csv (snapshots), TEST.vcd (every scan)")
      ("junit", po::value<std::string>(), "write JUnit XML (undecidable: skipped, with m_ci)")
      ("filter", po::value<std::vector<std::string>>(), "run (or list) only the scripts this shell pattern matches: their path as given, their test name (the file name without .cpt) or PATH/TEST (repeatable)")
      ("list", "list the scripts (PATH/TEST) the run would run, and run none")
      ("test-timeout", po::value<std::string>(), "a time-out per script on its scan clock: a script that runs longer fails")
      ("timeout", po::value<std::string>(), "a time-out of the whole run on the scan clock (all scripts together): the script running when it runs out fails, the later ones fail unrun")
      ("link-fault", po::value<std::string>(), "break a link in every run: [DEVICE=]AT:FOR, e.g. 100ms:300ms (DEVICE: plant offline, the first of the io file on a bench)")
      ("link-status", po::value<std::string>(), "an %IX bit that reads TRUE while the link to the plant works")
      ("max-wait", po::value<std::string>()->default_value("1s"), "how long ASSERT_COM re-checks through a communication error")
      ("alpha", po::value<double>()->default_value(0.1, "0.1"), "m_ci: least value in the middle band")
      ("beta", po::value<double>()->default_value(0.9, "0.9"), "m_ci: greatest value in the middle band")
      ("gamma", po::value<IntIn<2, 1000000>>()->default_value(IntIn<2, 1000000>{10}, "10"), "m_ci: cycles taken into account")
      ("psi", po::value<IntIn<1, 1000000>>()->default_value(IntIn<1, 1000000>{10}, "10"), "m_ci: latest runs counted for p_lst")
      ("n", po::value<double>()->default_value(1.0, "1"), "m_ci: shape of the fall from beta to alpha (1: linear)")
      ("native", "run the program through the native tier");
  add_dialect_options(desc);
}

// The command line of `plcfi script`, checked.
struct ScriptArgs {
  std::vector<std::string> programs, scripts;
  Selection sel;
  script::RunOptions ro;                 // m_ci and --max-wait; per script, its time limit and p_lst
  int64_t fault_at = -1, fault_for = 0;  // --link-fault; fault_at -1: none
  std::string fault_device;
};

// The plain arguments: the program's ST files and the .cpt scripts. False after printing
// the usage.
bool split_files(const po::variables_map& vm, const std::string& usage, ScriptArgs* a) {
  for (const auto& f : strings_of(vm, "files")) (ends_with(f, ".cpt") ? a->scripts : a->programs).push_back(f);
  if (a->programs.empty() || a->scripts.empty()) {
    std::cerr << "plcfi script: expected the program's ST files and one or more .cpt scripts\nusage: " << usage << "\n";
    return false;
  }
  return true;
}

// m_ci's parameters and --max-wait: how ASSERT_COM waits through a communication error.
// False after printing why.
bool wait_options(const po::variables_map& vm, script::RunOptions* ro) {
  ro->mci.alpha = number_option(vm, "alpha");
  ro->mci.beta = number_option(vm, "beta");
  ro->mci.gamma = vm["gamma"].as<IntIn<2, 1000000>>().value;
  ro->mci.psi = vm["psi"].as<IntIn<1, 1000000>>().value;
  ro->mci.n = number_option(vm, "n");
  if (std::string e = script::check_params(ro->mci); !e.empty()) {
    std::cerr << "plcfi script: " << e << "\n";
    return false;
  }
  std::string err;
  if (!rt::parse_duration(vm["max-wait"].as<std::string>(), &ro->max_wait_ns, &err)) {
    std::cerr << "plcfi script: --max-wait: " << err << "\n";
    return false;
  }
  return true;
}

// --link-fault [DEVICE=]AT:FOR. False after printing why.
bool link_fault_option(const po::variables_map& vm, ScriptArgs* a) {
  if (!vm.count("link-fault")) return true;
  std::string v = vm["link-fault"].as<std::string>(), err;
  if (size_t eq = v.find('='); eq != std::string::npos) {
    a->fault_device = v.substr(0, eq);
    v = v.substr(eq + 1);
  }
  size_t colon = v.find(':');
  if (colon == std::string::npos || !rt::parse_duration(v.substr(0, colon), &a->fault_at, &err) ||
      !rt::parse_duration(v.substr(colon + 1), &a->fault_for, &err) || a->fault_for <= 0) {
    std::cerr << "plcfi script: --link-fault: expected [DEVICE=]AT:FOR with two durations, e.g. 100ms:300ms"
              << (err.empty() ? "" : " (" + err + ")") << ", got '" << vm["link-fault"].as<std::string>() << "'\n";
    return false;
  }
  return true;
}

bool script_args(const po::variables_map& vm, const std::string& usage, ScriptArgs* a) {
  return split_files(vm, usage, a) && selection_of(vm, &a->sel) && wait_options(vm, &a->ro) && link_fault_option(vm, a);
}

bool load_scripts(const std::vector<std::string>& scripts, std::vector<script::Script>* parsed) {
  parsed->resize(scripts.size());
  std::string err;
  for (size_t i = 0; i < scripts.size(); ++i) {
    if (!script::load_script(scripts[i], &(*parsed)[i], &err)) {
      std::cerr << err << "\n";
      return false;
    }
  }
  return true;
}

// The configuration's tasks, or the program alone every --cycle-time.
bool script_schedule(const po::variables_map& vm, const st::Application& app, rt::Schedule* sched) {
  int64_t cycle = 0;
  std::string err;
  if (!rt::parse_duration(vm["cycle-time"].as<std::string>(), &cycle, &err)) {
    std::cerr << "plcfi script: --cycle-time: " << err << "\n";
    return false;
  }
  if (!(app.has_configuration ? sched->from_configuration(app, &err) : sched->single_program(app, "", cycle, &err))) {
    std::cerr << "plcfi script: " << err << "\n";
    return false;
  }
  return true;
}

// Where the scripts run. Offline: the plant model behind a link that can be broken. On a
// bench: the devices of the io file, each of which can be.
struct Target {
  std::unique_ptr<io::SimBackend> sim;
  std::unique_ptr<io::LinkFaultBackend> link;
  std::unique_ptr<io::DeviceIo> device_io;
  io::IoConfig cfg;
  std::string where;  // the plant, or the io file
  rt::IoBackend* backend = nullptr;
};

bool open_devices(const po::variables_map& vm, const st::Application& app, const rt::Schedule& sched, Target* t) {
  std::string err;
  if (!io::load_io_config(vm["io"].as<std::string>(), app, &t->cfg, &err) ||
      !(t->device_io = io::DeviceIo::open(t->cfg, sched.tick_ns(), &err))) {
    std::cerr << err << "\n";
    return false;
  }
  t->backend = t->device_io.get();
  t->where = "bench I/O " + t->cfg.path;
  return true;
}

// --link-status: the %IX bit that reads TRUE while the link works, into *status.
bool link_status_option(const po::variables_map& vm, const st::Application& app, std::optional<rt::ImageRef>* status) {
  if (!vm.count("link-status")) return true;
  rt::ImageRef ref;
  std::string err;
  if (!rt::parse_image_ref(app, vm["link-status"].as<std::string>(), &ref, &err) || ref.area != 'I' || !ref.is_bit) {
    std::cerr << "plcfi script: --link-status: " << (err.empty() ? "expected an input bit such as %IX1.0" : err) << "\n";
    return false;
  }
  *status = ref;
  return true;
}

bool open_plant_link(const po::variables_map& vm, const st::Application& app, Target* t) {
  std::string err;
  auto plant = io::open_plant(vm.count("plant") ? vm["plant"].as<std::string>() : "stamping",
                              vm.count("plant-config") ? vm["plant-config"].as<std::string>() : "", &err);
  if (!plant) {
    std::cerr << "plcfi script: " << err << "\n";
    return false;
  }
  t->where = "plant " + plant->name() + (plant->origin().empty() ? "" : " (" + plant->origin() + ")");
  if (!(t->sim = io::SimBackend::create(app, std::move(plant), &err))) {
    std::cerr << "plcfi script: " << err << "\n";
    return false;
  }
  std::optional<rt::ImageRef> status;
  if (!link_status_option(vm, app, &status)) return false;
  t->link = std::make_unique<io::LinkFaultBackend>(t->sim.get(), "plant", status);
  t->backend = t->link.get();
  return true;
}

// The bench's devices (--io) or the plant model (--plant). False after printing why.
bool open_target(const po::variables_map& vm, const st::Application& app, const rt::Schedule& sched, Target* t) {
  const bool bench = vm.count("io") > 0;
  if (bench && (vm.count("plant") || vm.count("plant-config") || vm.count("link-status"))) {
    std::cerr << "plcfi script: --io runs on the bench's devices; --plant, --plant-config and --link-status are for the plant model\n";
    return false;
  }
  return bench ? open_devices(vm, app, sched, t) : open_plant_link(vm, app, t);
}

// The scripts' names resolved in the program and among the link's devices.
bool bind_scripts(const st::Application& app, const std::vector<script::Script>& parsed, const std::vector<std::string>& devices,
                  std::vector<script::BoundScript>* bound) {
  bound->resize(parsed.size());
  std::string err;
  for (size_t i = 0; i < parsed.size(); ++i) {
    if (!script::bind_script(app, parsed[i], devices, &(*bound)[i], &err)) {
      std::cerr << err << "\n";
      return false;
    }
  }
  return true;
}

// The device --link-fault breaks: the one named, else the first. False when it is unknown.
bool link_fault_device(const std::vector<std::string>& devices, ScriptArgs* a) {
  if (a->fault_at < 0) return true;
  if (a->fault_device.empty() && !devices.empty()) a->fault_device = devices.front();
  bool known = false;
  for (const auto& d : devices) known = known || d == a->fault_device;
  if (!known) {
    std::string list;
    for (const auto& d : devices) list += (list.empty() ? "" : ", ") + d;
    std::cerr << "plcfi script: --link-fault: unknown device '" << a->fault_device << "' (known: " << (list.empty() ? "none" : list) << ")\n";
    return false;
  }
  return true;
}

// The scripts --filter selects, into *chosen. With --list they are printed, not run: 0.
// A --filter that selects nothing is a mistake (a misspelt name), not a green run: 2.
// Else -1: run them.
int choose_scripts(const Selection& sel, const std::vector<script::Script>& parsed, std::vector<size_t>* chosen) {
  *chosen = selected_scripts(parsed, sel.filter);
  if (chosen->empty()) {
    std::cerr << "plcfi script: --filter selects none of the " << parsed.size() << " script(s): --list shows them (PATH/TEST)\n";
    return 2;
  }
  if (sel.list) {  // what would run, without running it
    for (size_t i : *chosen) std::cout << parsed[i].path << "/" << parsed[i].name << "\n";
    return 0;
  }
  return -1;
}

// Every way out once the devices are open: the safe output state reaches them first.
struct SafeExit {
  rt::Runtime& rt;
  io::DeviceIo* io;
  ~SafeExit() {
    if (!io) return;
    rt.write_safe_outputs();
    io->close();
  }
};

std::unique_ptr<script::History> open_history(const std::string& path) {
  std::string err;
  auto history = script::History::open(path, &err);
  if (!history) std::cerr << "plcfi script: " << err << "\n";
  return history;
}

// --log DIR, created. False after printing why.
bool make_log_dir(const std::string& log_dir) {
  if (log_dir.empty()) return true;
  std::error_code ec;
  std::filesystem::create_directories(log_dir, ec);
  if (ec) {
    std::cerr << "plcfi script: --log: " << log_dir << ": " << ec.message() << "\n";
    return false;
  }
  return true;
}

// Paced on a bench (or offline with --realtime): the real-time loop watches signals and
// lost devices; a way out it takes ends the run undecidable, with its reason. Null when the
// runs are not paced.
std::unique_ptr<rt::ScanLoop> paced_loop(bool paced, rt::Runtime& runtime, const rt::StopSignals& signals,
                                         io::DeviceIo* device_io, script::RunOptions* ro) {
  if (!paced) return nullptr;
  auto loop = std::make_unique<rt::ScanLoop>(runtime, true, &signals, [device_io] { return device_io ? device_io->lost() : std::string(); });
  ro->scan = [l = loop.get()](rt::Runtime&, std::string* why) {
    if (l->check_stop() != rt::LoopEnd::None) {
      *why = l->end_reason();
      return false;
    }
    l->scan();
    return true;
  };
  return loop;
}

// What the runs of the scripts share.
struct Session {
  const st::Build& b;
  rt::Runtime& runtime;
  rt::IoBackend& backend;
  script::History& history;
  ScriptArgs& a;  // a.ro changes per script
  const std::string& log_dir;
  const std::string prog_hash;
  const uint64_t seed;
  rt::ScanLoop* loop = nullptr;  // paced runs only
};

// A script the run's time-out left no time for: failed without running.
void fail_not_started(const Selection& sel, const script::Script& s, testing::TestSuite* suite) {
  testing::TestCase& c = suite->cases.back();
  c.verdict = testing::Verdict::Fail;
  c.findings.push_back({"", not_started(sel)});
  std::cout << fmt::format("\n[{}] Failed  (not run)\n  {}\n", s.path, c.findings.back().text);
}

// The script's run. With --log, its waveform: every scan of the run, the variables a
// snapshot records that a VCD can show, into LOG/TEST.vcd. False after printing why.
bool run_traced(const Session& x, const script::Script& s, const script::BoundScript& bound, script::ScriptResult* r) {
  std::unique_ptr<report::TraceWriter> vcd;
  std::unique_ptr<TraceHook> vcd_hook;
  std::string err;
  if (!x.log_dir.empty()) {
    std::vector<st::VarHandle> traced;
    for (const auto& v : script::snapshot_variables(*x.b.app))
      if (v.is_bit || v.type->is_elementary()) traced.push_back(v);
    if (!(vcd = report::open_vcd(x.log_dir + "/" + s.name + ".vcd", traced, &err))) {
      std::cerr << "plcfi script: --log: " << err << "\n";
      return false;
    }
    vcd_hook = std::make_unique<TraceHook>(std::vector<report::TraceWriter*>{vcd.get()});
    x.runtime.add_hooks(vcd_hook.get());
  }
  *r = script::run_script(x.runtime, bound, x.a.ro);
  if (vcd) {
    x.runtime.remove_hooks(vcd_hook.get());
    if (!vcd->close(&err)) {
      std::cerr << "plcfi script: --log: " << err << "\n";
      return false;
    }
  }
  return true;
}

// --log: the run's text log LOG/TEST.log and its snapshots LOG/TEST.csv.
bool write_logs(const std::string& log_dir, const script::Script& s, const script::ScriptResult& r) {
  if (log_dir.empty()) return true;
  std::string err;
  if (!write_log(log_dir + "/" + s.name + ".log", report::script_text_log(r), &err) ||
      !write_log(log_dir + "/" + s.name + ".csv", report::script_csv_log(r), &err)) {
    std::cerr << "plcfi script: --log: " << err << "\n";
    return false;
  }
  return true;
}

// One script from a cold restart (the link broken as --link-fault says): run, printed,
// recorded in the history and the logs, its test case into `suite`. False after printing
// why.
bool run_one(const Session& x, const script::Script& s, const script::BoundScript& bound, int64_t* used_ns,
             testing::TestSuite* suite) {
  script::RunOptions& ro = x.a.ro;
  std::string err;
  std::vector<std::string> pous;
  const std::string pou_hash = script::involved_pous_hash(x.b, bound.var_paths, &pous);
  if (!x.history.passes_since_change(s.name, pou_hash, ro.mci.psi, &ro.p_lst, &err)) {
    std::cerr << "plcfi script: " << err << "\n";
    return false;
  }
  x.runtime.cold_restart(x.seed);
  if (x.a.fault_at >= 0) x.backend.break_link(x.a.fault_device, x.runtime.now() + x.a.fault_at, x.a.fault_for);
  if (x.loop) x.loop->start();
  const uint64_t failed_before = x.backend.failed_exchanges();
  script::ScriptResult r;
  if (!run_traced(x, s, bound, &r)) return false;
  *used_ns += r.end_ns;
  std::cout << report::script_run_text(s, r, pous, ro, x.backend.failed_exchanges() - failed_before);
  const script::HistoryRow row = history_row(s, r, x.prog_hash, pou_hash);
  if (!x.history.add(row, &err)) {
    std::cerr << "plcfi script: " << err << "\n";
    return false;
  }
  if (!write_logs(x.log_dir, s, r)) return false;
  suite->cases.back() = report::script_case(s, r, row, ro.p_lst);
  return true;
}

// The chosen scripts one after another until a stop signal, each a suite in `suites`.
// False after printing why.
bool run_scripts(const Session& x, const std::vector<size_t>& chosen, const std::vector<script::Script>& parsed,
                 const std::vector<script::BoundScript>& bound,
                 const std::vector<std::pair<std::string, std::string>>& run_props, const rt::StopSignals& signals,
                 std::vector<testing::TestSuite>* suites) {
  int64_t used_ns = 0;  // the scan clock of the scripts run so far (--timeout)
  for (size_t i : chosen) {
    suites->push_back(report::script_suite(parsed[i], run_props));
    if (!limit_time(x.a.sel, used_ns, &x.a.ro)) {
      fail_not_started(x.a.sel, parsed[i], &suites->back());
      continue;
    }
    if (!run_one(x, parsed[i], bound[i], &used_ns, &suites->back())) return false;
    if (signals.requested()) break;
  }
  return true;
}

}  // namespace

int cmd_script(const std::vector<std::string>& args) {
  const std::string usage =
      "plcfi script PROGRAM.st... TEST.cpt... [--plant stamping|bead_dispenser | --io FILE] [--realtime] [--history FILE] "
      "[--log DIR] [--junit F] [--filter GLOB] [--list] [--test-timeout D] [--timeout D] [--link-fault [DEVICE=]AT:FOR] "
      "[--max-wait 1s] [--alpha A --beta B --gamma G --psi P --n N]";
  po::options_description desc(
      "plcfi script: CPTest+ test scripts against a PLC program, on a plant model in virtual time or on bench I/O in real time");
  add_script_options(desc);
  po::variables_map vm;
  if (!parse_args(args, desc, vm, usage)) return 0;
  ScriptArgs a;
  if (!script_args(vm, usage, &a)) return 2;

  // Everything is read and checked before anything runs.
  auto b = compile_program(vm, a.programs);
  if (!b) return 2;
  const st::Application& app = *b->app;
  std::vector<script::Script> parsed;
  rt::Schedule sched;
  Target t;
  if (!load_scripts(a.scripts, &parsed) || !script_schedule(vm, app, &sched) || !open_target(vm, app, sched, &t)) return 2;
  const std::vector<std::string> devices = t.backend->link_devices();
  std::vector<script::BoundScript> bound;
  if (!bind_scripts(app, parsed, devices, &bound) || !link_fault_device(devices, &a)) return 2;
  std::vector<size_t> chosen;
  if (int s = choose_scripts(a.sel, parsed, &chosen); s >= 0) return s;
  rt::Runtime runtime(app, sched, t.backend);
  if (t.device_io) runtime.set_safe_state(t.cfg.safe_state);
  SafeExit safe_exit{runtime, t.device_io.get()};
  std::unique_ptr<st::NativeCode> native;
  if (vm.count("native") && !(native = load_native(app, "plcfi script"))) return 2;
  runtime.machine().set_native(native.get());
  const std::string history_path = vm.count("history") ? vm["history"].as<std::string>() : script::default_history_path();
  auto history = open_history(history_path);
  if (!history) return 2;
  const std::string log_dir = vm.count("log") ? vm["log"].as<std::string>() : "";
  if (!make_log_dir(log_dir)) return 2;

  rt::StopSignals signals;
  a.ro.signals = &signals;
  Session x{*b, runtime, *t.backend, *history, a, log_dir, script::program_hash(*b), vm["seed"].as<Count>().value, nullptr};
  std::cout << fmt::format("plcfi script: {} on {}, history {}\n", a.programs.front(), t.where, history_path);
  auto loop = paced_loop(t.device_io || vm.count("realtime"), runtime, signals, t.device_io.get(), &a.ro);
  x.loop = loop.get();
  std::vector<testing::TestSuite> suites;
  if (!run_scripts(x, chosen, parsed, bound, {{"io", t.where}, {"history", history_path}}, signals, &suites)) return 2;
  const testing::Totals totals = testing::totals(suites);
  std::cout << fmt::format("\n{} passed, {} failed, {} undecidable\n", totals.passed, totals.failed, totals.undecidable);
  std::string err;
  if (vm.count("junit") && !report::write_test_junit(vm["junit"].as<std::string>(), suites, &err)) {
    std::cerr << "plcfi script: " << err << "\n";
    return 2;
  }
  return totals.failed > 0 ? 1 : 0;
}

int cmd_history(const std::vector<std::string>& args) {
  const std::string usage = "plcfi history [TEST] [--history FILE] [--last N]";
  po::options_description desc("plcfi history: the run history of test scripts, newest first");
  desc.add_options()
      ("history", po::value<std::string>(), "run history (default $PLCFI_HISTORY or ~/.local/state/plcfi/history.sqlite)")
      ("last", po::value<Count>()->default_value(Count{50}, "50"), "at most this many runs (0: all)");
  po::variables_map vm;
  if (!parse_args(args, desc, vm, usage, "test")) return 0;
  auto tests = strings_of(vm, "test");
  if (tests.size() > 1) {
    std::cerr << "plcfi history: at most one test name\nusage: " << usage << "\n";
    return 2;
  }
  std::string err;
  const std::string path = vm.count("history") ? vm["history"].as<std::string>() : script::default_history_path();
  if (!std::filesystem::exists(path)) {
    std::cerr << "plcfi history: " << path << ": no history yet (plcfi script writes it)\n";
    return 2;
  }
  auto h = script::History::open(path, &err);
  std::vector<script::HistoryRow> rows;
  if (!h || !h->list(tests.empty() ? "" : tests[0], vm["last"].as<Count>().value, &rows, &err)) {
    std::cerr << "plcfi history: " << err << "\n";
    return 2;
  }
  if (rows.empty()) {
    std::cout << (tests.empty() ? std::string("no runs recorded") : "no runs of " + tests[0]) << " in " << path << "\n";
    return 0;
  }
  std::cout << report::history_table(rows);
  return 0;
}

}  // namespace plcfi::cli
