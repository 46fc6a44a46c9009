// The one in-process Modbus TCP slave of the tests and benchmarks: libmodbus serving a
// register map on a thread. stop() closes every socket at once (a device that crashed);
// start() brings it back on the same port.
#pragma once

#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

namespace plcfi::testing_support {

class ModbusSlave {
 public:
  // port 0: any free port (port() tells which). `host` may be an IPv6 address. Each of the
  // four tables has `table_size` entries, all zero.
  explicit ModbusSlave(int port = 0, std::string host = "127.0.0.1", int table_size = 64)
      : port_(port), host_(std::move(host)) {
    map_ = modbus_mapping_new(table_size, table_size, table_size, table_size);
    start();
  }
  ~ModbusSlave() {
    stop();
    modbus_mapping_free(map_);
  }
  ModbusSlave(const ModbusSlave&) = delete;
  ModbusSlave& operator=(const ModbusSlave&) = delete;

  void start() {
    stop_ = false;
    // libmodbus sets SO_REUSEADDR: a restart rebinds at once.
    if (ipv6()) {  // the protocol-independent calls
      ctx_ = modbus_new_tcp_pi(host_.c_str(), std::to_string(port_).c_str());
      listen_ = modbus_tcp_pi_listen(ctx_, 4);
    } else {
      ctx_ = modbus_new_tcp(host_.c_str(), port_);
      listen_ = modbus_tcp_listen(ctx_, 4);
    }
    if (port_ == 0 && listen_ >= 0) {
      sockaddr_storage a{};
      socklen_t len = sizeof a;
      getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &len);
      port_ = ntohs(a.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&a)->sin6_port
                                            : reinterpret_cast<sockaddr_in*>(&a)->sin_port);
    }
    thread_ = std::thread([this] { loop(); });
  }
  void stop() {
    if (!ctx_) return;
    stop_ = true;
    thread_.join();
    if (listen_ >= 0) ::close(listen_);
    modbus_free(ctx_);
    ctx_ = nullptr;
  }
  int port() const { return port_; }
  // Written by the test before clients ask, read by the serving thread on each request.
  modbus_mapping_t* map() { return map_; }
  // Requests answered so far, counted before the reply goes out: a client that got its
  // answer sees its request counted.
  std::atomic<int> requests{0};

 private:
  bool ipv6() const { return host_.find(':') != std::string::npos; }
  void loop() {
    std::vector<int> clients;
    uint8_t q[MODBUS_TCP_MAX_ADU_LENGTH];
    while (!stop_) {
      fd_set rd;
      FD_ZERO(&rd);
      FD_SET(listen_, &rd);
      int mx = listen_;
      for (int c : clients) FD_SET(c, &rd), mx = std::max(mx, c);
      timeval tv{0, 20'000};
      if (select(mx + 1, &rd, nullptr, nullptr, &tv) <= 0) continue;
      if (FD_ISSET(listen_, &rd)) {
        int c = ipv6() ? modbus_tcp_pi_accept(ctx_, &listen_) : modbus_tcp_accept(ctx_, &listen_);
        if (c >= 0) clients.push_back(c);
      }
      for (size_t i = 0; i < clients.size();) {
        if (!FD_ISSET(clients[i], &rd)) {
          ++i;
          continue;
        }
        modbus_set_socket(ctx_, clients[i]);
        int n = modbus_receive(ctx_, q);
        if (n > 0) {
          ++requests;
          modbus_reply(ctx_, q, n, map_);
          ++i;
        } else if (n < 0) {
          ::close(clients[i]);
          clients.erase(clients.begin() + static_cast<long>(i));
        } else {
          ++i;
        }
      }
    }
    for (int c : clients) ::close(c);
    modbus_set_socket(ctx_, -1);
  }

  int port_;
  std::string host_;
  modbus_t* ctx_ = nullptr;
  modbus_mapping_t* map_ = nullptr;
  int listen_ = -1;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace plcfi::testing_support
