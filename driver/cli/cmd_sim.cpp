// plcfi sim: a PLC program on a plant model in virtual time, with traces and a summary.
#include <chrono>
#include <iostream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "options.hpp"
#include "coverage_opts.hpp"
#include "trace_hook.hpp"
#include "common/duration.hpp"
#include "engine.hpp"
#include "io/sim/plant_factory.hpp"
#include "io/sim/sim_backend.hpp"
#include "monitor/edtl.hpp"
#include "plant_model/plant.hpp"
#include "report/edtl.hpp"
#include "report/trace.hpp"
#include "runtime/runtime.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {

// Splits "a,b , c" into names.
std::vector<std::string> split_list(const std::vector<std::string>& items) {
  std::vector<std::string> out;
  for (const auto& item : items) {
    std::string cur;
    for (char c : item + ",") {
      if (c == ',') {
        size_t b = cur.find_first_not_of(' '), e = cur.find_last_not_of(' ');
        if (b != std::string::npos) out.push_back(cur.substr(b, e - b + 1));
        cur.clear();
      } else {
        cur += c;
      }
    }
  }
  return out;
}

// Records when each alarm variable rose, and how often.
class AlarmWatch final : public rt::ScanHooks {
 public:
  explicit AlarmWatch(std::vector<st::VarHandle> vars) : vars_(std::move(vars)), prev_(vars_.size(), false),
                                                          first_(vars_.size(), -1), rises_(vars_.size(), 0) {}
  void end_of_scan(rt::Runtime& r) override {
    const uint8_t* mem = r.machine().mem();
    for (size_t i = 0; i < vars_.size(); ++i) {
      // Every scan: a plain BOOL is one byte (the common case), the rest as the engine reads them.
      const st::VarHandle& h = vars_[i];
      bool v = !h.is_bit && h.type->kind == st::TypeKind::Bool ? mem[h.addr] != 0 : st::read_bool(r.machine(), h);
      if (v && !prev_[i]) {
        ++rises_[i];
        if (first_[i] < 0) first_[i] = r.now();
      }
      prev_[i] = v;
    }
  }
  std::string summary() const {
    std::string out;
    for (size_t i = 0; i < vars_.size(); ++i)
      if (rises_[i])
        out += fmt::format("{}{} (first at {:.3f} s, raised {}x)", out.empty() ? "" : ", ", vars_[i].path,
                           static_cast<double>(first_[i]) * 1e-9, rises_[i]);
    return out.empty() ? "none" : out;
  }
  size_t raised() const {
    size_t n = 0;
    for (auto r : rises_) n += r != 0;
    return n;
  }

 private:
  std::vector<st::VarHandle> vars_;
  std::vector<uint8_t> prev_;
  std::vector<int64_t> first_;
  std::vector<uint64_t> rises_;
};

// Checks the requirements once per scan and reports each first violation as it happens.
class MonitorHook final : public rt::ScanHooks {
 public:
  explicit MonitorHook(monitor::MonitorSet* set) : set_(set) {}
  void end_of_scan(rt::Runtime& r) override {
    if (!set_->step(r.machine(), r.scan_count(), r.now())) return;
    auto verdicts = set_->verdicts();
    for (size_t i : set_->newly_violated()) {
      const auto& v = verdicts[i];
      const auto& x = v.violations.front();
      std::cout << fmt::format("  [scan {}, t={:.3f} s] {} VIOLATED: {} (trigger at scan {}, t={:.3f} s){}\n", x.state,
                               static_cast<double>(x.time_ns) * 1e-9, v.id, monitor::cause_text(x.cause), x.trigger_state,
                               static_cast<double>(x.trigger_time_ns) * 1e-9, v.text.empty() ? "" : " - " + v.text);
    }
  }

 private:
  monitor::MonitorSet* set_;
};

bool is_alarm_name(const std::string& name) {
  std::string c = st::canon(name);
  for (const char* k : {"ERROR", "ALARM", "WARNING", "STOP", "FAULT"})
    if (c.find(k) != std::string::npos) return true;
  return false;
}

// The options of `plcfi sim`.
void add_sim_options(po::options_description& desc) {
  desc.add_options()
      ("program", po::value<std::vector<std::string>>()->multitoken(), "ST files of the program (also accepted as plain arguments)")
      ("plant", po::value<std::string>()->default_value("stamping"), "plant model")
      ("plant-config", po::value<std::string>(), "plant parameters (YAML)")
      ("seed", po::value<Count>()->default_value(Count{1}, "1"), "seed of the plant's random variation")
      ("duration", po::value<std::string>()->default_value("1h"), "simulated time, e.g. 90s, 10m, 1h")
      ("cycle-time", po::value<std::string>()->default_value("10ms"), "cycle time when the program has no CONFIGURATION")
      ("vcd", po::value<std::string>(), "write a VCD trace")
      ("csv", po::value<std::string>(), "write a CSV trace (one row per scan)")
      ("watch", po::value<std::vector<std::string>>(), "variables to trace, comma-separated (default: the plant's signals and the alarms)")
      ("alarms", po::value<std::vector<std::string>>(), "alarm variables to report (default: BOOL globals named *Error*, *Alarm*, *Warning*, *Stop*, *Fault*)")
      ("requirements", po::value<std::string>(), "EDTL requirements (YAML) checked every scan")
      ("native", "run the program (and the monitors) through the native tier");
  add_coverage_export_options(desc);
  add_dialect_options(desc);
}

// --program and the plain arguments: the program's ST files.
std::vector<std::string> program_files(const po::variables_map& vm) {
  std::vector<std::string> files;
  if (vm.count("program")) files = vm["program"].as<std::vector<std::string>>();
  if (vm.count("files"))
    for (const auto& f : vm["files"].as<std::vector<std::string>>()) files.push_back(f);
  return files;
}

// --requirements: the EDTL requirements and their monitors' ST source, compiled with the
// program (late: none without --requirements).
struct Requirements {
  monitor::RequirementsFile reqs;
  monitor::MonitorSource mon;
  st::GeneratedSources late;
};

bool load_requirements_of(const po::variables_map& vm, Requirements* r) {
  if (!vm.count("requirements")) return true;
  std::string err;
  if (!monitor::load_requirements(vm["requirements"].as<std::string>(), &r->reqs, &err)) {
    std::cerr << err << "\n";
    return false;
  }
  r->mon = monitor::generate_monitors(r->reqs);
  r->late.push_back(r->mon.source(r->reqs.path));
  return true;
}

// --duration, and the schedule: the configuration's tasks, or the program alone every
// --cycle-time. False after printing why.
bool sim_timing(const po::variables_map& vm, const st::Application& app, int64_t* duration, rt::Schedule* sched) {
  int64_t cycle = 0;
  std::string err;
  if (!rt::parse_duration(vm["duration"].as<std::string>(), duration, &err) || *duration <= 0) {
    std::cerr << "plcfi sim: --duration: " << (err.empty() ? "must be positive" : err) << "\n";
    return false;
  }
  if (!rt::parse_duration(vm["cycle-time"].as<std::string>(), &cycle, &err)) {
    std::cerr << "plcfi sim: --cycle-time: " << err << "\n";
    return false;
  }
  bool ok = app.has_configuration ? sched->from_configuration(app, &err) : sched->single_program(app, "", cycle, &err);
  if (!ok) {
    std::cerr << "plcfi sim: " << err << "\n";
    return false;
  }
  return true;
}

// The plant model (--plant, --plant-config) behind the program's I/O. Null after printing
// why.
std::unique_ptr<io::SimBackend> open_sim(const po::variables_map& vm, const st::Application& app) {
  std::string err;
  auto plant = io::open_plant(vm["plant"].as<std::string>(), vm.count("plant-config") ? vm["plant-config"].as<std::string>() : "", &err);
  if (!plant) {
    std::cerr << "plcfi sim: " << err << "\n";
    return nullptr;
  }
  auto backend = io::SimBackend::create(app, std::move(plant), &err);
  if (!backend) std::cerr << "plcfi sim: " << err << "\n";
  return backend;
}

// The variables a list option (--alarms, --watch) names. False after printing why.
bool resolve_named(const po::variables_map& vm, const char* key, const st::Application& app, std::vector<st::VarHandle>* out) {
  std::string err;
  for (const auto& p : split_list(vm[key].as<std::vector<std::string>>())) {
    auto h = st::resolve(app, p, &err);
    if (!h) {
      std::cerr << "plcfi sim: --" << key << ": " << err << "\n";
      return false;
    }
    out->push_back(*h);
  }
  return true;
}

// --alarms, else the BOOL globals named like alarms.
bool alarm_vars(const po::variables_map& vm, const st::Application& app, std::vector<st::VarHandle>* alarms) {
  if (vm.count("alarms")) return resolve_named(vm, "alarms", app, alarms);
  std::string err;
  for (const auto& g : app.globals)
    if (g.sym->type->kind == st::TypeKind::Bool && is_alarm_name(g.sym->name)) {
      auto h = st::resolve(app, g.sym->name, &err);
      if (h) alarms->push_back(*h);
    }
  return true;
}

// --watch, else (when a trace is written) the plant's signals and the alarms.
bool watch_vars(const po::variables_map& vm, const st::Application& app, const plant::Plant& plant,
                const std::vector<st::VarHandle>& alarms, std::vector<st::VarHandle>* watch) {
  if (vm.count("watch")) return resolve_named(vm, "watch", app, watch);
  if (!vm.count("vcd") && !vm.count("csv")) return true;
  std::string err;
  for (const auto& s : plant.signals()) {
    auto h = st::resolve(app, s.name, &err);  // the program's name for the signal, if any
    if (!h) h = st::resolve(app, s.address, &err);
    if (h) {
      h->path = s.name;
      watch->push_back(*h);
    }
  }
  for (const auto& a : alarms) watch->push_back(a);
  return true;
}

// --vcd and --csv, opened. False after printing why.
bool open_traces(const po::variables_map& vm, const std::vector<st::VarHandle>& watch, const plant::Plant& plant,
                 std::vector<std::unique_ptr<report::TraceWriter>>* writers) {
  std::string err;
  if (vm.count("vcd")) {
    const std::string origin = plant.origin();
    auto w = report::open_vcd(vm["vcd"].as<std::string>(), watch, &err,
                              fmt::format("plcfi sim on plant {}{}", plant.name(), origin.empty() ? "" : ": " + origin));
    if (!w) {
      std::cerr << "plcfi sim: --vcd: " << err << "\n";
      return false;
    }
    writers->push_back(std::move(w));
  }
  if (vm.count("csv")) {
    auto w = report::open_csv(vm["csv"].as<std::string>(), watch, &err);
    if (!w) {
      std::cerr << "plcfi sim: --csv: " << err << "\n";
      return false;
    }
    writers->push_back(std::move(w));
  }
  return true;
}

std::vector<report::TraceWriter*> raw_writers(const std::vector<std::unique_ptr<report::TraceWriter>>& writers) {
  std::vector<report::TraceWriter*> raw;
  for (auto& w : writers) raw.push_back(w.get());
  return raw;
}

// The requirements' monitors, checked every scan by a hook on the runtime. False after
// printing why.
bool attach_monitors(const st::Application& app, const monitor::RequirementsFile& reqs, rt::Runtime& runtime,
                     std::unique_ptr<monitor::MonitorSet>* monitors, std::unique_ptr<MonitorHook>* hook) {
  std::string err;
  *monitors = monitor::MonitorSet::create(app, reqs, &err);
  if (!*monitors) {
    std::cerr << "plcfi sim: " << err << "\n";
    return false;
  }
  *hook = std::make_unique<MonitorHook>(monitors->get());
  runtime.add_hooks(hook->get());
  return true;
}

// The scans of a run: the wall time they took, and why the program stopped ("": it did not).
struct SimRun {
  double wall = 0;
  std::string trap_text;
};

SimRun run_scans(rt::Runtime& runtime, uint64_t scans) {
  SimRun run;
  auto t0 = std::chrono::steady_clock::now();
  for (uint64_t n = 0; n < scans; ++n) {
    if (runtime.scan() == rt::ScanStatus::Trapped) run.trap_text = runtime.stop_reason();
  }
  run.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

bool close_traces(const std::vector<std::unique_ptr<report::TraceWriter>>& writers) {
  std::string err;
  for (auto& w : writers)
    if (!w->close(&err)) {
      std::cerr << "plcfi sim: " << err << "\n";
      return false;
    }
  return true;
}

// A plant from a file: the file, its step and its notes.
void print_plant_file(const plant::Plant& plant, const rt::Schedule& sched) {
  const std::string origin = plant.origin();
  if (origin.empty()) return;
  const int64_t step = plant.step_ns();
  std::cout << fmt::format("  plant file      {}{}\n", origin,
                           step > 0 ? fmt::format(", plant step {}", common::format_duration(step)) : "");
  for (const auto& n : plant.notes()) std::cout << "  note            " << n << "\n";
  if (step > sched.tick_ns())
    std::cout << fmt::format("  note            the plant step is coarser than the base tick: the plant's outputs "
                             "change at most every {} scans\n",
                             (step + sched.tick_ns() - 1) / sched.tick_ns());
}

// The run's summary: what ran on which plant, the times, the plant's figures and the alarms.
void print_sim_summary(const std::string& program, const plant::Plant& plant, uint64_t seed, const rt::Schedule& sched,
                       const rt::Runtime& runtime, double wall, const AlarmWatch& alarms) {
  double simulated = static_cast<double>(runtime.now()) * 1e-9;
  std::cout << fmt::format("plcfi sim: {} on plant {} (seed {}), base tick {} ms\n", program, plant.name(), seed,
                           static_cast<double>(sched.tick_ns()) / 1e6);
  print_plant_file(plant, sched);
  std::cout << fmt::format("  simulated time  {:.3f} s ({} scans)\n", simulated, runtime.scan_count());
  std::cout << fmt::format("  wall time       {:.3f} s\n", wall);
  std::cout << fmt::format("  speed           {:.0f}x real time (simulated seconds per wall second)\n", wall > 0 ? simulated / wall : 0.0);
  std::string stats;
  for (const auto& [k, v] : plant.stats()) stats += fmt::format("{}{} {}", stats.empty() ? "" : ", ", k, v);
  std::cout << "  plant           " << stats << "\n";
  std::cout << "  alarms raised   " << alarms.summary() << "\n";
}

// The requirements' verdicts, printed: 1 when one was violated, else 0.
int requirements_status(const po::variables_map& vm, const monitor::MonitorSet& monitors) {
  int status = 0;
  auto verdicts = monitors.verdicts();
  std::cout << "requirements (" << vm["requirements"].as<std::string>() << "):\n" << report::edtl_verdicts_text(verdicts);
  for (const auto& v : verdicts)
    if (v.violated()) status = 1;
  return status;
}

}  // namespace

int cmd_sim(const std::vector<std::string>& args) {
  po::options_description desc("plcfi sim: run a PLC program on a plant model in virtual time");
  add_sim_options(desc);
  po::variables_map vm;
  if (!parse_args(args, desc, vm,
                  "plcfi sim --program FILE... --plant stamping [--plant-config F] [--seed N] --duration 1h "
                  "[--vcd F] [--csv F] [--watch PATH,...] [--requirements REQS.yaml] [--lcov F] [--cobertura F]"))
    return 0;
  if (!check_coverage_paths(vm, "plcfi sim")) return 2;
  const std::vector<std::string> files = program_files(vm);
  if (files.empty()) {
    std::cerr << "plcfi sim: no program files (--program FILE...)\n";
    return 2;
  }
  Requirements req;
  if (!load_requirements_of(vm, &req)) return 2;
  auto b = compile_program(vm, files, req.late);
  if (!b) return 2;
  const st::Application& app = *b->app;
  int64_t duration = 0;
  rt::Schedule sched;
  if (!sim_timing(vm, app, &duration, &sched)) return 2;
  auto backend = open_sim(vm, app);
  if (!backend) return 2;
  rt::Runtime runtime(app, sched, backend.get());
  std::unique_ptr<st::NativeCode> native;
  if (vm.count("native") && !(native = load_native(app, "plcfi sim"))) return 2;
  runtime.machine().set_native(native.get());
  runtime.machine().set_count_hits(coverage_export_wanted(vm));

  // The scan hooks, in this order every scan: alarms, traces, requirements.
  std::vector<st::VarHandle> alarms, watch;
  if (!alarm_vars(vm, app, &alarms)) return 2;
  AlarmWatch alarm_watch(alarms);
  runtime.add_hooks(&alarm_watch);
  std::vector<std::unique_ptr<report::TraceWriter>> writers;
  if (!watch_vars(vm, app, backend->plant(), alarms, &watch) || !open_traces(vm, watch, backend->plant(), &writers)) return 2;
  TraceHook trace(raw_writers(writers));
  if (!writers.empty()) runtime.add_hooks(&trace);
  std::unique_ptr<monitor::MonitorSet> monitors;
  std::unique_ptr<MonitorHook> monitor_hook;
  if (!req.late.empty() && !attach_monitors(app, req.reqs, runtime, &monitors, &monitor_hook)) return 2;

  const uint64_t seed = vm["seed"].as<Count>().value;
  runtime.cold_restart(seed);
  const SimRun run = run_scans(runtime, static_cast<uint64_t>(duration / sched.tick_ns()));
  if (!close_traces(writers)) return 2;
  print_sim_summary(files.back(), backend->plant(), seed, sched, runtime, run.wall, alarm_watch);
  const int status = monitors ? requirements_status(vm, *monitors) : 0;
  if (coverage_export_wanted(vm) &&
      !write_coverage_exports(vm, app, runtime.machine().hits(), report::coverage_files(*b), "plcfi_sim", "plcfi sim"))
    return 2;
  if (!run.trap_text.empty()) {
    std::cout << "  program stopped " << run.trap_text << "\n";
    return 1;
  }
  return status;
}

}  // namespace plcfi::cli
