// Modbus backend: io-section errors, the scan's exchange against an in-process libmodbus
// server (blocks, status bit, last good inputs, reconnect after the server restarts), and
// against an independent implementation (pymodbus) over TCP and over RTU on a pty pair.
#include <gtest/gtest.h>

#include "../support/modbus_slave.hpp"
#include "../support/temp_files.hpp"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <modbus/modbus.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <spawn.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "engine.hpp"
#include "io/io_config.hpp"
#include "io/modbus/modbus_backend.hpp"
#include "runtime/runtime.hpp"

extern char** environ;

namespace plcfi::io {
namespace {

namespace fs = std::filesystem;

const char* kProgram = R"(
PROGRAM P
VAR
  di0 AT %IX0.0 : BOOL;
  di1 AT %IX0.1 : BOOL;
  di2 AT %IX0.2 : BOOL;
  ir AT %IW2 : INT;
  ir3 AT %IW6 : INT;
  linkOk AT %IX8.0 : BOOL;
  co0 AT %QX0.0 : BOOL;
  co1 AT %QX0.1 : BOOL;
  hr AT %QW2 : INT;
  scans : DINT;
END_VAR
scans := scans + 1;
co0 := di0;
co1 := NOT di1;
hr := ir + 1;
END_PROGRAM
)";

using testing_support::remember_temp;

std::string temp(const std::string& name, const std::string& text) {
  fs::path p = fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(p) << text;
  return remember_temp(p.string());
}

int free_port() {
  int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(s);
  return ntohs(a.sin_port);
}

class ModbusIo : public ::testing::Test {
 public:
  void SetUp() override {
    b_ = st::build_sources({{"p.st", kProgram}}, st::CompileOptions{});
    ASSERT_TRUE(b_->ok()) << b_->diags.render_all();
    std::string err;
    ASSERT_TRUE(sched_.single_program(*b_->app, "P", 10'000'000, &err)) << err;
  }
  // The io section for one device `dev` (a tcp:/rtu: line and options).
  std::string io_text(const std::string& dev) const {
    return "io:\n  devices:\n    - name: unit1\n      " + dev +
           "\n      unit: 1\n      timeout: 200ms\n      status: \"%IX8.0\"\n      reconnect: {min: 50ms, max: 200ms}\n"
           "  map:\n"
           "    - {image: \"%IX0.0\", count: 3, device: unit1, discrete_inputs: 0}\n"
           "    - {image: \"%IW2\", count: 1, device: unit1, input_registers: 0}\n"
           "    - {image: \"%IW6\", count: 1, device: unit1, input_registers: 3}\n"
           "    - {image: \"%QX0.0\", count: 2, device: unit1, coils: 4}\n"
           "    - {image: \"%QW2\", count: 1, device: unit1, holding_registers: 10}\n";
  }
  std::unique_ptr<ModbusBackend> backend(const std::string& text) {
    IoConfig cfg;
    std::string err;
    EXPECT_TRUE(load_io_config(temp("plcfi_io", text), *b_->app, &cfg, &err)) << err;
    // A 1 s cycle: these tests scan on their own clock and allow the devices 200 ms.
    auto mb = ModbusBackend::create(cfg, 1'000'000'000, &err);
    EXPECT_TRUE(mb) << err;
    return mb;
  }
  int64_t get(rt::Runtime& r, const char* path) {
    std::string err;
    auto h = st::resolve(*b_->app, path, &err);
    return st::read_int(r.machine(), *h);
  }
  // Scans until cond or about two seconds of wall time (the device answers in real time).
  template <class F>
  bool scan_until(rt::Runtime& r, F cond) {
    for (int i = 0; i < 200; ++i) {
      r.scan();
      if (cond()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  std::unique_ptr<st::Build> b_;
  rt::Schedule sched_;
};

// ------------------------------------------------------------------ configuration

TEST_F(ModbusIo, IoSectionErrorsNameTheLine) {
  struct Case {
    std::string text;
    const char* expect;
  };
  const std::string dev = "io:\n  devices:\n    - {name: d, tcp: \"127.0.0.1:1502\"}\n  map:\n";
  for (const Case& c : {Case{dev + "    - {image: \"%IW2\", device: d, coils: 0}\n", ":5:15: coils map to bits"},
                        Case{dev + "    - {image: \"%QX0.0\", device: d, discrete_inputs: 0}\n", ":5:15: discrete_inputs are read-only"},
                        Case{dev + "    - {image: \"%IX0.0\", device: e, discrete_inputs: 0}\n", ":5:33: unknown device 'e'"},
                        Case{dev + "    - {image: \"%IX0.0\", device: d}\n", ":5:7: name one table"},
                        Case{dev + "    - {image: \"%IX0.0\", device: d, discrete_inputs: 70000}\n", "address: 70000 is outside 0..65535"},
                        Case{dev + "    - {image: \"%IX0.0\", count: 8, device: d, discrete_inputs: 0}\n"
                                   "    - {image: \"%IX0.4\", device: d, discrete_inputs: 9}\n",
                             ":6:15: overlaps the mapping at"},
                        Case{"io:\n  devices:\n    - {name: d, rtu: {device: /dev/ttyS0, parity: X}}\n  map: []\n", ":3:51: parity: expected N, E or O, got 'X'"},
                        Case{"io:\n  devices:\n    - {name: d, tcp: \"[::1:1502\"}\n  map: []\n", ":3:22: missing ']'"},
                        Case{"io:\n  devices:\n    - {name: d, tcp: \"h:1\", status: \"%QX0.0\"}\n  map: []\n", "status must be an input bit"},
                        Case{"io:\n  devices:\n    - {name: d, tcp: \"h:1\", speed: 3}\n  map: []\n", ":3:29: unknown key 'speed'"}}) {
    IoConfig cfg;
    std::string err;
    EXPECT_FALSE(load_io_config(temp("plcfi_io_bad", c.text), *b_->app, &cfg, &err)) << c.text;
    EXPECT_NE(err.find(c.expect), std::string::npos) << err << "\n  expected: " << c.expect;
  }
}

TEST_F(ModbusIo, Ipv6AndHostNamesParse) {
  IoConfig cfg;
  std::string err;
  std::string text = "io:\n  devices:\n    - {name: a, tcp: \"[::1]:1502\"}\n    - {name: b, tcp: \"localhost\"}\n"
                     "  map:\n    - {image: \"%IX0.0\", device: a, discrete_inputs: 0}\n";
  ASSERT_TRUE(load_io_config(temp("plcfi_io_v6", text), *b_->app, &cfg, &err)) << err;
  EXPECT_EQ(cfg.devices[0].host, "::1");
  EXPECT_EQ(cfg.devices[0].port, "1502");
  EXPECT_EQ(cfg.devices[1].host, "localhost");
  EXPECT_EQ(cfg.devices[1].port, "502");
}

// ------------------------------------------------------------------ in-process libmodbus server

// The shared in-process slave, with the values these tests read back.
class LibmodbusServer : public testing_support::ModbusSlave {
 public:
  explicit LibmodbusServer(int port, std::string host = "127.0.0.1") : ModbusSlave(port, std::move(host), 32) {
    map()->tab_input_bits[0] = 1;
    map()->tab_input_bits[2] = 1;
    map()->tab_input_registers[0] = 41;
    map()->tab_input_registers[3] = static_cast<uint16_t>(-7);
  }
};

TEST_F(ModbusIo, TimeoutMustBeBelowTheCycle) {
  IoConfig cfg;
  std::string err;
  std::string path = temp("plcfi_io_timeout", io_text("tcp: \"127.0.0.1:1502\""));
  ASSERT_TRUE(load_io_config(path, *b_->app, &cfg, &err)) << err;
  EXPECT_EQ(ModbusBackend::create(cfg, 100'000'000, &err), nullptr);  // 200 ms timeout, 100 ms cycle
  EXPECT_EQ(err, path + ":3:7: device 'unit1': timeout 200 ms is not below the cycle time 100 ms (a silent device would "
                        "make every scan overrun)");
}

TEST_F(ModbusIo, ExchangesTheImageInTheScan) {
  int port = free_port();
  LibmodbusServer server(port);
  auto mb = backend(io_text("tcp: \"127.0.0.1:" + std::to_string(port) + "\""));
  ASSERT_TRUE(mb);
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.cold_restart(1);
  ASSERT_TRUE(scan_until(r, [&] { return server.map()->tab_registers[10] == 42; }));
  EXPECT_EQ(get(r, "P.linkOk"), 1);
  EXPECT_EQ(get(r, "P.di0"), 1);
  EXPECT_EQ(get(r, "P.di1"), 0);
  EXPECT_EQ(get(r, "P.di2"), 1);
  EXPECT_EQ(get(r, "P.ir3"), -7);
  EXPECT_EQ(server.map()->tab_bits[4], 1);  // co0 := di0
  EXPECT_EQ(server.map()->tab_bits[5], 1);  // co1 := NOT di1
  // One request per contiguous block: DI 0..2, IR 0 and IR 3 (not contiguous), coils 4..5, HR 10.
  int before = server.requests.load();
  r.scan();
  EXPECT_EQ(server.requests.load() - before, 5);
  EXPECT_EQ(mb->stats()[0].failures, 0u);
}

// TCP by IPv6 address and by host name (modbus_new_tcp_pi resolves both).
TEST_F(ModbusIo, ExchangesOverIpv6AndByHostName) {
  for (const auto& [server_host, device] : {std::pair<std::string, std::string>{"::1", "[::1]"}, {"127.0.0.1", "localhost"}}) {
    SCOPED_TRACE(device);
    int port = free_port();
    LibmodbusServer server(port, server_host);
    auto mb = backend(io_text("tcp: \"" + device + ":" + std::to_string(port) + "\""));
    ASSERT_TRUE(mb);
    rt::Runtime r(*b_->app, sched_, mb.get());
    r.cold_restart(1);
    ASSERT_TRUE(scan_until(r, [&] { return server.map()->tab_registers[10] == 42; })) << mb->last_error();
    EXPECT_EQ(get(r, "P.linkOk"), 1);
    EXPECT_EQ(server.map()->tab_bits[4], 1);
  }
}

TEST_F(ModbusIo, KeepsLastGoodInputsAndReconnectsAfterAnOutage) {
  int port = free_port();
  auto server = std::make_unique<LibmodbusServer>(port);
  auto mb = backend(io_text("tcp: \"127.0.0.1:" + std::to_string(port) + "\""));
  ASSERT_TRUE(mb);
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.cold_restart(1);
  ASSERT_TRUE(scan_until(r, [&] { return get(r, "P.linkOk") == 1; }));
  EXPECT_EQ(get(r, "P.ir"), 41);
  server->stop();  // the device goes away
  auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(scan_until(r, [&] { return get(r, "P.linkOk") == 0; }));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));  // no hang
  for (int i = 0; i < 10; ++i) r.scan();
  EXPECT_EQ(get(r, "P.ir"), 41);  // last good value kept
  EXPECT_EQ(get(r, "P.di0"), 1);
  EXPECT_GT(mb->stats()[0].failures + mb->stats()[0].disconnects, 0u);
  EXPECT_NE(mb->last_error().find("unit1 (127.0.0.1:" + std::to_string(port) + ") unit 1"), std::string::npos)
      << mb->last_error();
  server->start();  // back: the backoff retries and the flag clears
  ASSERT_TRUE(scan_until(r, [&] { return get(r, "P.linkOk") == 1; }));
  EXPECT_EQ(mb->stats()[0].connects, 2u);
  EXPECT_EQ(get(r, "P.ir"), 41);
}

// Lost communication with one device: the run ends, and the safe state still reaches
// the devices that answer (what plcfi run and campaign do on that way out).
TEST_F(ModbusIo, LostDeviceEndsTheRunAndTheOthersGetTheSafeState) {
  int port_a = free_port(), port_b = free_port();
  auto a = std::make_unique<LibmodbusServer>(port_a);
  LibmodbusServer b(port_b);
  std::string text = "io:\n  devices:\n"
                     "    - {name: a, tcp: \"127.0.0.1:" + std::to_string(port_a) + "\", timeout: 100ms, lost_after: 300ms, "
                     "reconnect: {min: 50ms, max: 100ms}}\n"
                     "    - {name: b, tcp: \"127.0.0.1:" + std::to_string(port_b) + "\", timeout: 100ms}\n"
                     "  map:\n"
                     "    - {image: \"%IX0.0\", count: 1, device: a, discrete_inputs: 0}\n"
                     "    - {image: \"%QX0.0\", count: 1, device: a, coils: 4}\n"
                     "    - {image: \"%QX0.1\", count: 1, device: b, coils: 5}\n"
                     "    - {image: \"%QW2\", count: 1, device: b, holding_registers: 10}\n"
                     "  safe_state: {\"%QW2\": 7}\n";
  IoConfig cfg;
  std::string err;
  ASSERT_TRUE(load_io_config(temp("plcfi_io_two", text), *b_->app, &cfg, &err)) << err;
  auto mb = ModbusBackend::create(cfg, 1'000'000'000, &err);
  ASSERT_TRUE(mb) << err;
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.set_safe_state(cfg.safe_state);
  r.cold_restart(1);
  // di0 = 1 on device a: the program drives co0 := di0 (a) and co1 := NOT di1 (b).
  ASSERT_TRUE(scan_until(r, [&] { return b.map()->tab_bits[5] == 1 && a->map()->tab_bits[4] == 1; }));
  EXPECT_NE(b.map()->tab_registers[10], 7);
  a->stop();
  auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(scan_until(r, [&] { return mb->lost_device() != SIZE_MAX; }));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(3));
  EXPECT_EQ(mb->lost_device(), 0u);
  r.write_safe_outputs();
  EXPECT_EQ(b.map()->tab_bits[5], 0);         // off
  EXPECT_EQ(b.map()->tab_registers[10], 7);   // the configured safe value
  EXPECT_TRUE(mb->stats()[1].up);
}

// RS485 on a line that cannot do it (a pty): the error names the device and the mode.
TEST_F(ModbusIo, Rs485ModeOnALineWithoutItIsAnErrorNamingTheDevice) {
  int master = posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(grantpt(master), 0);
  ASSERT_EQ(unlockpt(master), 0);
  std::string dev = ptsname(master);
  auto mb = backend(io_text("rtu: {device: \"" + dev + "\", baud: 19200, parity: E, mode: rs485}"));
  ASSERT_TRUE(mb);
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.cold_restart(1);
  EXPECT_EQ(r.scan(), rt::ScanStatus::IoError);
  EXPECT_EQ(get(r, "P.linkOk"), 0);
  EXPECT_NE(mb->last_error().find("unit1 (" + dev + ") unit 1: RS485 mode: "), std::string::npos) << mb->last_error();
  mb->close();
  ::close(master);
}

// A peer that answers with garbage (a wrong header, a length it never sends, random
// bytes, an exception for every request) is a communication error: counted, the status
// bit cleared, the last good inputs kept; never a crash or a hang.
TEST_F(ModbusIo, GarbageAnsweringPeerIsAnErrorNotACrash) {
  int port = free_port();
  int ls = socket(AF_INET, SOCK_STREAM, 0);
  int one = 1;
  setsockopt(ls, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<uint16_t>(port));
  ASSERT_EQ(bind(ls, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(listen(ls, 8), 0);
  std::atomic<bool> stop{false};
  std::thread peer([&] {
    std::mt19937 rng(7);
    int answer = 0;
    while (!stop) {
      fd_set rd;
      FD_ZERO(&rd);
      FD_SET(ls, &rd);
      timeval tv{0, 20'000};
      if (select(ls + 1, &rd, nullptr, nullptr, &tv) <= 0) continue;
      int c = accept(ls, nullptr, nullptr);
      if (c < 0) continue;
      timeval rto{0, 200'000};
      setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &rto, sizeof rto);
      uint8_t q[260];
      while (!stop && ::recv(c, q, sizeof q, 0) > 0) {
        std::vector<uint8_t> r;
        switch (answer++ % 4) {
          case 0: r = {q[0], q[1], 0, 0, 0, 200, q[6], q[7], 1, 2};  // a length it never sends
            break;
          case 1: r = {static_cast<uint8_t>(q[0] + 1), q[1], 0, 0, 0, 3, q[6], q[7], 0};  // another transaction
            break;
          case 2: for (int i = 0; i < 40; ++i) r.push_back(static_cast<uint8_t>(rng()));  // noise
            break;
          default: r = {q[0], q[1], 0, 0, 0, 3, q[6], static_cast<uint8_t>(q[7] | 0x80), 4};  // exception 4
        }
        if (::send(c, r.data(), r.size(), MSG_NOSIGNAL) < 0) break;
      }
      ::close(c);
    }
  });
  std::string text = io_text("tcp: \"127.0.0.1:" + std::to_string(port) + "\"");
  text.replace(text.find("timeout: 200ms"), 14, "timeout: 50ms");
  auto mb = backend(text);
  ASSERT_TRUE(mb);
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.cold_restart(1);
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 40; ++i) {
    r.scan();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(10));
  EXPECT_EQ(get(r, "P.linkOk"), 0);
  EXPECT_EQ(get(r, "P.ir"), 0);  // never a value from the garbage
  EXPECT_GT(mb->stats()[0].failures + mb->stats()[0].disconnects, 0u);
  EXPECT_FALSE(mb->last_error().empty());
  mb->close();
  stop = true;
  peer.join();
  ::close(ls);
}

TEST_F(ModbusIo, UnreachableDeviceNeitherHangsNorCrashes) {
  int port = free_port();  // nobody listens
  auto mb = backend(io_text("tcp: \"127.0.0.1:" + std::to_string(port) + "\"\n      lost_after: 100ms"));
  ASSERT_TRUE(mb);
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.cold_restart(1);
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 30; ++i) EXPECT_EQ(r.scan(), rt::ScanStatus::IoError);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  EXPECT_EQ(get(r, "P.linkOk"), 0);
  EXPECT_NE(mb->last_error().find("connect"), std::string::npos) << mb->last_error();
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  EXPECT_EQ(mb->lost_device(), 0u);  // down longer than lost_after (monotonic clock)
}

// ------------------------------------------------------------------ pymodbus (independent)

class Child {
 public:
  explicit Child(std::vector<std::string> argv) {
    std::vector<char*> a;
    for (auto& s : argv) a.push_back(s.data());
    a.push_back(nullptr);
    if (posix_spawn(&pid_, a[0], nullptr, nullptr, a.data(), environ) != 0) pid_ = -1;
  }
  ~Child() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      int st;
      waitpid(pid_, &st, 0);
    }
  }
  bool ok() const { return pid_ > 0; }

 private:
  pid_t pid_ = -1;
};

const std::string kServer = std::string(PLCFI_SOURCE_DIR) + "/tests/io/modbus_test_server.py";

void check_against_pymodbus(ModbusIo& f, rt::Runtime& r, ModbusBackend& mb) {
  // pymodbus: DI 0..2 = 1,0,1; IR0 = 100; IR3 = 65535 (-1 as INT).
  ASSERT_TRUE(f.scan_until(r, [&] { return f.get(r, "P.linkOk") == 1 && f.get(r, "P.ir") == 100; })) << mb.last_error();
  EXPECT_EQ(f.get(r, "P.di0"), 1);
  EXPECT_EQ(f.get(r, "P.di1"), 0);
  EXPECT_EQ(f.get(r, "P.di2"), 1);
  EXPECT_EQ(f.get(r, "P.ir3"), -1);
}

TEST_F(ModbusIo, AgainstPymodbusOverTcp) {
  int port = free_port();
  Child server({"/usr/bin/python3", kServer, "--tcp", std::to_string(port)});
  ASSERT_TRUE(server.ok());
  // The outputs come back through a second device mapping that reads the same coils and
  // holding registers (FC01/FC03) into spare %I bytes.
  std::string text = io_text("tcp: \"127.0.0.1:" + std::to_string(port) + "\"") +
                     "    - {image: \"%IX20.0\", count: 2, device: unit1, coils: 4}\n"
                     "    - {image: \"%IW22\", count: 1, device: unit1, holding_registers: 10}\n";
  auto mb = backend(text);
  ASSERT_TRUE(mb);
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.cold_restart(1);
  check_against_pymodbus(*this, r, *mb);
  // Written by FC15/FC16 in one scan, read back by FC01/FC03 in the next.
  ASSERT_TRUE(scan_until(r, [&] {
    const uint8_t* in = r.raw_inputs();
    return (in[20] & 3) == 3 && (in[44] | (in[45] << 8)) == 101;  // %IW22 is bytes 44..45
  }));
}

TEST_F(ModbusIo, AgainstPymodbusOverRtuOnAPtyPair) {
  fs::path dir = fs::temp_directory_path() / ("plcfi_rtu_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string a = (dir / "a").string(), b = (dir / "b").string();
  Child pty({"/usr/bin/socat", "pty,raw,echo=0,link=" + a, "pty,raw,echo=0,link=" + b});
  ASSERT_TRUE(pty.ok());
  for (int i = 0; i < 100 && !(fs::exists(a) && fs::exists(b)); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(a) && fs::exists(b)) << "socat did not create the pty pair";
  Child server({"/usr/bin/python3", kServer, "--rtu", a, "--baud", "38400"});
  ASSERT_TRUE(server.ok());
  auto mb = backend(io_text("rtu: {device: " + b + ", baud: 38400, parity: N, data_bits: 8, stop_bits: 1}"));
  ASSERT_TRUE(mb);
  rt::Runtime r(*b_->app, sched_, mb.get());
  r.cold_restart(1);
  check_against_pymodbus(*this, r, *mb);
  EXPECT_GE(mb->stats()[0].connects, 1u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace plcfi::io
