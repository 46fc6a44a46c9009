// plcfi generate / plcfi campaign: test cases from TSD and FMEA, and the passive
// fault-injection campaign on the plant model.
#include <algorithm>
#include <filesystem>
#include <tuple>
#include <fstream>
#include <iostream>
#include <optional>

#include <unistd.h>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "campaign/driver.hpp"
#include "campaign/explore.hpp"
#include "campaign/generate.hpp"
#include "campaign/parallel.hpp"
#include "campaign/safety.hpp"
#include "common/file.hpp"
#include "commands.hpp"
#include "options.hpp"
#include "coverage_opts.hpp"
#include "json.hpp"
#include "report/campaign.hpp"
#include "report/campaign_html.hpp"

#include "io/devices/device_io.hpp"
#include <sstream>

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {

using campaign::CampaignBuild;
using campaign::TestCase;

bool write_diagrams(const CampaignBuild& cb, const std::string& dir, std::string* err) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    *err = dir + ": " + ec.message();
    return false;
  }
  for (const auto& tc : cb.cases) {
    auto p = report::campaign_puml_case(cb, tc);
    for (const auto& [suffix, text] : {std::pair{"sequence", report::sequence_diagram(p)}, {"timing", report::timing_diagram(p)}}) {
      std::string path = (std::filesystem::path(dir) / fmt::format("{}_{}.puml", tc.id, suffix)).string();
      std::ofstream f(path);
      f << text;
      if (!f) {
        *err = path + ": cannot write";
        return false;
      }
    }
  }
  return true;
}

// Loads and generates; prints errors and returns false (exit 2) when the specs are bad.
bool load_and_prepare(const std::string& path, const std::vector<std::string>& programs, const uint64_t* seed,
                      CampaignBuild* cb, const std::string& plant = "", bool explore = false) {
  campaign::Campaign spec;
  std::string err;
  if (!campaign::load_campaign(path, &spec, &err)) {
    std::cerr << err << "\n";
    return false;
  }
  if (!programs.empty()) spec.programs = programs;
  if (seed) spec.seed = *seed;
  if (explore) spec.explore.enabled = true;
  if (!plant.empty()) {
    spec.plant = plant;  // as given on the command line: relative to the working folder
    spec.plant_config.clear();
  }
  if (!campaign::prepare_campaign(std::move(spec), cb, &err)) {
    std::cerr << err << (err.empty() || err.back() == '\n' ? "" : "\n");
    return false;
  }
  return true;
}

void print_cases(const CampaignBuild& cb) { std::cout << report::campaign_cases_text(cb); }

// Milliseconds as JSON: an integer when whole (600, not 600.0), else a fraction.
Json json_ms(int64_t ns) {
  if (ns % 1'000'000 == 0) return ns / 1'000'000;
  return static_cast<double>(ns) * 1e-6;
}

// One case per line, in a JSON array.
std::string json_cases(const CampaignBuild& cb) {
  std::string o = "[\n";
  for (size_t i = 0; i < cb.cases.size(); ++i) {
    const auto& tc = cb.cases[i];
    Json j;
    j["id"] = tc.id;
    j["fmea"] = tc.row->id;
    if (tc.explored) j["explore"] = true;
    j["rpn"] = tc.rpn;
    j["fault_class"] = tc.cls->id;
    j["transition"] = tc.transition_ref();
    j["failure_mode"] = tc.row->failure_mode;
    j["precondition"] = tc.precondition;
    j["start"] = tc.start;
    j["target"] = tc.target->name;
    j["address"] = tc.target_ref.text;
    j["fault"] = tc.fault.text;
    j["alarm"] = tc.row->alarm;
    j["expected"] = tc.expected;
    j["deadline_ms"] = json_ms(tc.deadline_ns);
    j["max_duration_ms"] = json_ms(tc.max_duration_ns);
    o += "  " + json_line(j) + (i + 1 < cb.cases.size() ? ",\n" : "\n");
  }
  return o + "]\n";
}

// Explored cases that failed, as FMEA rows: listed and written to OUT/fmea_suggestions.csv.
bool print_suggestions(const CampaignBuild& cb, const campaign::CampaignResult& res, const std::string& out) {
  auto sug = campaign::fmea_suggestions(cb, res.executions);
  std::string path = (std::filesystem::path(out) / "fmea_suggestions.csv").string();
  std::ofstream f(path);
  f << campaign::fmea_suggestions_csv(sug);
  if (!f) {
    std::cerr << "plcfi campaign: " << path << ": cannot write\n";
    return false;
  }
  std::cout << report::fmea_suggestions_text(sug, path);
  return true;
}

// Parses the common arguments; returns 0 to go on, else the exit status (help, usage).
int parse(const std::string& cmd, const std::string& usage, po::options_description& desc, const std::vector<std::string>& args,
          po::variables_map* vm) {
  if (!parse_args(args, desc, *vm, usage, "campaign-file")) return -1;
  if (!vm->count("campaign-file") || (*vm)["campaign-file"].as<std::vector<std::string>>().size() != 1) {
    std::cerr << "plcfi " << cmd << ": expected one campaign file\nusage: " << usage << "\n";
    return 2;
  }
  return 0;
}

}  // namespace

int cmd_generate(const std::vector<std::string>& args) {
  const std::string usage = "plcfi generate CAMPAIGN.yaml [--json] [--puml DIR] [--program FILE...] [--explore]";
  po::options_description desc("plcfi generate: the prioritized test set of a campaign (one case per TSD transition with an FMEA row)");
  desc.add_options()
      ("json", "print the test cases as JSON")
      ("puml", po::value<std::string>(), "write a PlantUML sequence and timing diagram per case into DIR")
      ("program", po::value<std::vector<std::string>>()->multitoken(), "program files instead of the campaign's")
      ("explore", "add the explored cases: every signal of every TSD step under each applicable fault model");
  po::variables_map vm;
  if (int s = parse("generate", usage, desc, args, &vm)) return s < 0 ? 0 : s;
  CampaignBuild cb;
  std::vector<std::string> programs;
  if (vm.count("program")) programs = vm["program"].as<std::vector<std::string>>();
  if (!load_and_prepare(vm["campaign-file"].as<std::vector<std::string>>()[0], programs, nullptr, &cb, "", vm.count("explore") > 0))
    return 2;
  if (vm.count("json")) std::cout << json_cases(cb);
  else print_cases(cb);
  if (vm.count("puml")) {
    std::string err;
    if (!write_diagrams(cb, vm["puml"].as<std::string>(), &err)) {
      std::cerr << "plcfi generate: " << err << "\n";
      return 2;
    }
    if (!vm.count("json"))
      std::cout << fmt::format("\nwrote {} diagrams to {}\n", 2 * cb.cases.size(), vm["puml"].as<std::string>());
  }
  return 0;
}

namespace {

// The options of `plcfi campaign`.
void add_campaign_options(po::options_description& desc) {
  desc.add_options()
      ("out", po::value<std::string>(), "output folder: results.jsonl, VCD per test, diagrams (default plcfi-out/<campaign>-<program>)")
      ("resume", "finish a campaign whose journal is in the output folder (no case runs twice)")
      ("junit", po::value<std::string>(), "write JUnit XML")
      ("program", po::value<std::vector<std::string>>()->multitoken(), "program files instead of the campaign's")
      ("plant", po::value<std::string>(), "plant instead of the campaign's: a built-in plant's name or a plant file (FMU, ST)")
      ("seed", po::value<Count>(), "seed instead of the campaign's")
      ("explore", "also test the failures the FMEA forgot (explored cases X1...); failed ones become FMEA suggestions")
      ("no-vcd", "no VCD trace per test")
      ("html", po::value<std::string>(), "write a self-contained HTML report (DIR/index.html): verdicts, waveforms, TSD")
      ("quiet", "no live progress line")
      ("io", po::value<std::string>(), "run on real I/O: a file with an io: section (instead of the campaign's io: or plant)")
      ("arm", "allow fault injection on real I/O (required with io:)")
      ("realtime", "pace the scans in real time (always on with real I/O); report wake latency, execution time, overruns")
      ("rt-priority", po::value<RtPriority>()->default_value(RtPriority{0}, "0"), "with real time: SCHED_FIFO priority (1..99; 0 keeps the normal scheduler)")
      ("cpu", po::value<CpuIndex>()->default_value(CpuIndex{-1}, "-1"), "with real time: pin the scan thread to this CPU")
      ("native", "run program, preconditions and monitors through the native tier")
      ("jobs", po::value<IntIn<1, 256>>(), "run the tests on N worker processes; the journal is the one --jobs 1 writes")
      ("baseline", po::value<std::string>(), "an earlier run's output folder: report what changed in verdicts, DC and worst "
                                             "reaction time (its safety.json; needs an FMEA with failure_rate)")
      ("fail-on-regression", "with --baseline: exit 1 when something got worse (a PASS lost, a lower DC, a longer worst reaction, ...)")
      ("shard", po::value<std::string>(), "run share K of N (K = 0..N-1) into OUT/shard-K-of-N.jsonl; `plcfi merge` "
                                          "combines the N shard files into the campaign's journal");
  add_coverage_export_options(desc);
}

// The command line, checked: how the runs are split, where the results go, what they are
// compared with.
struct CampaignArgs {
  int jobs = 1;
  int shard_k = 0, shard_n = 0;  // shard_n 0: no --shard
  std::string out;
  std::optional<report::SafetyReport> baseline;  // --baseline: the earlier run's evidence
  bool live = false;                             // the progress line on stderr
};

// --jobs and --shard, and the options that do not go with them. False after printing why.
bool split_options(const po::variables_map& vm, CampaignArgs* a) {
  a->jobs = vm.count("jobs") ? static_cast<int>(vm["jobs"].as<IntIn<1, 256>>().value) : 1;
  if (vm.count("shard")) {
    std::string why;
    if (!campaign::parse_share(vm["shard"].as<std::string>(), &a->shard_k, &a->shard_n, &why)) {
      std::cerr << "plcfi campaign: --shard " << why << "\n";
      return false;
    }
    for (const char* o : {"jobs", "resume", "junit", "html", "lcov", "cobertura", "io", "realtime"})
      if (vm.count(o)) {
        std::cerr << "plcfi campaign: --shard runs one share of an offline campaign; --" << o
                  << " does not go with it (run `plcfi merge` on the shard files, then look at the journal)\n";
        return false;
      }
  }
  if (a->jobs > 1)
    for (const char* o : {"io", "realtime", "lcov", "cobertura"})
      if (vm.count(o)) {
        std::cerr << "plcfi campaign: --jobs splits an offline campaign between processes; --" << o
                  << (std::string(o) == "io" || std::string(o) == "realtime" ? " runs on one machine's real time"
                                                                              : " counts the scans of one process")
                  << ": drop --jobs\n";
        return false;
      }
  return true;
}

// The campaign file with the command line's --program, --seed, --plant and --explore,
// prepared. False after printing why.
bool load_with_options(const po::variables_map& vm, CampaignBuild* cb) {
  std::vector<std::string> programs;
  if (vm.count("program")) programs = vm["program"].as<std::vector<std::string>>();
  uint64_t seed = vm.count("seed") ? vm["seed"].as<Count>().value : 0;
  return load_and_prepare(vm["campaign-file"].as<std::vector<std::string>>()[0], programs, vm.count("seed") ? &seed : nullptr, cb,
                          vm.count("plant") ? vm["plant"].as<std::string>() : "", vm.count("explore") > 0);
}

// Runs split between processes (--jobs, --shard) need an offline campaign that restarts
// cold. False after printing why.
bool splittable(const CampaignArgs& a, const campaign::Campaign& c) {
  if (a.jobs <= 1 && a.shard_n == 0) return true;
  if (!c.io.empty()) {
    std::cerr << "plcfi campaign: " << c.path << ": the campaign runs on real I/O (io: " << c.io
              << "); --jobs and --shard split offline campaigns only\n";
    return false;
  }
  if (c.restart == campaign::RestartKind::Warm) {
    std::cerr << "plcfi campaign: " << c.path
              << ": restart: warm carries each run's retained state into the next run, so the runs cannot be split "
                 "between processes; use restart: cold for --jobs or --shard\n";
    return false;
  }
  return true;
}

// --out, else plcfi-out/<campaign>-<program>.
std::string out_dir(const po::variables_map& vm, const campaign::Campaign& c) {
  return vm.count("out") ? vm["out"].as<std::string>()
                         : (std::filesystem::path("plcfi-out") /
                            (c.name + "-" + std::filesystem::path(c.programs.back()).stem().string()))
                               .string();
}

// --baseline (and --fail-on-regression, which needs it) into a->baseline. The baseline is
// read before the campaign runs: a wrong folder is a usage error, not a surprise after an
// hour of testing. False after printing why.
bool read_baseline(const po::variables_map& vm, const campaign::Campaign& c, CampaignArgs* a) {
  if (vm.count("fail-on-regression") && !vm.count("baseline")) {
    std::cerr << "plcfi campaign: --fail-on-regression compares with an earlier run: add --baseline OLD_OUT\n";
    return false;
  }
  if (!vm.count("baseline")) return true;
  if (a->shard_n > 0) {
    std::cerr << "plcfi campaign: --baseline compares a whole campaign; it does not go with --shard\n";
    return false;
  }
  if (!campaign::wants_safety_evidence(c)) {
    std::cerr << "plcfi campaign: --baseline compares safety evidence, and " << c.fmea.path
              << " has no failure_rate column (see docs/pages/reports/safety.md)\n";
    return false;
  }
  std::string path = (std::filesystem::path(vm["baseline"].as<std::string>()) / "safety.json").string(), text, err;
  a->baseline.emplace();
  if (!common::read_file(path, common::kMaxSpecBytes, &text, &err) || !report::parse_safety_json(text, path, &*a->baseline, &err)) {
    std::cerr << "plcfi campaign: --baseline: " << err << "\n";
    return false;
  }
  return true;
}

// The output folders, before a long campaign rather than after it: the HTML report's is
// writable, the diagrams are written. False after printing why.
bool prepare_outputs(const po::variables_map& vm, const CampaignBuild& cb, const std::string& out) {
  std::string err;
  if (vm.count("html") && !report::html_dir_writable(vm["html"].as<std::string>(), &err)) {
    std::cerr << "plcfi campaign: " << err << "\n";
    return false;
  }
  if (!write_diagrams(cb, (std::filesystem::path(out) / "diagrams").string(), &err)) {
    std::cerr << "plcfi campaign: " << err << "\n";
    return false;
  }
  return true;
}

// A test's verdict, printed as it ends.
void print_verdict_line(const CampaignBuild& cb, const campaign::Execution& e) {
  std::cout << fmt::format("  [run {:>2}, t={:7.3f} s] {} path {} {}: {}\n", e.run, static_cast<double>(e.inject_ns) * 1e-9,
                           e.case_id, e.path, campaign::outcome_name(e.outcome), cb.cases[e.case_index].transition_ref())
            << std::flush;
}

// The driver's options from the command line. With a.live, a progress line on stderr that
// each verdict line clears and writes again.
campaign::DriverOptions driver_options(const po::variables_map& vm, const CampaignBuild& cb, const CampaignArgs& a,
                                       const st::NativeCode* native, std::vector<uint64_t>* branch_hits) {
  campaign::DriverOptions opt;
  opt.native = native;
  opt.out_dir = a.out;
  opt.resume = vm.count("resume") > 0;
  opt.vcd = !vm.count("no-vcd");
  if (coverage_export_wanted(vm)) opt.branch_hits = branch_hits;
  auto progress_line = [live = a.live](const campaign::Progress& p) {
    if (!live) return;
    std::cerr << fmt::format("\r  run {:>3}  cases tested {}/{}  PASS {}  FAIL {}  t = {:.1f} s   ", p.run, p.cases_tested,
                             p.cases, p.pass, p.fail, static_cast<double>(p.campaign_ns) * 1e-9)
              << std::flush;
  };
  opt.on_progress = progress_line;
  opt.on_verdict = [&cb, live = a.live, progress_line](const campaign::Execution& e, const campaign::Progress& p) {
    if (live) std::cerr << "\r" << std::string(72, ' ') << "\r";
    print_verdict_line(cb, e);
    progress_line(p);
  };
  return opt;
}

// --shard K/N: this share's runs into OUT/shard-K-of-N.jsonl (`plcfi merge` makes the
// journal of the N files), verdict lines without the progress line.
int run_shard(CampaignBuild& cb, const CampaignArgs& a, campaign::DriverOptions opt) {
  opt.on_progress = nullptr;
  opt.on_verdict = [&cb](const campaign::Execution& e, const campaign::Progress&) { print_verdict_line(cb, e); };
  const std::string shard_path =
      (std::filesystem::path(a.out) / fmt::format("shard-{}-of-{}.jsonl", a.shard_k, a.shard_n)).string();
  campaign::ShardSummary sum;
  std::string err;
  if (!campaign::run_campaign_shard(cb, a.shard_k, a.shard_n, opt, shard_path, &sum, &err)) {
    std::cerr << "plcfi campaign: " << err << "\n";
    return 2;
  }
  std::cout << fmt::format("\nshard {}/{}: {} run(s) searched, {} tested here: {} PASS, {} FAIL; stopped: {}\n", a.shard_k,
                           a.shard_n, sum.runs, sum.executions, sum.pass, sum.fail, sum.end_reason);
  std::cout << fmt::format("shard file {}; combine the {} shard files with: plcfi merge --out DIR FILES...\n", shard_path,
                           a.shard_n);
  return 0;
}

// What a finished campaign leaves for the summary and the reports.
struct Finished {
  campaign::CampaignResult res;
  std::vector<std::string> io_report;  // real I/O: the devices' figures
};

// The devices of the io file, opened for a campaign on real I/O. Null after printing why:
// no --arm, a bad io file, devices that cannot be opened.
std::unique_ptr<io::DeviceIo> open_devices(const std::string& io_path, bool armed, const CampaignBuild& cb, io::IoConfig* cfg) {
  if (!armed) {
    std::cerr << "plcfi campaign: refusing to inject faults on real I/O (" << io_path
              << ") without --arm: the campaign forces sensor values and suppresses or changes actuator commands on the "
                 "machine. Make sure the bench is safe to run and that stopping it is possible, then add --arm.\n";
    return nullptr;
  }
  std::string err;
  if (!io::load_io_config(io_path, *cb.build->app, cfg, &err)) {
    std::cerr << err << "\n";
    return nullptr;
  }
  auto backend = io::DeviceIo::open(*cfg, cb.schedule.tick_ns(), &err);
  if (!backend) std::cerr << err << "\n";
  return backend;
}

// The campaign on the bench, in real time: a stop signal or a lost device withdraws the
// fault and writes the safe state. The devices are closed after it.
bool run_on_devices(io::DeviceIo& bench, const io::IoConfig& cfg, const std::string& io_path, CampaignBuild& cb,
                  const rt::RealtimeOptions& rto, std::optional<rt::StopSignals>& signals, campaign::DriverOptions& opt,
                  Finished* f, std::string* err) {
  signals.emplace();
  opt.realtime = true;
  warn_realtime_setup(rto, "plcfi campaign");
  opt.signals = &*signals;
  auto* lost = &bench;
  opt.io_lost = [lost] { return lost->lost(); };
  opt.safe_state = cfg.safe_state;
  std::cout << fmt::format("  armed: real I/O over {} in real time; SIGINT/SIGTERM withdraw the fault and write the safe state\n",
                           io_path);
  bool ran = campaign::run_campaign_on(cb, &bench, opt, &f->res, err);
  bench.close();
  f->io_report = bench.report();
  return ran;
}

// The campaign on the plant model: in virtual time, or with --realtime at the speed of the
// real plant (a rehearsal of the bench run); with --jobs on worker processes.
bool run_offline(bool realtime, CampaignBuild& cb, const CampaignArgs& a, const rt::RealtimeOptions& rto,
                 std::optional<rt::StopSignals>& signals, campaign::DriverOptions& opt, Finished* f, std::string* err) {
  if (realtime) {
    signals.emplace();
    opt.realtime = true;
    opt.signals = &*signals;
    warn_realtime_setup(rto, "plcfi campaign");
  }
  if (a.jobs > 1) {
    if (a.live) std::cerr << fmt::format("  {} worker processes\n", a.jobs);
    opt.on_progress = nullptr;
    return campaign::run_campaign_jobs(cb, a.jobs, opt, &f->res, err);
  }
  return campaign::run_campaign(cb, opt, &f->res, err);
}

// Runs the campaign on real I/O (--io or the campaign's io:) or on the plant model. The
// stop signals of a real-time run go into `signals`, installed until the command ends.
// False after printing why.
bool run(const po::variables_map& vm, CampaignBuild& cb, const CampaignArgs& a, std::optional<rt::StopSignals>& signals,
         campaign::DriverOptions& opt, Finished* f) {
  std::string io_path = vm.count("io") ? vm["io"].as<std::string>() : cb.spec.io;
  rt::RealtimeOptions rto;
  rto.priority = static_cast<int>(vm["rt-priority"].as<RtPriority>().value);
  rto.cpu = static_cast<int>(vm["cpu"].as<CpuIndex>().value);
  std::string err;
  bool ran = false;
  if (!io_path.empty()) {
    io::IoConfig cfg;
    auto bench = open_devices(io_path, vm.count("arm") > 0, cb, &cfg);
    if (!bench) return false;
    ran = run_on_devices(*bench, cfg, io_path, cb, rto, signals, opt, f, &err);
  } else {
    ran = run_offline(vm.count("realtime") > 0, cb, a, rto, signals, opt, f, &err);
  }
  if (!ran) {
    if (a.live) std::cerr << "\n";
    std::cerr << "plcfi campaign: " << err << "\n";
    return false;
  }
  return true;
}

// The totals, the run's figures (scans, time, real-time and I/O figures) and where the
// files are.
void print_totals(const CampaignBuild& cb, const Finished& f, size_t fail, const std::string& out) {
  std::cout << report::campaign_totals_text(cb, f.res, f.io_report, fail, out);
}

// Safety evidence, only when the FMEA gives failure rates (else nothing changes): into
// *safety, OUT/safety.json and OUT/traceability.csv, and printed. False after printing why.
bool write_safety_evidence(const CampaignBuild& cb, const campaign::CampaignResult& res, const std::string& out, bool vcd,
                           std::optional<report::SafetyReport>* safety) {
  if (!campaign::wants_safety_evidence(cb.spec)) return true;
  *safety = campaign::safety_evidence(cb, res.executions, res.not_reached, res.pending, vcd);
  for (const auto& [name, text] : {std::pair{"safety.json", report::safety_json(**safety)},
                                   {"traceability.csv", report::traceability_csv(**safety)}}) {
    std::string path = (std::filesystem::path(out) / name).string();
    std::ofstream f(path, std::ios::binary);
    f << text;
    if (!f) {
      std::cerr << "plcfi campaign: " << path << ": cannot write\n";
      return false;
    }
  }
  std::cout << report::safety_text(**safety, out);
  return true;
}

// What changed since the baseline (the folder `old`), printed; returns the regressions.
size_t print_baseline_changes(const report::SafetyReport& baseline, const report::SafetyReport& now, const std::string& old) {
  size_t regressions = 0;
  std::cout << report::baseline_changes_text(report::compare_safety(baseline, now), old, &regressions);
  return regressions;
}

// --junit: one suite, the executions, then the cases not tested and not reached; the run's
// figures and the safety evidence as properties. False after printing why.
bool write_campaign_junit(const std::string& path, const CampaignBuild& cb, const Finished& f,
                          const std::optional<report::SafetyReport>& safety) {
  std::string err;
  if (!report::write_junit(path, {report::campaign_junit(cb, f.res, f.io_report, safety)}, &err)) {
    std::cerr << "plcfi campaign: " << err << "\n";
    return false;
  }
  return true;
}

// --html DIR: the report with the safety evidence. False after printing why.
bool write_campaign_html(const std::string& dir, const CampaignBuild& cb, const campaign::CampaignResult& res,
                         const std::string& out, bool vcd, const std::optional<report::SafetyReport>& safety) {
  auto model = report::campaign_html_model(cb, res, out, vcd);
  model.safety = safety;
  std::string err;
  if (!report::write_html_report(model, dir, &err)) {
    std::cerr << "plcfi campaign: " << err << "\n";
    return false;
  }
  std::cout << "HTML report: " << (std::filesystem::path(dir) / "index.html").string() << "\n";
  return true;
}

// The reports asked for after the run: --junit, --html, --lcov and --cobertura. False after
// printing why.
bool write_reports(const po::variables_map& vm, const CampaignBuild& cb, const Finished& f, const std::string& out, bool vcd,
                   const std::optional<report::SafetyReport>& safety, const std::vector<uint64_t>& branch_hits) {
  if (vm.count("junit") && !write_campaign_junit(vm["junit"].as<std::string>(), cb, f, safety)) return false;
  if (vm.count("html") && !write_campaign_html(vm["html"].as<std::string>(), cb, f.res, out, vcd, safety)) return false;
  return !coverage_export_wanted(vm) ||
         write_coverage_exports(vm, *cb.build->app, branch_hits, cb.program_files, "campaign_" + cb.spec.name, "plcfi campaign");
}

// 1 when the campaign is incomplete, got worse than the baseline (--fail-on-regression), or
// a case failed or was not reached; else 0.
int campaign_status(const po::variables_map& vm, const campaign::CampaignResult& res, size_t fail, size_t regressions) {
  if (res.interrupted) {
    std::cout << "campaign incomplete (" << res.end_reason << "); finish it with --resume\n";
    return 1;
  }
  if (regressions && vm.count("fail-on-regression")) {
    std::cout << fmt::format("{} regression(s) since {}: failing (--fail-on-regression)\n", regressions,
                             vm["baseline"].as<std::string>());
    return 1;
  }
  return fail || !res.not_reached.empty() ? 1 : 0;
}

}  // namespace

int cmd_campaign(const std::vector<std::string>& args) {
  const std::string usage =
      "plcfi campaign CAMPAIGN.yaml [--out DIR] [--resume] [--junit F] [--program FILE...] [--plant PLANT] [--seed N] [--explore] [--no-vcd] [--html DIR] [--quiet] [--io FILE --arm] [--realtime [--rt-priority N] [--cpu N]] [--jobs N | --shard K/N] [--baseline OLD_OUT [--fail-on-regression]]";
  po::options_description desc("plcfi campaign: passive fault-injection campaign on the plant model (virtual time) or, with --io and --arm, on real I/O in real time");
  add_campaign_options(desc);
  po::variables_map vm;
  if (int s = parse("campaign", usage, desc, args, &vm)) return s < 0 ? 0 : s;
  CampaignArgs a;
  if (!check_coverage_paths(vm, "plcfi campaign") || !split_options(vm, &a)) return 2;
  CampaignBuild cb;
  if (!load_with_options(vm, &cb) || !splittable(a, cb.spec)) return 2;
  const auto& c = cb.spec;
  a.out = out_dir(vm, c);
  if (!read_baseline(vm, c, &a) || !prepare_outputs(vm, cb, a.out)) return 2;
  std::cout << fmt::format("plcfi campaign {}: {} test case(s), program {}, plant {}, seed {}\n", c.name, cb.cases.size(),
                           c.programs.back(), c.plant, c.seed);
  a.live = !vm.count("quiet") && isatty(STDERR_FILENO);
  std::unique_ptr<st::NativeCode> native;
  if (vm.count("native") && !(native = load_native(*cb.build->app, "plcfi campaign"))) return 2;
  std::vector<uint64_t> branch_hits;  // --lcov/--cobertura
  campaign::DriverOptions opt = driver_options(vm, cb, a, native.get(), &branch_hits);
  if (a.shard_n > 0) return run_shard(cb, a, opt);

  Finished f;
  std::optional<rt::StopSignals> signals;  // installed for real-time runs only
  if (!run(vm, cb, a, signals, opt, &f)) return 2;
  if (a.live) std::cerr << "\r" << std::string(72, ' ') << "\r";
  if (f.res.resumed) std::cout << fmt::format("  resumed: {} verdict(s) read from {}/results.jsonl\n", f.res.resumed, a.out);
  size_t fail = 0;
  std::cout << report::campaign_verdict_table(cb, f.res, &fail);
  print_totals(cb, f, fail, a.out);
  if (c.explore.enabled && !print_suggestions(cb, f.res, a.out)) return 2;
  std::optional<report::SafetyReport> safety;
  if (!write_safety_evidence(cb, f.res, a.out, opt.vcd, &safety)) return 2;
  const size_t regressions = a.baseline ? print_baseline_changes(*a.baseline, *safety, vm["baseline"].as<std::string>()) : 0;
  if (!write_reports(vm, cb, f, a.out, opt.vcd, safety, branch_hits)) return 2;
  return campaign_status(vm, f.res, fail, regressions);
}

}  // namespace plcfi::cli
