// plcfi plant-server: a plant model in real time behind a Modbus TCP server.
#include <atomic>
#include <csignal>
#include <iostream>

#include <boost/program_options.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "plant_model/plant.hpp"
#include "runtime/schedule.hpp"

#ifdef PLCFI_HAVE_MODBUS
#include "io/modbus/plant_server.hpp"
#endif

namespace po = boost::program_options;

namespace plcfi::cli {

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop.store(true); }
}  // namespace

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
