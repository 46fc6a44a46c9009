// ST engine commands: check, run, test, disasm.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>

#include <unistd.h>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "options.hpp"
#include "coverage_opts.hpp"
#include "native/native.hpp"
#include "json.hpp"
#include "engine.hpp"
#include "report/junit.hpp"
#include "common/duration.hpp"
#include "runtime/schedule.hpp"
#include "report/tests.hpp"
#include "testing/suites.hpp"

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {

// Compiles and prints diagnostics. Returns null after printing why.
std::unique_ptr<st::Build> load(const std::vector<std::string>& files, const st::CompileOptions& opt, const char* cmd,
                                size_t shown = st::DiagEngine::kShown) {
  if (files.empty()) {
    std::cerr << "plcfi " << cmd << ": no input files\n";
    return nullptr;
  }
  auto b = st::build_files(files, opt);
  for (const auto& e : b->io_errors) std::cerr << e << "\n";
  std::cerr << b->diags.render_all(shown);
  return b;
}


Json json_value(const st::Machine& m, const st::VarHandle& h) {
  const st::Type* t = h.type;
  if (h.is_bit || t->kind == st::TypeKind::Bool) return st::read_bool(m, h);
  if (t->is_integer() || t->is_bitstring()) return st::read_int(m, h);
  if (t->is_real()) return st::read_real(m, h);
  return st::format(m, h);
}

}  // namespace

std::unique_ptr<st::NativeCode> load_native(const st::Application& app, const char* who) {
  std::string err;
  st::NativeOptions no;
  no.progress = ::isatty(2) != 0;  // a long compile shows how far it got
  auto nc = st::NativeCode::build(app, no, &err);
  if (!nc) {
    std::cerr << who << ": " << err << "\n";
    return nullptr;
  }
  std::string how = nc->from_cache() ? "from the cache" : fmt::format("compiled in {:.2f} s", nc->compile_seconds());
  if (nc->units() > 1 && !nc->from_cache())
    how += nc->units_compiled() == nc->units()
               ? fmt::format(" ({} units)", nc->units())
               : fmt::format(" ({} of {} units, the rest from the cache)", nc->units_compiled(), nc->units());
  std::cerr << fmt::format("{}: native tier: {} function(s){}, {}\n", who, nc->functions(),
                           nc->interpreted() ? fmt::format(", {} left to the interpreter", nc->interpreted()) : "", how);
  return nc;
}

int cmd_check(const std::vector<std::string>& args) {
  po::options_description desc("plcfi check: compile ST files and report every error and warning");
  desc.add_options()("no-warnings", "report errors only")
      ("max-shown", po::value<size_t>()->default_value(st::DiagEngine::kShown),
       "show at most N diagnostics, errors first (0: all); the summary counts every one");
  po::variables_map vm;
  add_dialect_options(desc);
  if (!parse_args(args, desc, vm, "plcfi check FILES... [--no-warnings] [--max-shown N]")) return 0;
  st::CompileOptions opt;
  apply_dialect_options(vm, &opt);
  opt.warnings = !vm.count("no-warnings");
  opt.test_mode = true;  // test files may be checked too; their built-ins are then known
  auto b = load(strings_of(vm, "files"), opt, "check", vm["max-shown"].as<size_t>());
  if (!b) return 2;
  if (!b->io_errors.empty()) return 2;
  size_t errors = b->diags.error_count(), warnings = b->diags.warning_count();
  std::cout << fmt::format("{}: {} error(s), {} warning(s)\n", errors ? "FAILED" : "OK", errors, warnings);
  return errors ? 1 : 0;
}

int cmd_disasm(const std::vector<std::string>& args) {
  po::options_description desc("plcfi disasm: print the bytecode of ST files with their source lines");
  desc.add_options()("native", "print the C++ the native tier generates instead")(
      "coverage", "the code `run --coverage` runs: a COV per branch arm, every IF with jumps");
  po::variables_map vm;
  add_dialect_options(desc);
  if (!parse_args(args, desc, vm, "plcfi disasm FILES... [--native] [--coverage]")) return 0;
  st::CompileOptions opt;
  apply_dialect_options(vm, &opt);
  opt.warnings = false;
  // As `run` compiles it (with --native: as `run --native` does).
  opt.coverage = vm.count("coverage") > 0;
  opt.loop_tails = !vm.count("native");
  opt.if_selects = !vm.count("native");
  auto b = load(strings_of(vm, "files"), opt, "disasm");
  if (!b || !b->ok()) return 2;
  if (vm.count("native")) {
    std::vector<uint32_t> entries, skipped;
    std::cout << st::native_source(*b->app, &entries, &skipped);
    for (uint32_t e : skipped) std::cout << "// left to the interpreter: entry " << e << "\n";
    return 0;
  }
  std::cout << st::disassemble(*b->app, b.get());
  return 0;
}

namespace {

// The options of `plcfi run`.
void add_run_options(po::options_description& desc) {
  desc.add_options()
      ("program", po::value<std::string>(), "program instance or type to run (without a CONFIGURATION)")
      ("cycles", po::value<Count>()->default_value(Count{1}, "1"), "number of base-tick cycles to run")
      ("cycle-time", po::value<std::string>()->default_value("10ms"), "cycle time for a single program (e.g. 10ms)")
      ("set", po::value<std::vector<std::string>>(), "PATH=VALUE before the first cycle (repeatable)")
      ("print", po::value<std::vector<std::string>>(), "PATH to print at the end (repeatable)")
      ("json", "print the result as JSON")
      ("coverage", "print branch coverage per file")
      ("budget", po::value<Count>()->default_value(Count{10'000'000}, "10000000"), "loop iterations allowed per program call (watchdog)")
      ("native", "run the program through the native tier (generated C++, compiled by the system's compiler)")
      ("io", po::value<std::string>(), "exchange the image with real I/O (a file with an io: section: Modbus/GPIO devices and mappings), paced in real time")
      ("realtime", "pace the scans on absolute real-time deadlines and report wake latency (always on with --io)")
      ("duration", po::value<std::string>(), "with --io or --realtime: run this long (e.g. 10s); SIGINT/SIGTERM also end the run")
      ("rt-priority", po::value<RtPriority>()->default_value(RtPriority{0}, "0"), "with --realtime: SCHED_FIFO priority (1..99; 0 keeps the normal scheduler)")
      ("cpu", po::value<CpuIndex>()->default_value(CpuIndex{-1}, "-1"), "with --realtime: pin the scan thread to this CPU")
      ("junit", po::value<std::string>(), "with --io or --realtime: JUnit XML with the wake latency, execution time and overruns as properties");
  add_dialect_options(desc);
}

// The configuration's tasks, or one program (--program) every --cycle-time. False after
// printing why.
bool run_schedule(const po::variables_map& vm, const st::Application& app, rt::Schedule* sched) {
  std::string err;
  bool ok_sched;
  if (app.has_configuration && !vm.count("program")) {
    ok_sched = sched->from_configuration(app, &err);
  } else {
    int64_t cycle = 0;
    if (!rt::parse_duration(vm["cycle-time"].as<std::string>(), &cycle, &err)) {
      std::cerr << "plcfi run: --cycle-time: " << err << "\n";
      return false;
    }
    ok_sched = sched->single_program(app, vm.count("program") ? vm["program"].as<std::string>() : "", cycle, &err);
  }
  if (!ok_sched) {
    std::cerr << "plcfi run: " << err << "\n";
    return false;
  }
  return true;
}

// The options of a paced run (--io, --realtime). False after printing why.
bool paced_options(const po::variables_map& vm, const st::NativeCode* native, RunIoOptions* o) {
  o->native = native;
  // Real I/O is always paced: unpaced scans would hammer the devices (and the plant)
  // millions of times a second.
  o->realtime = vm.count("realtime") > 0 || vm.count("io") > 0;
  o->rt.priority = static_cast<int>(vm["rt-priority"].as<RtPriority>().value);
  o->rt.cpu = static_cast<int>(vm["cpu"].as<CpuIndex>().value);
  if (vm.count("junit")) o->junit = vm["junit"].as<std::string>();
  std::string err;
  if (vm.count("duration") && (!rt::parse_duration(vm["duration"].as<std::string>(), &o->duration_ns, &err) || o->duration_ns <= 0)) {
    std::cerr << "plcfi run: --duration: " << (err.empty() ? "must be positive" : err) << "\n";
    return false;
  }
  if (!vm["cycles"].defaulted() || !vm.count("duration")) o->cycles = vm["cycles"].as<Count>().value;
  return true;
}

// --io or --realtime: the program paced in real time, on real I/O or none; --set applied
// after the cold restart, --print at the end.
int run_paced(const po::variables_map& vm, const st::Application& app, const rt::Schedule& sched, const st::NativeCode* native) {
  RunIoOptions o;
  if (!paced_options(vm, native, &o)) return 2;
  std::vector<std::string> sets = strings_of(vm, "set");
  std::vector<std::string> prints = strings_of(vm, "print");
  std::string err;
  auto setup = [&](st::Machine& mm) {
    mm.set_budget(vm["budget"].as<Count>().value);
    for (const auto& sv : sets) {
      auto eq = sv.find('=');
      auto h = eq == std::string::npos ? std::nullopt : st::resolve(app, sv.substr(0, eq), &err);
      if (!h || !st::write_text(mm, *h, sv.substr(eq + 1), &err)) {
        std::cerr << "plcfi run: --set '" << sv << "': " << (eq == std::string::npos ? "expected PATH=VALUE" : err) << "\n";
        return false;
      }
    }
    for (const auto& p : prints)
      if (!st::resolve(app, p, &err)) {
        std::cerr << "plcfi run: --print: " << err << "\n";
        return false;
      }
    return true;
  };
  auto report = [&](st::Machine& mm, int) {
    for (const auto& p : prints) {
      auto h = st::resolve(app, p, &err);
      std::cout << h->path << " = " << st::format(mm, *h) << "\n";
    }
  };
  return run_with_io(app, sched, vm.count("io") ? vm["io"].as<std::string>() : "", o, setup, report);
}

// --set PATH=VALUE, written before the first cycle. False after printing why.
bool apply_sets(const po::variables_map& vm, const st::Application& app, st::Machine& m) {
  std::string err;
  for (const auto& s : strings_of(vm, "set")) {
    auto eq = s.find('=');
    if (eq == std::string::npos) {
      std::cerr << "plcfi run: --set '" << s << "': expected PATH=VALUE\n";
      return false;
    }
    auto h = st::resolve(app, s.substr(0, eq), &err);
    if (!h || !st::write_text(m, *h, s.substr(eq + 1), &err)) {
      std::cerr << "plcfi run: --set: " << err << "\n";
      return false;
    }
  }
  return true;
}

// --print: the variables printed at the end. False after printing why.
bool resolve_prints(const po::variables_map& vm, const st::Application& app, std::vector<st::VarHandle>* prints) {
  std::string err;
  for (const auto& p : strings_of(vm, "print")) {
    auto h = st::resolve(app, p, &err);
    if (!h) {
      std::cerr << "plcfi run: --print: " << err << "\n";
      return false;
    }
    prints->push_back(*h);
  }
  return true;
}

// Up to `cycles` base ticks in virtual time, until a trap (*status 1, *trap_text why); what
// the program logs goes to stderr as it happens. Returns the cycles completed.
uint64_t run_cycles(const st::Application& app, const rt::Schedule& sched, st::Machine& m, uint64_t cycles, int* status,
                    std::string* trap_text) {
  uint64_t done = 0;
  for (uint64_t n = 0; n < cycles && *status == 0; ++n) {
    m.set_now(static_cast<int64_t>(n) * sched.tick_ns());
    m.clear_taken();
    if (!sched.run_due(app, m, n, trap_text)) *status = 1;
    // What the program logged (ADSLOGSTR, ...), as it happened, beside the trap messages.
    for (const auto& entry : m.log()) std::cerr << "[" << entry.level << "] " << entry.text << "\n";
    m.log().clear();
    m.merge_coverage();
    if (*status == 0) ++done;
  }
  return done;
}

// The --print variables at the end: as text, or (--json) one JSON line with the run's
// figures.
void print_values(const po::variables_map& vm, const st::Machine& m, const std::vector<st::VarHandle>& prints, uint64_t done,
                  const rt::Schedule& sched, const std::string& trap_text) {
  if (vm.count("json")) {
    Json j;
    j["cycles"] = done;
    j["time_ns"] = static_cast<int64_t>(done) * sched.tick_ns();
    j["tick_ns"] = sched.tick_ns();
    j["trap"] = trap_text.empty() ? Json(nullptr) : Json(trap_text);
    j["values"] = Json::object();
    for (const auto& h : prints) j["values"][h.path] = json_value(m, h);
    std::cout << json_line(j) << "\n";
  } else {
    for (const auto& h : prints) std::cout << h.path << " = " << st::format(m, h) << "\n";
  }
}

// The program in virtual time, unpaced: --cycles base ticks from a cold restart and --set.
int run_virtual(const po::variables_map& vm, const st::Application& app, const rt::Schedule& sched,
                const st::NativeCode* native) {
  st::Machine m(app);
  m.set_budget(vm["budget"].as<Count>().value);
  m.set_native(native);
  int status = 0;
  std::string trap_text;
  // The start: FB_init of every instance (CODESYS); --set values then override.
  if (!m.cold_restart()) {
    trap_text = st::describe_trap(app, m.trap()) + " (in FB_init at the start)";
    status = 1;
  }
  std::vector<st::VarHandle> prints;
  if (!apply_sets(vm, app, m) || !resolve_prints(vm, app, &prints)) return 2;
  const uint64_t done = run_cycles(app, sched, m, vm["cycles"].as<Count>().value, &status, &trap_text);
  if (!trap_text.empty()) std::cerr << trap_text << "\n";
  print_values(vm, m, prints, done, sched, trap_text);
  if (vm.count("coverage")) std::cout << st::coverage_report(app, m.covered());
  return status;
}

}  // namespace

int cmd_run(const std::vector<std::string>& args) {
  po::options_description desc("plcfi run: run ST programs in virtual time (the configuration's tasks, or one program)");
  add_run_options(desc);
  po::variables_map vm;
  if (!parse_args(args, desc, vm, "plcfi run FILES... [--program NAME] [--cycles N] [--cycle-time 10ms] [--set PATH=VALUE]... [--print PATH]... [--json] [--io FILE] [--realtime [--rt-priority N] [--cpu N]] [--duration T] [--junit F]")) return 0;
  st::CompileOptions opt;
  apply_dialect_options(vm, &opt);
  opt.warnings = false;
  opt.coverage = vm.count("coverage") > 0;  // else the arms spend nothing on marking it
  // Loop tails spare the interpreter a dispatch; the C++ compiler threads those jumps
  // itself and optimizes a loop with one bottom better (crc16_parity: 6 % more
  // instructions with them).
  opt.loop_tails = !vm.count("native");
  opt.if_selects = !vm.count("native");  // the C++ compiler chooses between jumps and selects itself
  auto b = load(strings_of(vm, "files"), opt, "run");
  if (!b || !b->ok()) return 2;
  const st::Application& app = *b->app;
  rt::Schedule sched;
  if (!run_schedule(vm, app, &sched)) return 2;
  std::unique_ptr<st::NativeCode> native;
  if (vm.count("native") && !(native = load_native(app, "plcfi run"))) return 2;
  if (vm.count("io") || vm.count("realtime")) return run_paced(vm, app, sched, native.get());
  return run_virtual(vm, app, sched, native.get());
}

namespace {

// --tcunit-param KEY=VALUE, each checked against TcUnit's parameter list.
bool tcunit_params(const po::variables_map& vm, std::vector<std::pair<std::string, std::string>>* out) {
  if (!vm.count("tcunit-param")) return true;
  for (const auto& kv : vm["tcunit-param"].as<std::vector<std::string>>()) {
    const auto eq = kv.find('=');
    const std::string key = kv.substr(0, eq), value = eq == std::string::npos ? "" : kv.substr(eq + 1);
    std::string why = eq == std::string::npos ? "give KEY=VALUE" : st::tcunit_param_error(key, value);
    if (!why.empty()) {
      std::cerr << "plcfi test: --tcunit-param " << kv << ": " << why << "\n";
      return false;
    }
    out->emplace_back(key, value);
  }
  return true;
}

// A TcUnit parameter the project or the command line set (the last setting), if any.
std::optional<std::string> tcunit_param_set(const st::Build& b, const st::CompileOptions& opt, const char* key) {
  std::optional<std::string> v;
  for (const auto& p : b.library_params)
    if (st::iequals(p.list, "GVL_Param_TcUnit") && st::iequals(p.key, key)) v = p.value;
  for (const auto& [k, value] : opt.tcunit_params)
    if (st::iequals(k, key)) v = value;
  return v;
}

bool is_true(const std::optional<std::string>& v) { return v && (st::iequals(*v, "TRUE") || *v == "1"); }

// --filter, --list, --test-timeout: the same for every kind of test.
struct TestSelection {
  testing::Filter filter;
  bool list = false;
  int64_t test_timeout_ns = 0;
};

bool test_selection(const po::variables_map& vm, TestSelection* sel) {
  if (vm.count("filter")) sel->filter = testing::Filter(vm["filter"].as<std::vector<std::string>>());
  sel->list = vm.count("list") > 0;
  if (vm.count("test-timeout")) {
    std::string err;
    if (!rt::parse_duration(vm["test-timeout"].as<std::string>(), &sel->test_timeout_ns, &err) || sel->test_timeout_ns <= 0) {
      std::cerr << "plcfi test: --test-timeout: " << (err.empty() ? "must be positive" : err) << "\n";
      return false;
    }
  }
  return true;
}

// A --filter that selects nothing is a mistake (a misspelt name), not a green run.
int no_test_selected() {
  std::cerr << "plcfi test: --filter selected no test: --list shows the tests and their names (SUITE/TEST)\n";
  return 2;
}

bool write_junit_of(const po::variables_map& vm, const std::vector<testing::TestSuite>& suites) {
  if (!vm.count("junit")) return true;
  std::string err;
  if (report::write_test_junit(vm["junit"].as<std::string>(), suites, &err)) return true;
  std::cerr << "plcfi test: " << err << "\n";
  return false;
}

// The schedule a TcUnit or --until run scans: the configuration's tasks, or one program.
bool tcunit_schedule(const st::Application& app, const po::variables_map& vm, rt::Schedule* sched, const char* why) {
  std::string err;
  bool ok;
  if (app.has_configuration && !vm.count("program")) {
    ok = sched->from_configuration(app, &err);
  } else {
    int64_t cycle = 0;
    if (!rt::parse_duration(vm["cycle-time"].as<std::string>(), &cycle, &err)) {
      std::cerr << "plcfi test: --cycle-time: " << err << "\n";
      return false;
    }
    ok = sched->single_program(app, vm.count("program") ? vm["program"].as<std::string>() : "", cycle, &err);
  }
  if (!ok) std::cerr << "plcfi test: " << why << ": " << err << "\n";
  return ok;
}

// The TcUnit suites: run, printed, TcUnit's summary and xUnit file; their results join
// `suites`. Returns an exit status when the run cannot be reported (0: go on).
int run_tcunit_suites(const st::Build& b, const st::CompileOptions& opt, const po::variables_map& vm, const rt::Schedule& sched,
                      st::Machine& m, int64_t timeout_ns, const TestSelection& sel, std::vector<testing::TestSuite>* suites,
                      bool* ok) {
  testing::TcUnitOptions to;
  to.timeout_ns = timeout_ns;
  to.test_timeout_ns = sel.test_timeout_ns;
  to.filter = &sel.filter;
  to.budget = vm["budget"].as<Count>().value;
  const testing::TcUnitReport rep = testing::run_tcunit(*b.app, sched, m, to);
  if (!rep.program_trap.empty()) std::cerr << rep.program_trap << "\n";
  if (!rep.run_called) {
    std::cerr << "plcfi test: TcUnit.RUN() was not called within " << common::format_duration(to.timeout_ns)
              << ": call it in the program that holds the suites (e.g. PRG_TEST, called by a task)\n";
    return 1;
  }
  std::vector<testing::TestSuite> tc = testing::tcunit_suites(rep, b);
  report::print_tests(std::cout, tc);
  // TcUnit's LogExtendedResults and xUnitEnablePublish, when the project (or
  // --tcunit-param) sets them; plcfi prints the extended results only when asked otherwise.
  const bool extended = vm.count("tcunit-extended") || is_true(tcunit_param_set(b, opt, "LogExtendedResults"));
  *ok = report::print_tcunit_summary(std::cout, rep, extended);
  std::string xunit = vm.count("xunit") ? vm["xunit"].as<std::string>() : "";
  if (xunit.empty() && is_true(tcunit_param_set(b, opt, "xUnitEnablePublish"))) {
    // xUnitFilePath, its TwinCAT folder variables read as the current folder.
    xunit = tcunit_param_set(b, opt, "xUnitFilePath").value_or("%TC_BOOTPRJPATH%tcunit_xunit_testresults.xml");
    for (const char* var : {"%TC_BOOTPRJPATH%", "%TC_INSTALLPATH%"})
      for (size_t at; (at = xunit.find(var)) != std::string::npos;) xunit.erase(at, std::strlen(var));
    std::replace(xunit.begin(), xunit.end(), '\\', '/');
    std::cout << "TcUnit: xUnit file " << xunit << " (xUnitEnablePublish)\n";
  }
  std::string err;
  if (!xunit.empty() && !report::write_tcunit_xunit(xunit, tc, rep.seconds, &err)) {
    std::cerr << "plcfi test: " << err << "\n";
    return 2;
  }
  for (auto& s : tc) suites->push_back(std::move(s));
  return 0;
}

// The --until condition EXPR compiled as a PROGRAM linked onto the program, so it reaches
// every instance by path; its instance, with its output `reached` in *reached. Null after
// printing why.
const st::ProgramInstance* link_until(st::Build& b, const std::string& expr, const st::CompileOptions& opt,
                                      const st::Symbol** reached) {
  const std::string head = "PROGRAM _PLCFI_UNTIL\nVAR_OUTPUT reached : BOOL; END_VAR\nreached := ";
  st::LineOrigin origin;
  origin.path = "--until";
  origin.line = 1;
  origin.col = 1;
  origin.prefix = static_cast<uint32_t>(std::string("reached := ").size());
  b.sm.add("--until", expr);  // the origin of the condition's line: errors point into the option's text
  st::GeneratedSource src("<--until>", head + expr + ";\nEND_PROGRAM\n", {{}, {}, origin});
  st::CompileOptions strict = opt;  // a condition: BOOL, not a number CODESYS would convert
  strict.strict = true;
  if (!st::link_generated(b, {src}, strict)) {
    std::cerr << b.diags.render_all();
    std::cerr << "plcfi test: --until '" << expr << "' is not a BOOL expression over the program's variables\n";
    return nullptr;
  }
  // One expression: text that closes the assignment and goes on (`X; END_PROGRAM ...`)
  // would compile as statements or POUs of its own.
  const st::CompilationUnit& cond = *b.late.back();
  if (cond.pous.size() != 1 || cond.pous[0]->body.size() != 1 || !cond.types.empty() || !cond.globals.empty() ||
      !cond.configs.empty()) {
    std::cerr << "plcfi test: --until '" << expr << "' is not one expression: give a single BOOL condition\n";
    return nullptr;
  }
  const st::ProgramInstance* until = nullptr;
  for (const auto& o : b.app->observers)
    if (st::iequals(o.name, "_PLCFI_UNTIL")) until = &o;
  *reached = until ? until->pou->find_var("reached") : nullptr;
  if (!*reached) {
    std::cerr << "plcfi test: --until: the condition's program is missing\n";
    return nullptr;
  }
  return until;
}

// --until --list: the FB_ASSERT units, as FB_init names them; their states show only as
// the program runs.
int list_fb_assert_units(const st::Application& app, const TestSelection& sel) {
  st::Machine m(app);
  std::string trap;
  const std::vector<std::string> units = testing::fb_assert_units(app, m, &trap);
  if (!trap.empty()) {
    std::cerr << trap << "\n";
    return 1;
  }
  size_t listed = 0;
  for (const auto& u : units)
    if (sel.filter.names_suite(u)) {
      std::cout << u << "\n";
      ++listed;
    }
  return listed == 0 && !sel.filter.empty() ? no_test_selected() : 0;
}

// The FB_ASSERT line: the assertions evaluated and failed, the failures logged, and how the
// run ended.
void print_fb_assert_line(const testing::UntilReport& rep, const testing::Totals& logged, int64_t timeout_ns) {
  const std::string ending = rep.reached ? fmt::format("--until held after {} of virtual time ({} cycles)",
                                                         common::format_duration(rep.virtual_ns), rep.cycles)
                             : rep.program_trap.empty()
                                 ? fmt::format("--until did not hold within the time-out ({}, {} cycles)",
                                               common::format_duration(timeout_ns), rep.cycles)
                                 : fmt::format("a runtime error ended the run after {} cycles", rep.cycles);
  std::cout << fmt::format("FB_ASSERT: {} assertions evaluated, {} failed, {} failures logged; {}\n", rep.checks,
                           rep.failures, logged.failed, ending);
}

// `plcfi test --until EXPR`: the program scans until EXPR holds; then FB_ASSERT's log is
// reported, one group per unit under test.
int run_until_mode(st::Build& b, const po::variables_map& vm, const st::CompileOptions& opt, int64_t timeout_ns,
                   const TestSelection& sel) {
  if (!b.tests.empty()) {
    std::cerr << "plcfi test: --until scans the program until a condition holds; it takes no test files "
                 "(TEST ... END_TEST): run them without --until\n";
    return 2;
  }
  const st::Symbol* reached = nullptr;
  const st::ProgramInstance* until = link_until(b, vm["until"].as<std::string>(), opt, &reached);
  if (!until) return 2;
  const st::Application& app = *b.app;
  if (sel.list) return list_fb_assert_units(app, sel);
  rt::Schedule sched;
  if (!tcunit_schedule(app, vm, &sched, "--until scans the program's tasks")) return 2;
  st::Machine m(app);
  std::unique_ptr<st::NativeCode> native;
  if (vm.count("native") && !(native = load_native(app, "plcfi test"))) return 2;
  m.set_native(native.get());
  m.set_count_hits(coverage_export_wanted(vm));
  testing::UntilOptions uo;
  uo.timeout_ns = timeout_ns;
  uo.test_timeout_ns = sel.test_timeout_ns;
  uo.filter = &sel.filter;
  uo.budget = vm["budget"].as<Count>().value;
  const testing::UntilReport rep = testing::run_until(app, sched, m, *until, reached->offset, uo);
  if (!rep.program_trap.empty()) std::cerr << rep.program_trap << "\n";
  const std::vector<testing::TestSuite> suites = testing::fb_assert_suites(rep, b);
  report::print_tests(std::cout, suites);
  const testing::Totals logged = testing::totals(suites);
  if (rep.overflow) std::cout << "  (the log holds 500 entries: later ones were not kept)\n";
  print_fb_assert_line(rep, logged, timeout_ns);
  if (vm.count("coverage")) std::cout << st::coverage_report(app, m.covered());
  // Every evaluation counts, also a failure logged once for several cycles of one state;
  // a state that outlasted --test-timeout fails too.
  std::cout << rep.checks - rep.failures << " passed, " << rep.failures + rep.timeouts << " failed\n";
  if (!write_junit_of(vm, suites)) return 2;
  if (coverage_export_wanted(vm) && !write_coverage_exports(vm, app, m.hits(), report::coverage_files(b), "plcfi_test", "plcfi test"))
    return 2;
  return rep.failures > 0 || logged.failed > 0 || !rep.reached ? 1 : 0;
}

// The options of `plcfi test`.
void add_test_options(po::options_description& desc) {
  desc.add_options()
      ("junit", po::value<std::string>(), "write JUnit XML to this file")
      ("coverage", "print branch coverage of the sources")
      ("budget", po::value<Count>()->default_value(Count{100'000'000}, "100000000"), "loop iterations allowed per test phase (watchdog)")
      ("native", "run the tests through the native tier (generated C++, compiled by the system's compiler)")
      ("timeout", po::value<std::string>()->default_value("10s"), "TcUnit: virtual time the suites get to finish every test (TcUnit's default: 10s); --until: the time the condition gets")
      ("program", po::value<std::string>(), "TcUnit: the program to scan (the one calling TcUnit.RUN()) when there is no task configuration or to run it alone")
      ("cycle-time", po::value<std::string>()->default_value("10ms"), "TcUnit: cycle time of that program")
      ("tcunit-extended", "TcUnit: print its extended results too (per suite and test: status, number of assertions, duration)")
      ("tcunit-param", po::value<std::vector<std::string>>(), "TcUnit: set one of its library parameters (GVL_Param_TcUnit), KEY=VALUE, after the project's own (e.g. MaxNumberOfTestsForEachTestSuite=200; repeatable)")
      ("xunit", po::value<std::string>(), "TcUnit: write the xUnit XML file TcUnit publishes (testsuites, testcase status PASS/FAIL/SKIP, durations)")
      ("filter", po::value<std::vector<std::string>>(), "run (or list) only the tests this shell pattern matches: their suite's name (test file, TcUnit instance path, FB_ASSERT unit), their own name or SUITE/TEST (repeatable)")
      ("list", "list the tests (SUITE/TEST) the run would run, and run none")
      ("test-timeout", po::value<std::string>(), "a time-out per test beside --timeout: a TcUnit test not finished that long after its start fails (the others go on); a test file's test that advanced the clock further fails; an FB_ASSERT unit staying longer in one state fails there")
      ("until", po::value<std::string>(), "scan the program until this ST condition holds (e.g. 'PRG_TEST.fbTest.bDone'), then report FB_ASSERT's failed assertions");
  add_coverage_export_options(desc);
  add_dialect_options(desc);
}

// --timeout, which must be positive. False after printing why.
bool timeout_option(const po::variables_map& vm, int64_t* timeout_ns) {
  std::string err;
  if (!rt::parse_duration(vm["timeout"].as<std::string>(), timeout_ns, &err) || *timeout_ns <= 0) {
    std::cerr << "plcfi test: --timeout: " << (err.empty() ? "must be positive" : err) << "\n";
    return false;
  }
  return true;
}

// The compile options of tests: the dialect, TcUnit's parameters, the test built-ins.
// False after printing why.
bool test_compile_options(const po::variables_map& vm, st::CompileOptions* opt) {
  apply_dialect_options(vm, opt);
  if (!tcunit_params(vm, &opt->tcunit_params)) return false;
  opt->test_mode = true;
  opt->warnings = false;
  // As `run`: the arms mark coverage only when a report or an export asks for it (then
  // every IF keeps its jumps); without, the tests run the code `plcfi run` runs.
  opt->coverage = vm.count("coverage") > 0 || coverage_export_wanted(vm);
  opt->loop_tails = !vm.count("native");
  opt->if_selects = !vm.count("native");
  return true;
}

// Test files or TcUnit suites among the inputs; false after saying there are none (and
// pointing FB_ASSERT tests to --until).
bool has_tests(const st::Build& b, bool tcunit) {
  if (!b.tests.empty() || tcunit) return true;
  std::cerr << "plcfi test: no tests among the inputs: neither a test file (it starts with TEST, SETUP or TEARDOWN) "
               "nor a TcUnit suite instance (of a function block that EXTENDS FB_TestSuite)"
            << (testing::has_fb_assert(*b.app) ? "; tests with FB_ASSERT run with --until EXPR (e.g. the test FB's bDone)" : "")
            << "\n";
  return false;
}

// --list: what would run, without running it.
int list_tests(const st::Build& b, const TestSelection& sel) {
  std::vector<std::string> names = testing::list_test_files(*b.app, sel.filter);
  for (auto& n : testing::list_tcunit(b, sel.filter)) names.push_back(std::move(n));
  for (const auto& n : names) std::cout << n << "\n";
  if (names.empty() && !sel.filter.empty()) return no_test_selected();
  return 0;
}

// The test files' tests, run and printed.
std::vector<testing::TestSuite> run_test_files(const po::variables_map& vm, const st::Application& app, st::Machine& m,
                                               const TestSelection& sel) {
  testing::TestRunOptions ro;
  ro.budget = vm["budget"].as<Count>().value;
  ro.filter = &sel.filter;
  ro.test_timeout_ns = sel.test_timeout_ns;
  std::vector<testing::TestSuite> suites = testing::test_file_suites(testing::run_tests(app, m, ro));
  report::print_tests(std::cout, suites);
  return suites;
}

}  // namespace

int cmd_test(const std::vector<std::string>& args) {
  po::options_description desc(
      "plcfi test: run ST unit tests: test files (sources and test files in any order) and TcUnit suites "
      "(function blocks that EXTEND FB_TestSuite, run by TcUnit.RUN())");
  add_test_options(desc);
  po::variables_map vm;
  if (!parse_args(args, desc, vm, "plcfi test SOURCES... TESTS... [--filter GLOB] [--list] [--junit FILE] [--coverage] [--lcov FILE] [--cobertura FILE] [--timeout 10s] [--test-timeout D] [--until EXPR] [--xunit FILE]")) return 0;
  int64_t timeout_ns = 0;
  TestSelection sel;
  st::CompileOptions opt;
  if (!check_coverage_paths(vm, "plcfi test") || !timeout_option(vm, &timeout_ns) || !test_selection(vm, &sel) ||
      !test_compile_options(vm, &opt))
    return 2;
  auto b = load(strings_of(vm, "files"), opt, "test");
  if (!b || !b->ok()) return 2;
  if (vm.count("until")) return run_until_mode(*b, vm, opt, timeout_ns, sel);
  const st::Application& app = *b->app;
  const bool tcunit = testing::has_tcunit_suites(app);
  if (!has_tests(*b, tcunit)) return 2;
  if (sel.list) return list_tests(*b, sel);
  rt::Schedule sched;
  if (tcunit && !tcunit_schedule(app, vm, &sched, "TcUnit suites run in the scan of the program that calls TcUnit.RUN()")) return 2;
  st::Machine m(app);
  std::unique_ptr<st::NativeCode> native;
  if (vm.count("native") && !(native = load_native(app, "plcfi test"))) return 2;
  m.set_native(native.get());
  m.set_count_hits(coverage_export_wanted(vm));
  std::vector<testing::TestSuite> suites;
  if (!b->tests.empty()) suites = run_test_files(vm, app, m, sel);
  bool tcunit_ok = true;
  if (tcunit) {
    if (int status = run_tcunit_suites(*b, opt, vm, sched, m, timeout_ns, sel, &suites, &tcunit_ok); status != 0)
      return status;
  } else if (vm.count("xunit")) {
    std::cerr << "plcfi test: --xunit writes TcUnit's xUnit file: there are no TcUnit suites among the inputs (use --junit)\n";
    return 2;
  }
  if (vm.count("coverage")) std::cout << st::coverage_report(app, m.covered());
  const testing::Totals totals = testing::totals(suites);
  std::cout << report::totals_line(totals) << "\n";
  if (totals.all() == 0 && !sel.filter.empty()) return no_test_selected();
  if (!write_junit_of(vm, suites)) return 2;
  if (coverage_export_wanted(vm) &&
      !write_coverage_exports(vm, app, m.hits(), report::coverage_files(*b), "plcfi_test", "plcfi test"))
    return 2;
  return totals.failed || !tcunit_ok ? 1 : 0;
}

}  // namespace plcfi::cli
