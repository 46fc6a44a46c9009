// plcfi plant-server: a plant model in real time behind a Modbus TCP server.
#include <atomic>
#include <csignal>
#include <cstring>
#include <iostream>

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>
#include <sys/mman.h>
#include <sys/prctl.h>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "engine.hpp"
#include "plant_model/plant.hpp"
#include "report/junit.hpp"
#include "runtime/clock.hpp"
#include "runtime/runtime.hpp"
#include "runtime/schedule.hpp"

#include "io/bench/bench_io.hpp"
#ifdef PLCFI_HAVE_MODBUS
#include "io/modbus/plant_server.hpp"
#endif

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {
std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
void on_signal(int s) {
  g_signal.store(s);
  g_stop.store(true);
}

}  // namespace

// Real-time set-up of the scan thread; each step that fails is reported and skipped (a
// bench run without privileges still runs, with worse latency).
void realtime_setup(const RealtimeOptions& o, const char* who) {
  prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);
  // Keep the CPUs out of deep idle states while the run lasts (PM QoS, as cyclictest
  // does): the request holds while the file stays open, so it is never closed here.
  static int dma_latency = -1;
  if (dma_latency < 0) {
    dma_latency = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    int32_t zero = 0;
    if (dma_latency >= 0 && ::write(dma_latency, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
      ::close(dma_latency);
      dma_latency = -1;
    }
  }
  if (o.lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    std::cerr << who << ": warning: mlockall: " << std::strerror(errno) << " (page faults may add latency)\n";
  if (o.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(o.cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0)
      std::cerr << who << ": warning: CPU affinity " << o.cpu << ": " << std::strerror(errno) << "\n";
  }
  if (o.priority > 0) {
    sched_param sp{};
    sp.sched_priority = o.priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
      std::cerr << who << ": warning: SCHED_FIFO priority " << o.priority << ": " << std::strerror(errno) << "\n";
  }
}

int run_with_io(const st::Application& app, const rt::Schedule& sched, const std::string& io_path, const RunIoOptions& o,
                const std::function<bool(st::Machine&)>& setup, const std::function<void(st::Machine&, int)>& report) {
  std::string err;
  io::IoConfig cfg;
  std::unique_ptr<io::BenchIo> backend;
  if (!io_path.empty()) {  // without an io file: the pacing alone (latency measurements)
    if (!io::load_io_config(io_path, app, &cfg, &err)) {
      std::cerr << err << "\n";
      return 2;
    }
    backend = io::BenchIo::open(cfg, sched.tick_ns(), &err);
    if (!backend) {
      std::cerr << err << "\n";
      return 2;
    }
  }
  rt::Runtime runtime(app, sched, backend.get());
  runtime.machine().set_native(o.native);
  runtime.set_safe_state(cfg.safe_state);
  runtime.cold_restart(1);
  if (!setup(runtime.machine())) {
    runtime.write_safe_outputs();
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);
  if (o.realtime) realtime_setup(o.rt, "plcfi run");
  rt::RealTimePacer pacer(sched.tick_ns());
  pacer.start();
  uint64_t scans = 0;
  int status = 0;
  std::string why = "done";
  const int64_t t0 = rt::RealTimePacer::monotonic_ns();
  while (true) {
    if (g_stop.load()) {
      why = g_signal.load() == SIGTERM ? "SIGTERM" : "SIGINT";
      break;
    }
    if (o.cycles && scans >= o.cycles) break;
    if (o.duration_ns && rt::RealTimePacer::monotonic_ns() - t0 >= o.duration_ns) break;
    if (o.realtime) pacer.wait_next();
    int64_t a = rt::RealTimePacer::monotonic_ns();
    rt::ScanStatus st = runtime.scan();
    pacer.record_exec(rt::RealTimePacer::monotonic_ns() - a);
    ++scans;
    if (st == rt::ScanStatus::Trapped) {
      why = "trap: " + runtime.stop_reason();
      status = 1;
      break;
    }
    std::string lost = backend ? backend->lost() : "";
    if (!lost.empty()) {
      why = "communication lost: " + lost;
      status = 1;
      break;
    }
  }
  // Every way out: the safe output state reaches the devices before they are closed.
  runtime.write_safe_outputs();
  if (backend) backend->close();
  std::cout << fmt::format("plcfi run: {} scans of {} ms over {}, ended: {}; outputs written to the safe state{}\n", scans,
                           static_cast<double>(sched.tick_ns()) / 1e6, backend ? cfg.path : "no I/O", why,
                           cfg.safe_state.empty() ? " (all off)" : fmt::format(" (all off but {})", cfg.safe_state.size()));
  if (o.realtime)
    std::cout << fmt::format("  wake latency   {}\n  execution      {}\n  overruns       {}\n", pacer.wake_latency().summary(),
                             pacer.exec_time().summary(), pacer.overruns());
  if (backend)
    for (const auto& line : backend->report()) std::cout << "  " << line << "\n";
  report(runtime.machine(), status);
  if (!o.junit.empty()) {
    report::JunitSuite suite;
    suite.name = "run";
    report::JunitCase jc;
    jc.classname = "run";
    jc.name = backend ? "scan cycle on " + cfg.path : "scan cycle";
    jc.seconds = static_cast<double>(rt::RealTimePacer::monotonic_ns() - t0) * 1e-9;
    if (status != 0) {
      jc.outcome = report::JunitCase::Outcome::Fail;
      jc.message = why;
    }
    jc.properties.emplace_back("scans", std::to_string(scans));
    jc.properties.emplace_back("ended", why);
    if (o.realtime)
      for (const auto& p : pacer.properties()) suite.properties.push_back(p);
    if (backend) {
      int n = 0;
      for (const auto& line : backend->report()) suite.properties.emplace_back(fmt::format("io_{}", n++), line);
    }
    suite.cases.push_back(jc);
    if (!report::write_junit(o.junit, {suite}, &err)) {
      std::cerr << "plcfi run: " << err << "\n";
      return 2;
    }
  }
  return status;
}

int cmd_plant_server(const std::vector<std::string>& args) {
  po::options_description desc("plcfi plant-server: a plant model in real time behind a Modbus TCP server");
  desc.add_options()
      ("plant", po::value<std::string>()->default_value("stamping"), "plant model")
      ("plant-config", po::value<std::string>(), "plant parameters (YAML)")
      ("listen", po::value<std::string>()->default_value("127.0.0.1:1502"), "address and port (HOST:PORT, [V6]:PORT); loopback by default")
      ("tick", po::value<std::string>()->default_value("1ms"), "plant step in real time")
      ("duration", po::value<std::string>(), "stop after this long (default: until SIGINT/SIGTERM)")
      ("seed", po::value<uint64_t>()->default_value(1), "seed of the plant's random variation")
      ("help,h", "show this help");
  po::variables_map vm;
  po::store(po::command_line_parser(args).options(desc).run(), vm);
  po::notify(vm);
  if (vm.count("help")) {
    std::cout << "usage: plcfi plant-server [--plant stamping] [--listen 127.0.0.1:1502] [--tick 1ms] [--duration T]\n\n"
              << desc << "\nRegister map: a sensor on %IXb.i is discrete input 8b+i, on %IWn input register n;\n"
                         "an actuator on %QXb.i is coil 8b+i, on %QWn holding register n (the plant's I/O map).\n";
    return 0;
  }
#ifndef PLCFI_HAVE_MODBUS
  std::cerr << "plcfi plant-server: this plcfi was built without Modbus (PLCFI_MODBUS=OFF)\n";
  return 2;
#else
  std::string err;
  io::PlantServerOptions opt;
  std::string listen = vm["listen"].as<std::string>();
  size_t colon = listen.rfind(':');
  if (!listen.empty() && listen[0] == '[') {
    size_t close = listen.find(']');
    if (close == std::string::npos || close + 1 >= listen.size() || listen[close + 1] != ':') {
      std::cerr << "plcfi plant-server: --listen: expected [ADDRESS]:PORT, got '" << listen << "'\n";
      return 2;
    }
    opt.host = listen.substr(1, close - 1);
    opt.port = listen.substr(close + 2);
  } else if (colon == std::string::npos || colon == 0 || colon + 1 == listen.size()) {
    std::cerr << "plcfi plant-server: --listen: expected HOST:PORT, got '" << listen << "'\n";
    return 2;
  } else {
    opt.host = listen.substr(0, colon);
    opt.port = listen.substr(colon + 1);
  }
  if (!rt::parse_duration(vm["tick"].as<std::string>(), &opt.tick_ns, &err) || opt.tick_ns <= 0) {
    std::cerr << "plcfi plant-server: --tick: " << (err.empty() ? "must be positive" : err) << "\n";
    return 2;
  }
  if (vm.count("duration") && (!rt::parse_duration(vm["duration"].as<std::string>(), &opt.duration_ns, &err) || opt.duration_ns <= 0)) {
    std::cerr << "plcfi plant-server: --duration: " << (err.empty() ? "must be positive" : err) << "\n";
    return 2;
  }
  opt.seed = vm["seed"].as<uint64_t>();
  auto plant = plant::make_plant(vm["plant"].as<std::string>(), vm.count("plant-config") ? vm["plant-config"].as<std::string>() : "", &err);
  if (!plant) {
    std::cerr << "plcfi plant-server: " << err << "\n";
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);  // a client that disappears mid-answer is not our end
  io::PlantServerStats stats;
  auto listening = [](const io::PlantServerOptions& o) {
    std::cout << fmt::format("plcfi plant-server: listening on {}:{}, plant step {} us\n", o.host, o.port, o.tick_ns / 1000)
              << std::flush;
  };
  bool ok = io::serve_plant(*plant, opt, g_stop, &stats, &err, listening);
  std::cout << fmt::format("plcfi plant-server: {} plant steps ({} late), {} connection(s), {} request(s)\n", stats.steps,
                           stats.late_steps, stats.connections, stats.requests);
  std::string s;
  for (const auto& [k, v] : plant->stats()) s += fmt::format("{}{} {}", s.empty() ? "" : ", ", k, v);
  std::cout << "  plant " << s << "\n";
  if (!ok) {
    std::cerr << "plcfi plant-server: " << err << "\n";
    return 2;
  }
  return 0;
#endif
}

}  // namespace plcfi::cli
