// The devices of a run on real I/O (a bench): every backend an `io:` section names (Modbus units, GPIO chips)
// behind one IoBackend, plus what the run loop needs to know about them: whether a
// device has been lost for longer than allowed, and their statistics for the end report.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "io/io_config.hpp"
#include "runtime/backend.hpp"

namespace plcfi::io {

class ModbusBackend;
class GpioBackend;

class DeviceIo final : public rt::IoBackend {
 public:
  // Opens (GPIO) or prepares (Modbus: connects in the first read) every backend of cfg.
  static std::unique_ptr<DeviceIo> open(const IoConfig& cfg, int64_t cycle_ns, std::string* err);
  ~DeviceIo() override;

  const std::string& name() const override { return name_; }
  uint32_t input_extent() const override;
  uint32_t output_extent() const override;
  bool read(uint8_t* inputs, int64_t now_ns) override;
  bool write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) override;
  bool write_final(const uint8_t* outputs, int64_t now_ns) override;
  void reset(uint64_t seed) override;
  const std::string& last_error() const override { return error_; }
  std::vector<std::string> link_devices() const override;
  bool break_link(const std::string& device, int64_t from_ns, int64_t duration_ns) override;
  uint64_t failed_exchanges() const override {
    uint64_t n = 0;
    for (const auto* p : parts_) n += p->failed_exchanges();
    return n;
  }

  // "" or the lost device's last error (down longer than its lost_after).
  std::string lost() const;
  // One line per device or request: requests, failures, (re)connects, last error.
  std::vector<std::string> report() const;
  const IoConfig& config() const { return cfg_; }
  // Closes every backend; the caller writes the safe state before.
  void close();

 private:
  DeviceIo() = default;
  IoConfig cfg_;
  template <typename Op>
  bool each_part(Op op);
  std::vector<rt::IoBackend*> parts_;
  std::unique_ptr<ModbusBackend> modbus_;
  std::unique_ptr<GpioBackend> gpio_;
  std::string name_ = "bench", error_;
};

}  // namespace plcfi::io
