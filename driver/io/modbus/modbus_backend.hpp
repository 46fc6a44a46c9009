// Modbus master backend (libmodbus): the image exchanged with Modbus TCP/RTU units in the
// scan, one request per contiguous block of a device table (FC01/02/03/04 in read(),
// FC15/16 in write()), with a response timeout below the cycle time and our own
// reconnect state machine (exponential backoff; libmodbus's link recovery is never
// enabled, it can block for ever). On a failed exchange the image keeps the last good
// inputs, the device's status bit (a mapped %IX) goes FALSE and the error is counted.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/io_config.hpp"
#include "runtime/backend.hpp"

typedef struct _modbus modbus_t;  // NOLINT: libmodbus's opaque context

namespace plcfi::io {

struct DeviceStats {
  uint64_t requests = 0, failures = 0, connects = 0, disconnects = 0;
  uint64_t missed = 0;  // scans in which the device was down (not connected): no exchange at all
  bool up = false;
  std::string last_error;  // "plant (127.0.0.1:1502) unit 1: read discrete_inputs 0..15: Connection refused"
};

class ModbusBackend final : public rt::IoBackend {
 public:
  // Builds the request blocks; does not connect yet (the first read() does). cycle_ns
  // bounds the response timeout (default: half the cycle) of devices without timeout:.
  static std::unique_ptr<ModbusBackend> create(const IoConfig& cfg, int64_t cycle_ns, std::string* err);
  ~ModbusBackend() override;

  const std::string& name() const override { return name_; }
  uint32_t input_extent() const override { return in_extent_; }
  uint32_t output_extent() const override { return out_extent_; }
  // Contract: scan thread only. Never blocks longer than the devices' response timeouts
  // (one per block) plus one connect attempt per device that is due for it.
  bool read(uint8_t* inputs, int64_t now_ns) override;
  bool write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) override;
  // Up to kFinalAttempts writes, each after reconnecting at once (no backoff) to a device
  // dropped by the one before; broken links (test scripts) are ignored.
  bool write_final(const uint8_t* outputs, int64_t now_ns) override;
  static constexpr int kFinalAttempts = 5;
  // A restart: devices with a reset_register get 1 written there (a plant that can be
  // re-initialized remotely, as plcfi plant-server); others are left as they are.
  void reset(uint64_t seed) override;
  const std::string& last_error() const override { return error_; }

  const std::vector<DeviceStats>& stats() const { return stats_; }
  // The Modbus devices of the io file; a broken link skips their requests (each counted
  // as failed) as a pulled cable would, without touching the connection.
  std::vector<std::string> link_devices() const override;
  bool break_link(const std::string& device, int64_t from_ns, int64_t duration_ns) override;
  // Failed requests of every device (a timeout, a refused or broken connection, a short
  // or wrong answer), and the scans in which a device was down and not asked at all.
  uint64_t failed_exchanges() const override {
    uint64_t n = 0;
    for (const auto& s : stats_) n += s.failures + s.missed;
    return n;
  }
  // The device that has been down longer than its lost_after, on the monotonic clock
  // (SIZE_MAX: none).
  size_t lost_device() const;
  const IoConfig& config() const { return cfg_; }
  // Closes every connection (the driver writes the safe state before).
  void close();

 private:
  struct Block {
    size_t device;
    ModbusTable table;
    int address, count;
    bool output;                 // written in write() (coils/holding registers mapped to %Q)
    std::vector<const ModbusPoint*> points;
  };
  struct Device {
    modbus_t* ctx = nullptr;
    bool connected = false;
    int64_t next_attempt = 0, backoff = 0, down_since = -1;
    int64_t broken_from = 0, broken_to = 0;  // an injected link fault, on the scan clock
  };
  ModbusBackend() = default;
  bool ensure(size_t d, int64_t now);
  void drop(size_t d, int64_t now, const std::string& what);
  std::string label(size_t d) const;

  IoConfig cfg_;
  std::vector<Block> blocks_;
  std::vector<Device> dev_;
  std::vector<DeviceStats> stats_;
  std::vector<uint8_t> bits_;
  std::vector<uint16_t> regs_;
  int64_t timeout_default_ = 0;
  uint32_t in_extent_ = 0, out_extent_ = 0;
  std::string name_ = "modbus", error_;
};

}  // namespace plcfi::io
