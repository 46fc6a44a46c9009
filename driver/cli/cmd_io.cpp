// plcfi run --io (the program on real I/O, paced in real time) and plcfi plant-server (a
// plant model in real time behind a Modbus TCP server).
#include <iostream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "options.hpp"
#include "engine.hpp"
#include "io/sim/plant_factory.hpp"
#include "plant_model/plant.hpp"
#include "report/junit.hpp"
#include "runtime/clock.hpp"
#include "runtime/realtime.hpp"
#include "runtime/runtime.hpp"
#include "runtime/schedule.hpp"

#include "io/devices/device_io.hpp"
#ifdef PLCFI_HAVE_MODBUS
#include "io/modbus/plant_server.hpp"
#endif

namespace po = boost::program_options;

namespace plcfi::cli {

void warn_realtime_setup(const rt::RealtimeOptions& o, const char* who) {
  for (const auto& w : rt::realtime_setup(o)) std::cerr << who << ": warning: " << w << "\n";
}

namespace {

// The io file's devices, opened; none without an io file (the pacing alone: latency
// measurements). False after printing why.
bool open_run_io(const std::string& io_path, const st::Application& app, const rt::Schedule& sched, io::IoConfig* cfg,
                 std::unique_ptr<io::DeviceIo>* backend) {
  if (io_path.empty()) return true;
  std::string err;
  if (!io::load_io_config(io_path, app, cfg, &err)) {
    std::cerr << err << "\n";
    return false;
  }
  *backend = io::DeviceIo::open(*cfg, sched.tick_ns(), &err);
  if (!*backend) {
    std::cerr << err << "\n";
    return false;
  }
  return true;
}

// Every way out: the safe output state reaches the devices before they are closed; then
// the line that says how the run ended. False (after printing why) when the safe state could
// not be written.
bool end_safely(rt::Runtime& runtime, io::DeviceIo* backend, const io::IoConfig& cfg, const rt::ScanLoop& loop,
                const rt::Schedule& sched) {
  const bool safe = runtime.write_safe_outputs();
  const std::string safe_error = safe || !backend ? std::string() : backend->last_error();
  if (backend) backend->close();
  std::cout << fmt::format("plcfi run: {} scans of {} ms over {}, ended: {}; {}{}\n", loop.scans(),
                           static_cast<double>(sched.tick_ns()) / 1e6, backend ? cfg.path : "no I/O", loop.end_reason(),
                           safe ? "outputs written to the safe state" : "THE SAFE STATE COULD NOT BE WRITTEN",
                           cfg.safe_state.empty() ? " (all off)" : fmt::format(" (all off but {})", cfg.safe_state.size()));
  if (!safe)
    std::cerr << fmt::format("plcfi run: the safe state could not be written: {}; check the outputs at the devices\n",
                             safe_error);
  return safe;
}

// --junit: the scan cycle as one test case (failed when the run did), the real-time and
// the devices' figures as properties. False after printing why.
bool write_run_junit(const std::string& path, const rt::ScanLoop& loop, const io::DeviceIo* backend, const io::IoConfig& cfg,
                     int status, int64_t t0) {
  report::ScanRunFacts run;
  run.name = backend ? "scan cycle on " + cfg.path : "scan cycle";
  run.seconds = static_cast<double>(rt::RealTimePacer::monotonic_ns() - t0) * 1e-9;
  run.failed = status != 0;
  run.ended = loop.end_reason();
  run.scans = loop.scans();
  if (loop.paced()) run.realtime = loop.pacer().properties();
  if (backend) run.io_report = backend->report();
  std::string err;
  if (!report::write_junit(path, {report::scan_run_junit(run)}, &err)) {
    std::cerr << "plcfi run: " << err << "\n";
    return false;
  }
  return true;
}

}  // namespace

int run_with_io(const st::Application& app, const rt::Schedule& sched, const std::string& io_path, const RunIoOptions& o,
                const std::function<bool(st::Machine&)>& setup, const std::function<void(st::Machine&, int)>& report) {
  io::IoConfig cfg;
  std::unique_ptr<io::DeviceIo> backend;
  if (!open_run_io(io_path, app, sched, &cfg, &backend)) return 2;
  rt::Runtime runtime(app, sched, backend.get());
  runtime.machine().set_native(o.native);
  runtime.set_safe_state(cfg.safe_state);
  runtime.cold_restart(1);
  if (!setup(runtime.machine())) {
    runtime.write_safe_outputs();
    return 2;
  }
  rt::StopSignals signals;
  if (o.realtime) warn_realtime_setup(o.rt, "plcfi run");
  rt::ScanLoop loop(runtime, o.realtime, &signals, [&backend] { return backend ? backend->lost() : std::string(); });
  const int64_t t0 = rt::RealTimePacer::monotonic_ns();
  rt::LoopEnd end = loop.run(o.cycles, o.duration_ns);
  int status = end == rt::LoopEnd::Trapped || end == rt::LoopEnd::CommunicationLost ? 1 : 0;
  if (!end_safely(runtime, backend.get(), cfg, loop, sched)) status = 1;
  for (const auto& line : loop.figures()) std::cout << "  " << line << "\n";
  if (backend)
    for (const auto& line : backend->report()) std::cout << "  " << line << "\n";
  report(runtime.machine(), status);
  if (!o.junit.empty() && !write_run_junit(o.junit, loop, backend.get(), cfg, status, t0)) return 2;
  return status;
}

namespace {

// The options of `plcfi plant-server` (it takes no plain arguments, so --help is its own).
void add_plant_server_options(po::options_description& desc) {
  desc.add_options()
      ("plant", po::value<std::string>()->default_value("stamping"), "plant model")
      ("plant-config", po::value<std::string>(), "plant parameters (YAML)")
      ("listen", po::value<std::string>()->default_value("127.0.0.1:1502"), "address and port (HOST:PORT, [V6]:PORT); loopback by default")
      ("tick", po::value<std::string>()->default_value("1ms"), "plant step in real time")
      ("duration", po::value<std::string>(), "stop after this long (default: until SIGINT/SIGTERM)")
      ("seed", po::value<Count>()->default_value(Count{1}, "1"), "seed of the plant's random variation (and of --drop-rate)")
      ("drop-rate", po::value<double>()->default_value(0.0, "0"), "leave this fraction of the requests unanswered (0..1): a lossy link")
      ("stall", po::value<std::string>(), "answer every request this late (e.g. 10ms; beyond the master's timeout: a failed exchange)")
      ("help,h", "show this help");
}

#ifdef PLCFI_HAVE_MODBUS
// --listen HOST:PORT or [V6]:PORT into opt. False after printing why.
bool listen_option(const std::string& listen, io::PlantServerOptions* opt) {
  size_t colon = listen.rfind(':');
  if (!listen.empty() && listen[0] == '[') {
    size_t close = listen.find(']');
    if (close == std::string::npos || close + 1 >= listen.size() || listen[close + 1] != ':') {
      std::cerr << "plcfi plant-server: --listen: expected [ADDRESS]:PORT, got '" << listen << "'\n";
      return false;
    }
    opt->host = listen.substr(1, close - 1);
    opt->port = listen.substr(close + 2);
  } else if (colon == std::string::npos || colon == 0 || colon + 1 == listen.size()) {
    std::cerr << "plcfi plant-server: --listen: expected HOST:PORT, got '" << listen << "'\n";
    return false;
  } else {
    opt->host = listen.substr(0, colon);
    opt->port = listen.substr(colon + 1);
  }
  // libmodbus takes the port as text and lets the resolver wrap it (99999 served on 34463).
  bool neg = false;
  uint64_t port = 0;
  if (!parse_whole(opt->port, &neg, &port) || neg || port < 1 || port > 65535) {
    std::cerr << "plcfi plant-server: --listen: port '" << opt->port << "' is not a whole number from 1 to 65535\n";
    return false;
  }
  return true;
}

// The server's options: --listen, --tick, --duration, --seed, --drop-rate and --stall.
// False after printing why.
bool server_options(const po::variables_map& vm, io::PlantServerOptions* opt) {
  if (!listen_option(vm["listen"].as<std::string>(), opt)) return false;
  std::string err;
  if (!rt::parse_duration(vm["tick"].as<std::string>(), &opt->tick_ns, &err) || opt->tick_ns <= 0) {
    std::cerr << "plcfi plant-server: --tick: " << (err.empty() ? "must be positive" : err) << "\n";
    return false;
  }
  if (vm.count("duration") && (!rt::parse_duration(vm["duration"].as<std::string>(), &opt->duration_ns, &err) || opt->duration_ns <= 0)) {
    std::cerr << "plcfi plant-server: --duration: " << (err.empty() ? "must be positive" : err) << "\n";
    return false;
  }
  opt->seed = vm["seed"].as<Count>().value;
  opt->drop_rate = vm["drop-rate"].as<double>();
  if (!(opt->drop_rate >= 0.0 && opt->drop_rate <= 1.0)) {
    std::cerr << "plcfi plant-server: --drop-rate: expected a fraction from 0 to 1, got " << opt->drop_rate << "\n";
    return false;
  }
  if (vm.count("stall") && (!rt::parse_duration(vm["stall"].as<std::string>(), &opt->stall_ns, &err) || opt->stall_ns > 10'000'000'000)) {
    std::cerr << "plcfi plant-server: --stall: " << (err.empty() ? "at most 10 s" : err) << "\n";
    return false;
  }
  return true;
}

// What the server did: plant steps, connections, requests (and the ones dropped or stalled),
// and the plant's figures.
void print_server_summary(const io::PlantServerStats& stats, const io::PlantServerOptions& opt, const plant::Plant& plant) {
  std::cout << fmt::format("plcfi plant-server: {} plant steps ({} late), {} connection(s), {} request(s){}\n", stats.steps,
                           stats.late_steps, stats.connections, stats.requests,
                           opt.drop_rate > 0 || opt.stall_ns > 0
                               ? fmt::format(", {} left unanswered, {} answered late", stats.dropped, stats.stalled)
                               : std::string());
  std::string s;
  for (const auto& [k, v] : plant.stats()) s += fmt::format("{}{} {}", s.empty() ? "" : ", ", k, v);
  std::cout << "  plant " << s << "\n";
}
#endif

}  // namespace

int cmd_plant_server(const std::vector<std::string>& args) {
  po::options_description desc("plcfi plant-server: a plant model in real time behind a Modbus TCP server");
  add_plant_server_options(desc);
  po::variables_map vm;
  po::store(po::command_line_parser(args).options(desc).run(), vm);
  po::notify(vm);
  if (vm.count("help")) {
    std::cout << "usage: plcfi plant-server [--plant stamping] [--listen 127.0.0.1:1502] [--tick 1ms] [--duration T] "
                 "[--drop-rate P] [--stall T]\n\n"
              << desc << "\nRegister map: a sensor on %IXb.i is discrete input 8b+i, on %IWn input register n;\n"
                         "an actuator on %QXb.i is coil 8b+i, on %QWn holding register n (the plant's I/O map).\n";
    return 0;
  }
#ifndef PLCFI_HAVE_MODBUS
  std::cerr << "plcfi plant-server: this plcfi was built without Modbus (PLCFI_MODBUS=OFF)\n";
  return 2;
#else
  io::PlantServerOptions opt;
  if (!server_options(vm, &opt)) return 2;
  std::string err;
  auto plant = io::open_plant(vm["plant"].as<std::string>(), vm.count("plant-config") ? vm["plant-config"].as<std::string>() : "", &err);
  if (!plant) {
    std::cerr << "plcfi plant-server: " << err << "\n";
    return 2;
  }
  rt::StopSignals signals;  // SIGPIPE too: a client that disappears mid-answer is not our end
  io::PlantServerStats stats;
  auto listening = [](const io::PlantServerOptions& o) {
    std::cout << fmt::format("plcfi plant-server: listening on {}:{}, plant step {} us\n", o.host, o.port, o.tick_ns / 1000)
              << std::flush;
  };
  bool ok = io::serve_plant(*plant, opt, [&signals] { return signals.requested(); }, &stats, &err, listening);
  print_server_summary(stats, opt, *plant);
  if (!ok) {
    std::cerr << "plcfi plant-server: " << err << "\n";
    return 2;
  }
  return 0;
#endif
}

}  // namespace plcfi::cli
