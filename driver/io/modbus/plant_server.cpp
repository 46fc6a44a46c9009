// Modbus TCP server around a plant model, stepped on absolute real-time deadlines.
#include "plant_server.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

#include <sys/select.h>
#include <unistd.h>

#include <fmt/format.h>
#include <modbus/modbus.h>

namespace plcfi::io {

bool plant_address(const std::string& a, bool* input, bool* bit, int* index) {
  if (a.size() < 4 || a[0] != '%' || (a[1] != 'I' && a[1] != 'Q') || (a[2] != 'X' && a[2] != 'W')) return false;
  *input = a[1] == 'I';
  *bit = a[2] == 'X';
  size_t dot = a.find('.');
  try {
    if (*bit) {
      if (dot == std::string::npos) return false;
      int byte = std::stoi(a.substr(3, dot - 3)), b = std::stoi(a.substr(dot + 1));
      if (byte < 0 || b < 0 || b > 7) return false;
      *index = byte * 8 + b;
    } else {
      if (dot != std::string::npos) return false;
      *index = std::stoi(a.substr(3));
      if (*index < 0) return false;
    }
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

namespace {

struct Binding {
  size_t signal;
  bool input, bit;
  int index;
  plant::SignalKind kind;
};

struct Ctx {
  modbus_t* ctx = nullptr;
  modbus_mapping_t* map = nullptr;
  int server = -1;
  ~Ctx() {
    if (server >= 0) ::close(server);
    if (map) modbus_mapping_free(map);
    if (ctx) {
      modbus_close(ctx);
      modbus_free(ctx);
    }
  }
};

}  // namespace

bool serve_plant(plant::Plant& plant, const PlantServerOptions& opt, const std::function<bool()>& stop, PlantServerStats* stats,
                 std::string* err, void (*on_listening)(const PlantServerOptions&)) {
  const auto& sig = plant.signals();
  std::vector<Binding> bind;
  int n_bits = 16, n_in_bits = 16, n_regs = kResetRegister + 1, n_in_regs = 8;
  for (size_t i = 0; i < sig.size(); ++i) {
    Binding b{i, false, false, 0, sig[i].kind};
    if (!plant_address(sig[i].address, &b.input, &b.bit, &b.index)) {
      *err = fmt::format("plant signal {} has address '{}', which has no Modbus point", sig[i].name, sig[i].address);
      return false;
    }
    if (b.bit && b.input) n_in_bits = std::max(n_in_bits, b.index + 1);
    if (b.bit && !b.input) n_bits = std::max(n_bits, b.index + 1);
    if (!b.bit && b.input) n_in_regs = std::max(n_in_regs, b.index + 1);
    if (!b.bit && !b.input) n_regs = std::max(n_regs, b.index + 1);
    bind.push_back(b);
  }
  Ctx c;
  c.ctx = modbus_new_tcp_pi(opt.host.c_str(), opt.port.c_str());
  if (!c.ctx) {
    *err = fmt::format("{}:{}: {}", opt.host, opt.port, modbus_strerror(errno));
    return false;
  }
  c.map = modbus_mapping_new(n_bits, n_in_bits, n_regs, n_in_regs);
  if (!c.map) {
    *err = std::string("cannot allocate the register map: ") + modbus_strerror(errno);
    return false;
  }
  c.server = modbus_tcp_pi_listen(c.ctx, 8);
  if (c.server < 0) {
    *err = fmt::format("cannot listen on {}:{}: {}", opt.host, opt.port, modbus_strerror(errno));
    return false;
  }
  plant.reset(opt.seed);
  std::vector<double> act(sig.size(), 0.0), sen(sig.size(), 0.0);
  auto publish = [&]() {
    for (const auto& b : bind) {
      if (!b.input) continue;
      if (b.bit) c.map->tab_input_bits[b.index] = sen[b.signal] != 0 ? 1 : 0;
      else c.map->tab_input_registers[b.index] = static_cast<uint16_t>(static_cast<int16_t>(std::lround(sen[b.signal])));
    }
  };
  plant.sense(sen.data());
  publish();
  if (on_listening) on_listening(opt);

  std::vector<int> clients;
  std::vector<uint8_t> query(MODBUS_TCP_MAX_ADU_LENGTH);
  uint64_t rng = opt.seed * 0x9e3779b97f4a7c15ull + 1;  // the link's losses (drop_rate)
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto next = start + std::chrono::nanoseconds(opt.tick_ns);
  const double dt = static_cast<double>(opt.tick_ns) * 1e-9;
  // The plant's clock starts with the first client: a PLC that connects later does not
  // miss what the operator does at the start (the start button press, for instance).
  bool running = false;
  while (!stop()) {
    auto now = clock::now();
    if (opt.duration_ns > 0 && now - start >= std::chrono::nanoseconds(opt.duration_ns)) break;
    if (!running && !clients.empty()) {
      running = true;
      next = now + std::chrono::nanoseconds(opt.tick_ns);
    }
    if (running && now >= next) {
      // Step on absolute deadlines. A late server (a loaded machine) counts the late step
      // and makes the steps it missed at once: the plant's physics must keep real time,
      // as the PLC's clock does, or the program's supervision times would run against a
      // slowed-down plant. Beyond a second behind, the rest is dropped.
      int steps = 1;
      if (now - next > std::chrono::nanoseconds(opt.tick_ns)) {
        ++stats->late_steps;
        auto behind = (now - next) / std::chrono::nanoseconds(opt.tick_ns);
        const int64_t max_catch_up = std::max<int64_t>(1, 1'000'000'000 / opt.tick_ns);
        steps = static_cast<int>(std::min<int64_t>(behind, max_catch_up)) + 1;
        if (behind > max_catch_up) next = now - std::chrono::nanoseconds(opt.tick_ns) * max_catch_up;
      }
      if (c.map->tab_registers[kResetRegister] != 0) {
        // A test system asks for a new start: the plant back to its initial state.
        c.map->tab_registers[kResetRegister] = 0;
        plant.reset(opt.seed + ++stats->resets);
        plant.sense(sen.data());
        publish();
      }
      for (const auto& b : bind) {
        if (b.input) continue;
        act[b.signal] = b.bit ? c.map->tab_bits[b.index] : static_cast<double>(static_cast<int16_t>(c.map->tab_registers[b.index]));
      }
      for (int k = 0; k < steps; ++k) {
        plant.step(dt, act.data(), sen.data());
        ++stats->steps;
        next += std::chrono::nanoseconds(opt.tick_ns);
      }
      publish();
      continue;
    }
    // Wait for requests until the next step is due.
    fd_set rd;
    FD_ZERO(&rd);
    FD_SET(c.server, &rd);
    int maxfd = c.server;
    for (int fd : clients) {
      FD_SET(fd, &rd);
      maxfd = std::max(maxfd, fd);
    }
    auto wait = running ? std::chrono::duration_cast<std::chrono::microseconds>(next - now) : std::chrono::microseconds(20'000);
    timeval tv{static_cast<time_t>(wait.count() / 1'000'000), static_cast<suseconds_t>(wait.count() % 1'000'000)};
    int r = select(maxfd + 1, &rd, nullptr, nullptr, &tv);
    if (r < 0) {
      if (errno == EINTR) continue;
      *err = std::string("select: ") + std::strerror(errno);
      break;
    }
    if (r == 0) continue;
    if (FD_ISSET(c.server, &rd)) {
      int fd = modbus_tcp_pi_accept(c.ctx, &c.server);
      if (fd >= 0) {
        clients.push_back(fd);
        ++stats->connections;
      }
    }
    for (size_t k = 0; k < clients.size();) {
      int fd = clients[k];
      if (!FD_ISSET(fd, &rd)) {
        ++k;
        continue;
      }
      modbus_set_socket(c.ctx, fd);
      int n = modbus_receive(c.ctx, query.data());
      if (n > 0) {
        ++stats->requests;
        // A lost request: answered never. The draw comes first so that the sequence of
        // losses depends on the seed and the request count only.
        rng = rng * 6364136223846793005ull + 1442695040888963407ull;
        const double u = static_cast<double>(rng >> 11) * 0x1.0p-53;
        if (u < opt.drop_rate) {
          ++stats->dropped;
        } else {
          if (opt.stall_ns > 0) {
            std::this_thread::sleep_for(std::chrono::nanoseconds(opt.stall_ns));
            ++stats->stalled;
          }
          modbus_reply(c.ctx, query.data(), n, c.map);
        }
        ++k;
      } else if (n == 0) {
        ++k;  // a request for another unit on RTU; not on TCP
      } else {
        ::close(fd);  // the client went away or sent garbage
        clients.erase(clients.begin() + static_cast<long>(k));
      }
    }
  }
  for (int fd : clients) ::close(fd);
  modbus_set_socket(c.ctx, -1);
  return err->empty();
}

}  // namespace plcfi::io
