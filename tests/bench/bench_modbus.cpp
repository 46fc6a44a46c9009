// Modbus cycle I/O cost of the backend against a raw libmodbus loop doing the same
// requests, both against one libmodbus server thread in this process (loopback TCP).
#include <benchmark/benchmark.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>

#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include "engine.hpp"
#include "io/io_config.hpp"
#include "io/modbus/modbus_backend.hpp"
#include "../support/modbus_slave.hpp"

namespace {

using namespace plcfi;

using Server = testing_support::ModbusSlave;

// The stamping module's map: 11 discrete inputs, 1 input register, 6 coils, 1 holding register.
const char* kProgram = "PROGRAM P\nVAR x AT %IX0.0 : BOOL; p AT %IW2 : INT; y AT %QX0.0 : BOOL; sp AT %QW2 : INT; END_VAR\nEND_PROGRAM\n";

void BM_modbus_cycle_raw_libmodbus(benchmark::State& state) {
  Server server;
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", server.port());
  modbus_set_slave(ctx, 1);
  modbus_set_response_timeout(ctx, 0, 5000);
  if (modbus_connect(ctx) != 0) {
    state.SkipWithError("connect failed");
    return;
  }
  uint8_t bits[16] = {};
  uint16_t regs[4] = {};
  for (auto _ : state) {
    modbus_read_input_bits(ctx, 0, 11, bits);
    modbus_read_input_registers(ctx, 2, 1, regs);
    modbus_write_bits(ctx, 0, 6, bits);
    modbus_write_registers(ctx, 2, 1, regs);
  }
  modbus_close(ctx);
  modbus_free(ctx);
}
BENCHMARK(BM_modbus_cycle_raw_libmodbus)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_modbus_cycle_backend(benchmark::State& state) {
  Server server;
  auto b = st::build_sources({{"p.st", kProgram}}, st::CompileOptions{});
  auto path = (std::filesystem::temp_directory_path() / ("plcfi_bench_io_" + std::to_string(::getpid()) + ".yaml")).string();
  std::ofstream(path) << "io:\n  devices:\n    - {name: d, tcp: \"127.0.0.1:" << server.port() << "\", timeout: 5ms}\n  map:\n"
                      << "    - {image: \"%IX0.0\", count: 11, device: d, discrete_inputs: 0}\n"
                      << "    - {image: \"%IW2\", count: 1, device: d, input_registers: 2}\n"
                      << "    - {image: \"%QX0.0\", count: 6, device: d, coils: 0}\n"
                      << "    - {image: \"%QW2\", count: 1, device: d, holding_registers: 2}\n";
  io::IoConfig cfg;
  std::string err;
  if (!b->ok() || !io::load_io_config(path, *b->app, &cfg, &err)) {
    state.SkipWithError(err.c_str());
    return;
  }
  std::filesystem::remove(path);
  auto mb = io::ModbusBackend::create(cfg, 10'000'000, &err);
  std::vector<uint8_t> in(64), out(64);
  int64_t now = 0;
  for (auto _ : state) {
    mb->read(in.data(), now);
    mb->write(out.data(), now, 10'000'000);
    now += 10'000'000;
  }
  if (mb->stats()[0].failures) state.SkipWithError(mb->last_error().c_str());
}
BENCHMARK(BM_modbus_cycle_backend)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
