// Fuzz target: the Modbus backend's reply path. A loopback TCP peer in this process answers
// each request of the backend with the next piece of the fuzzer's input, so plcfi's
// read()/write()/reset(), its reconnect state machine and libmodbus's reply checks meet
// arbitrary replies: wrong ids, short, long, exceptions, closed connections.
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "io/modbus/modbus_backend.hpp"

namespace {

constexpr int64_t kCycleNs = 10'000'000;
// Short: a reply that stops half-way costs the backend one timeout, and the fuzzer many.
constexpr int64_t kTimeoutNs = 3'000'000;

// The peer's script is the input cut into replies, each [mode][length][length bytes].
// Mode bit 0: the request's transaction id goes in front (libmodbus drops replies with
// another id, so most replies need it; without it a wrong id is tried too). Bit 1: the
// connection closes after this reply. Once the script is used up the peer closes the
// connection without a reply.
class Peer {
 public:
  Peer() {
    listen_fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    socklen_t len = sizeof a;
    if (listen_fd_ < 0 || bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || listen(listen_fd_, 8) != 0 ||
        getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
      std::perror("fuzz_modbus_reply: loopback listener");
      std::abort();
    }
    port_ = ntohs(a.sin_port);
    // The peer lives as long as the process (libFuzzer exits without unwinding).
    std::thread([this] { serve(); }).detach();
  }

  int port() const { return port_; }

  void set_script(const uint8_t* data, size_t size) {
    std::lock_guard<std::mutex> lock(mu_);
    script_.assign(data, data + size);
    pos_ = 0;
  }

 private:
  void serve() {
    for (;;) {
      int c = accept(listen_fd_, nullptr, nullptr);
      if (c < 0) continue;
      serve_connection(c);
      ::close(c);
    }
  }

  // Reads exactly n bytes; false when the backend closed or went silent for a second.
  static bool read_exact(int fd, uint8_t* p, size_t n) {
    while (n > 0) {
      pollfd pfd{fd, POLLIN, 0};
      if (poll(&pfd, 1, 1000) <= 0) return false;
      ssize_t r = recv(fd, p, n, 0);
      if (r <= 0) return false;
      p += r;
      n -= static_cast<size_t>(r);
    }
    return true;
  }

  void serve_connection(int c) {
    for (;;) {
      // A Modbus TCP request: MBAP header (transaction id 2, protocol 2, length 2), then
      // `length` bytes (unit id and PDU).
      uint8_t req[6 + 256];
      if (!read_exact(c, req, 6)) return;
      size_t len = static_cast<size_t>(req[4]) << 8 | req[5];
      if (len == 0 || len > 256 || !read_exact(c, req + 6, len)) return;
      std::vector<uint8_t> reply;
      bool close_after = false;
      {
        std::lock_guard<std::mutex> lock(mu_);
        if (pos_ + 2 > script_.size()) return;
        uint8_t mode = script_[pos_];
        size_t n = std::min<size_t>(script_[pos_ + 1], script_.size() - pos_ - 2);
        pos_ += 2;
        if (mode & 1) reply = {req[0], req[1]};
        reply.insert(reply.end(), script_.begin() + static_cast<std::ptrdiff_t>(pos_),
                     script_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
        pos_ += n;
        close_after = (mode & 2) != 0;
      }
      if (!reply.empty() && send(c, reply.data(), reply.size(), MSG_NOSIGNAL) < 0) return;
      if (close_after) return;
    }
  }

  int listen_fd_ = -1;
  int port_ = 0;
  std::mutex mu_;
  std::vector<uint8_t> script_;
  size_t pos_ = 0;
};

Peer* g_peer = nullptr;

plcfi::rt::ImageRef bit_ref(char area, uint32_t byte, uint8_t bit) {
  plcfi::rt::ImageRef r;
  r.area = area;
  r.offset = byte;
  r.is_bit = true;
  r.bit = bit;
  r.size = 1;
  return r;
}

plcfi::rt::ImageRef word_ref(char area, uint32_t byte) {
  plcfi::rt::ImageRef r;
  r.area = area;
  r.offset = byte;
  r.size = 2;
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  g_peer = new Peer();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  if (size < 2) return 0;
  // The first two bytes size two blocks, so replies of every length meet a request
  // that expects them.
  int registers = 1 + data[0] % 125;
  int inputs = 1 + data[1] % 200;
  g_peer->set_script(data + 2, size - 2);

  io::IoConfig cfg;
  io::ModbusDevice d;
  d.name = "peer";
  d.host = "127.0.0.1";
  d.port = std::to_string(g_peer->port());
  d.unit = 1;
  d.timeout_ns = kTimeoutNs;
  d.reconnect_min_ns = 0;  // reconnect at once: every request meets the script
  d.reconnect_max_ns = 0;
  d.has_status = true;
  d.status = bit_ref('I', 0, 0);
  d.reset_register = 100;
  d.where = "fuzz:1:1";
  cfg.devices.push_back(d);
  auto point = [&](io::ModbusTable table, int address, int count, rt::ImageRef image) {
    io::ModbusPoint p;
    p.table = table;
    p.address = address;
    p.count = count;
    p.image = image;
    p.where = "fuzz:1:1";
    cfg.points.push_back(p);
  };
  point(io::ModbusTable::DiscreteInputs, 0, inputs, bit_ref('I', 2, 0));
  point(io::ModbusTable::Coils, 0, 6, bit_ref('I', 40, 0));
  point(io::ModbusTable::InputRegisters, 2, registers, word_ref('I', 42));
  point(io::ModbusTable::HoldingRegisters, 10, 2, word_ref('I', 300));
  point(io::ModbusTable::Coils, 0, 6, bit_ref('Q', 0, 0));
  point(io::ModbusTable::HoldingRegisters, 2, 3, word_ref('Q', 2));

  std::string err;
  auto backend = io::ModbusBackend::create(cfg, kCycleNs, &err);
  if (!backend) {
    std::fprintf(stderr, "fuzz_modbus_reply: %s\n", err.c_str());
    std::abort();
  }
  std::vector<uint8_t> in(backend->input_extent()), out(backend->output_extent(), 0x5a);
  for (int scan = 0; scan < 3; ++scan) {
    (void)backend->read(in.data(), scan * kCycleNs);
    (void)backend->write(out.data(), scan * kCycleNs, kCycleNs);
  }
  backend->reset(0);
  (void)backend->read(in.data(), 3 * kCycleNs);
  (void)backend->lost_device();
  return 0;
}
