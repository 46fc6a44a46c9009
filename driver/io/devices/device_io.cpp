// Bench I/O: Modbus and GPIO backends combined.
#include "device_io.hpp"

#include <algorithm>

#include <fmt/format.h>

#ifdef PLCFI_HAVE_MODBUS
#include "io/modbus/modbus_backend.hpp"
#endif
#ifdef PLCFI_HAVE_GPIO
#include "io/gpio/gpio_backend.hpp"
#endif

namespace plcfi::io {

std::unique_ptr<DeviceIo> DeviceIo::open(const IoConfig& cfg, int64_t cycle_ns, std::string* err) {
  std::unique_ptr<DeviceIo> b(new DeviceIo());
  b->cfg_ = cfg;
  if (!cfg.devices.empty()) {
#ifdef PLCFI_HAVE_MODBUS
    b->modbus_ = ModbusBackend::create(b->cfg_, cycle_ns, err);
    if (!b->modbus_) return nullptr;
    b->parts_.push_back(b->modbus_.get());
#else
    (void)cycle_ns;
    *err = cfg.devices[0].where + ": device '" + cfg.devices[0].name + "': this plcfi was built without Modbus (PLCFI_MODBUS=OFF)";
    return nullptr;
#endif
  }
  if (!cfg.gpio_devices.empty()) {
#ifdef PLCFI_HAVE_GPIO
    b->gpio_ = GpioBackend::open(b->cfg_, err);
    if (!b->gpio_) return nullptr;
    b->parts_.push_back(b->gpio_.get());
#else
    *err = cfg.gpio_devices[0].where + ": device '" + cfg.gpio_devices[0].name + "': this plcfi was built without GPIO (PLCFI_GPIO=OFF)";
    return nullptr;
#endif
  }
  return b;
}

DeviceIo::~DeviceIo() { close(); }

uint32_t DeviceIo::input_extent() const {
  uint32_t e = 0;
  for (auto* p : parts_) e = std::max(e, p->input_extent());
  return e;
}

uint32_t DeviceIo::output_extent() const {
  uint32_t e = 0;
  for (auto* p : parts_) e = std::max(e, p->output_extent());
  return e;
}

// Every part does `op`; false if any failed, with the last failure's error kept.
template <typename Op>
bool DeviceIo::each_part(Op op) {
  bool ok = true;
  for (auto* p : parts_)
    if (!op(*p)) {
      ok = false;
      error_ = p->last_error();
    }
  return ok;
}

bool DeviceIo::read(uint8_t* inputs, int64_t now_ns) {
  return each_part([&](rt::IoBackend& p) { return p.read(inputs, now_ns); });
}

bool DeviceIo::write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) {
  return each_part([&](rt::IoBackend& p) { return p.write(outputs, now_ns, dt_ns); });
}

bool DeviceIo::write_final(const uint8_t* outputs, int64_t now_ns) {
  return each_part([&](rt::IoBackend& p) { return p.write_final(outputs, now_ns); });
}

std::vector<std::string> DeviceIo::link_devices() const {
  std::vector<std::string> d;
  for (const auto* p : parts_)
    for (auto& n : p->link_devices()) d.push_back(std::move(n));
  return d;
}

bool DeviceIo::break_link(const std::string& device, int64_t from_ns, int64_t duration_ns) {
  for (auto* p : parts_)
    if (p->break_link(device, from_ns, duration_ns)) return true;
  return false;
}

void DeviceIo::reset(uint64_t seed) {
  for (auto* p : parts_) p->reset(seed);
}

std::string DeviceIo::lost() const {
#ifdef PLCFI_HAVE_MODBUS
  if (modbus_) {
    size_t d = modbus_->lost_device();
    if (d != SIZE_MAX) return modbus_->stats()[d].last_error;
  }
#endif
  return "";
}

std::vector<std::string> DeviceIo::report() const {
  std::vector<std::string> out;
#ifdef PLCFI_HAVE_MODBUS
  if (modbus_)
    for (size_t i = 0; i < cfg_.devices.size(); ++i) {
      const auto& d = modbus_->stats()[i];
      out.push_back(fmt::format("device {}: {} requests, {} failed, {} connect(s), {} disconnect(s){}", cfg_.devices[i].name,
                                d.requests, d.failures, d.connects, d.disconnects,
                                d.last_error.empty() ? "" : "; last error: " + d.last_error));
    }
#endif
#ifdef PLCFI_HAVE_GPIO
  if (gpio_) {
    for (const auto& l : gpio_->describe()) out.push_back("gpio " + l);
    if (gpio_->failures()) out.push_back(fmt::format("gpio: {} failed line operations; last error: {}", gpio_->failures(), gpio_->last_error()));
  }
#endif
  return out;
}

void DeviceIo::close() {
#ifdef PLCFI_HAVE_MODBUS
  if (modbus_) modbus_->close();
#endif
#ifdef PLCFI_HAVE_GPIO
  if (gpio_) gpio_->close();
#endif
}

}  // namespace plcfi::io
