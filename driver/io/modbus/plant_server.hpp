// A plant model behind a Modbus TCP server, in real time: `plcfi plant-server` lets a bench
// run be rehearsed end to end over a real protocol stack. The register map follows the
// plant's default image addresses: a sensor on %IXb.i is discrete input 8*b+i, one on
// %IWn input register n; an actuator on %QXb.i is coil 8*b+i, one on %QWn holding
// register n. Any unit id is answered. The plant's time starts with the first client.
// Writing a non-zero value to holding register 100 resets the plant (a campaign's restart).
#pragma once

#include <atomic>
#include <functional>
#include <cstdint>
#include <memory>
#include <string>

#include "plant_model/plant.hpp"

namespace plcfi::io {

constexpr int kResetRegister = 100;

struct PlantServerOptions {
  std::string host = "127.0.0.1";  // loopback unless asked otherwise
  std::string port = "1502";
  int64_t tick_ns = 1'000'000;      // plant step
  int64_t duration_ns = 0;          // 0: until stopped
  uint64_t seed = 1;
  // A bad link, to rehearse communication faults: each request is left unanswered with
  // this probability (0..1), and every answer waits stall_ns before it goes out (beyond the
  // master's response timeout it arrives too late). Deterministic for a seed.
  double drop_rate = 0.0;
  int64_t stall_ns = 0;
};

struct PlantServerStats {
  uint64_t steps = 0, requests = 0, connections = 0, resets = 0, dropped = 0, stalled = 0;
  int64_t late_steps = 0;  // ticks that started after their deadline (overloaded machine)
};

// Serves until `stop` becomes true, the duration ends, or an error. Returns false with a
// message (bad address, port in use) in *err. Single-threaded: requests are answered
// between plant steps. `on_listening` is called once the socket listens.
bool serve_plant(plant::Plant& plant, const PlantServerOptions& opt, const std::function<bool()>& stop, PlantServerStats* stats,
                 std::string* err, void (*on_listening)(const PlantServerOptions&) = nullptr);

// Parses "%IX0.4" / "%QW2" into (input?, bit?, index): index = 8*byte+bit for bits, the word
// number for words. False for anything else.
bool plant_address(const std::string& a, bool* input, bool* bit, int* index);

}  // namespace plcfi::io
