// Modbus master backend: blocks, exchange in the scan, reconnect with backoff.
#include "modbus_backend.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <limits>

#include <fmt/format.h>
#include <modbus/modbus.h>

namespace plcfi::io {

namespace {

// Reconnect timing and lost_after run on the monotonic clock: the scan clock restarts at
// zero with every cold restart of a campaign, the devices' connections do not.
int64_t mono() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool is_bits(ModbusTable t) { return t == ModbusTable::Coils || t == ModbusTable::DiscreteInputs; }

// Protocol limits per request (Modbus application protocol, FC01-04, FC15, FC16).
int max_count(ModbusTable t, bool write) {
  if (is_bits(t)) return write ? 1968 : 2000;
  return write ? 123 : 125;
}

}  // namespace

std::unique_ptr<ModbusBackend> ModbusBackend::create(const IoConfig& cfg, int64_t cycle_ns, std::string* err) {
  std::unique_ptr<ModbusBackend> b(new ModbusBackend());
  b->cfg_ = cfg;
  b->timeout_default_ = std::max<int64_t>(cycle_ns / 2, 100'000);
  // A device that does not answer must not stretch the scan past its deadline.
  for (const auto& d : cfg.devices)
    if (d.timeout_ns >= cycle_ns) {
      *err = fmt::format("{}: device '{}': timeout {} ms is not below the cycle time {} ms (a silent device would make "
                         "every scan overrun)",
                         d.where, d.name, static_cast<double>(d.timeout_ns) / 1e6, static_cast<double>(cycle_ns) / 1e6);
      return nullptr;
    }
  b->dev_.resize(cfg.devices.size());
  b->stats_.resize(cfg.devices.size());
  // Points grouped by device, table and direction, merged into contiguous blocks.
  std::vector<const ModbusPoint*> pts;
  for (const auto& p : b->cfg_.points) pts.push_back(&p);
  std::sort(pts.begin(), pts.end(), [](const ModbusPoint* x, const ModbusPoint* y) {
    return std::tie(x->device, x->table, x->image.area, x->address) < std::tie(y->device, y->table, y->image.area, y->address);
  });
  for (const ModbusPoint* p : pts) {
    bool out = p->image.area == 'Q';
    Block* last = b->blocks_.empty() ? nullptr : &b->blocks_.back();
    if (last && last->device == p->device && last->table == p->table && last->output == out && p->address <= last->address + last->count &&
        std::max(last->address + last->count, p->address + p->count) - last->address <= max_count(p->table, out)) {
      last->count = std::max(last->address + last->count, p->address + p->count) - last->address;
      last->points.push_back(p);
    } else {
      if (p->count > max_count(p->table, out)) {
        *err = fmt::format("{}: {} {} points in one mapping; Modbus allows {} per request", p->where, p->count,
                           table_name(p->table), max_count(p->table, out));
        return nullptr;
      }
      b->blocks_.push_back(Block{p->device, p->table, p->address, p->count, out, {p}});
    }
    uint32_t end = is_bits(p->table) ? (p->image.offset * 8 + p->image.bit + static_cast<uint32_t>(p->count) + 7) / 8
                                     : p->image.offset + 2 * static_cast<uint32_t>(p->count);
    (out ? b->out_extent_ : b->in_extent_) = std::max(out ? b->out_extent_ : b->in_extent_, end);
  }
  for (const auto& d : b->cfg_.devices)
    if (d.has_status) b->in_extent_ = std::max(b->in_extent_, d.status.offset + 1);
  b->bits_.resize(2000);
  b->regs_.resize(125);
  return b;
}

ModbusBackend::~ModbusBackend() { close(); }

void ModbusBackend::close() {
  for (auto& d : dev_) {
    if (d.ctx) {
      modbus_close(d.ctx);
      modbus_free(d.ctx);
    }
    d.ctx = nullptr;
    d.connected = false;
  }
}

std::string ModbusBackend::label(size_t i) const {
  const auto& d = cfg_.devices[i];
  if (d.rtu) return fmt::format("{} ({}) unit {}", d.name, d.device, d.unit);
  bool v6 = d.host.find(':') != std::string::npos;
  return fmt::format("{} ({}{}{}:{}) unit {}", d.name, v6 ? "[" : "", d.host, v6 ? "]" : "", d.port, d.unit);
}

void ModbusBackend::drop(size_t i, int64_t now, const std::string& what) {
  Device& d = dev_[i];
  const auto& c = cfg_.devices[i];
  if (d.connected) ++stats_[i].disconnects;
  if (d.ctx) modbus_close(d.ctx);
  d.connected = false;
  stats_[i].up = false;
  if (d.down_since < 0) d.down_since = now;
  d.backoff = d.backoff == 0 ? c.reconnect_min_ns : std::min(2 * d.backoff, c.reconnect_max_ns);
  d.next_attempt = now + d.backoff;
  stats_[i].last_error = label(i) + ": " + what;
  error_ = stats_[i].last_error;
}

bool ModbusBackend::ensure(size_t i, int64_t now) {
  Device& d = dev_[i];
  if (d.connected) return true;
  if (now < d.next_attempt) return false;
  const auto& c = cfg_.devices[i];
  if (!d.ctx) {
    d.ctx = c.rtu ? modbus_new_rtu(c.device.c_str(), c.baud, c.parity, c.data_bits, c.stop_bits)
                  : modbus_new_tcp_pi(c.host.c_str(), c.port.c_str());
    if (!d.ctx) {
      drop(i, now, std::string("cannot create the Modbus context: ") + modbus_strerror(errno));
      return false;
    }
    // No link recovery: a failed exchange returns at once and this state machine decides.
    modbus_set_error_recovery(d.ctx, MODBUS_ERROR_RECOVERY_NONE);
  }
  int64_t to = c.timeout_ns > 0 ? c.timeout_ns : timeout_default_;
  modbus_set_response_timeout(d.ctx, static_cast<uint32_t>(to / 1'000'000'000), static_cast<uint32_t>((to % 1'000'000'000) / 1000));
  modbus_set_byte_timeout(d.ctx, static_cast<uint32_t>(to / 1'000'000'000), static_cast<uint32_t>((to % 1'000'000'000) / 1000));
  modbus_set_slave(d.ctx, c.unit);
  if (modbus_connect(d.ctx) != 0) {
    drop(i, now, std::string("connect: ") + modbus_strerror(errno));
    return false;
  }
  // The serial mode is set on the open line (libmodbus needs the file descriptor);
  // RS232 is the line's default, so setting it costs no ioctl.
  if (c.rtu && modbus_rtu_set_serial_mode(d.ctx, c.rs485 ? MODBUS_RTU_RS485 : MODBUS_RTU_RS232) != 0) {
    drop(i, now, std::string(c.rs485 ? "RS485" : "RS232") + " mode: " + modbus_strerror(errno));
    return false;
  }
  d.connected = true;
  d.backoff = 0;
  d.down_since = -1;
  ++stats_[i].connects;
  stats_[i].up = true;
  return true;
}

size_t ModbusBackend::lost_device() const {
  const int64_t now = mono();
  for (size_t i = 0; i < dev_.size(); ++i) {
    const auto& c = cfg_.devices[i];
    if (c.lost_after_ns > 0 && dev_[i].down_since >= 0 && now - dev_[i].down_since >= c.lost_after_ns) return i;
  }
  return SIZE_MAX;
}

void ModbusBackend::reset(uint64_t) {
  const int64_t now = mono();
  for (size_t i = 0; i < dev_.size(); ++i) {
    int reg = cfg_.devices[i].reset_register;
    if (reg < 0 || !ensure(i, now)) continue;
    ++stats_[i].requests;
    if (modbus_write_register(dev_[i].ctx, reg, 1) != 1) {
      ++stats_[i].failures;
      drop(i, now, fmt::format("reset (holding register {}): {}", reg, modbus_strerror(errno)));
    }
  }
}

std::vector<std::string> ModbusBackend::link_devices() const {
  std::vector<std::string> d;
  for (const auto& c : cfg_.devices) d.push_back(c.name);
  return d;
}

bool ModbusBackend::break_link(const std::string& device, int64_t from_ns, int64_t duration_ns) {
  for (size_t i = 0; i < cfg_.devices.size(); ++i)
    if (cfg_.devices[i].name == device) {
      dev_[i].broken_from = from_ns;
      dev_[i].broken_to = from_ns + duration_ns;
      return true;
    }
  return false;
}

bool ModbusBackend::read(uint8_t* inputs, int64_t scan_ns) {
  const int64_t now = mono();
  bool ok = true;
  auto broken = [&](size_t d) { return scan_ns >= dev_[d].broken_from && scan_ns < dev_[d].broken_to; };
  for (size_t i = 0; i < dev_.size(); ++i)
    if (!broken(i) && !ensure(i, now)) {
      ok = false;
      ++stats_[i].missed;
    }
  for (const Block& b : blocks_) {
    if (b.output) continue;
    if (broken(b.device)) {
      // The injected fault: the request is lost on the way; the image keeps its values.
      ++stats_[b.device].requests;
      ++stats_[b.device].failures;
      ok = false;
      continue;
    }
    if (!dev_[b.device].connected) continue;
    modbus_t* ctx = dev_[b.device].ctx;
    int n = -1;
    switch (b.table) {
      case ModbusTable::Coils: n = modbus_read_bits(ctx, b.address, b.count, bits_.data()); break;
      case ModbusTable::DiscreteInputs: n = modbus_read_input_bits(ctx, b.address, b.count, bits_.data()); break;
      case ModbusTable::HoldingRegisters: n = modbus_read_registers(ctx, b.address, b.count, regs_.data()); break;
      case ModbusTable::InputRegisters: n = modbus_read_input_registers(ctx, b.address, b.count, regs_.data()); break;
    }
    ++stats_[b.device].requests;
    if (n != b.count) {
      ++stats_[b.device].failures;
      drop(b.device, now,
           fmt::format("read {} {}..{}: {}", table_name(b.table), b.address, b.address + b.count - 1,
                       n < 0 ? modbus_strerror(errno) : "short answer"));
      ok = false;
      continue;  // the image keeps the last good values of this block
    }
    for (const ModbusPoint* p : b.points) {
      int first = p->address - b.address;
      for (int k = 0; k < p->count; ++k) {
        if (is_bits(b.table)) {
          uint32_t bit = p->image.offset * 8 + p->image.bit + static_cast<uint32_t>(k);
          uint8_t mask = static_cast<uint8_t>(1u << (bit % 8));
          inputs[bit / 8] = static_cast<uint8_t>(bits_[static_cast<size_t>(first + k)] ? inputs[bit / 8] | mask : inputs[bit / 8] & ~mask);
        } else {
          uint16_t v = regs_[static_cast<size_t>(first + k)];
          inputs[p->image.offset + 2 * k] = static_cast<uint8_t>(v & 0xff);
          inputs[p->image.offset + 2 * k + 1] = static_cast<uint8_t>(v >> 8);
        }
      }
    }
  }
  for (size_t i = 0; i < dev_.size(); ++i)
    if (cfg_.devices[i].has_status) cfg_.devices[i].status.set(inputs, dev_[i].connected && !broken(i) ? 1 : 0);
  return ok;
}

bool ModbusBackend::write(const uint8_t* outputs, int64_t scan_ns, int64_t) {
  const int64_t now = mono();
  bool ok = true;
  for (const Block& b : blocks_) {
    if (b.output && scan_ns >= dev_[b.device].broken_from && scan_ns < dev_[b.device].broken_to) {
      ++stats_[b.device].requests;
      ++stats_[b.device].failures;
      ok = false;
      continue;
    }
    if (!b.output || !dev_[b.device].connected) {
      if (b.output) ok = false;
      continue;
    }
    for (const ModbusPoint* p : b.points) {
      int first = p->address - b.address;
      for (int k = 0; k < p->count; ++k) {
        if (is_bits(b.table)) {
          uint32_t bit = p->image.offset * 8 + p->image.bit + static_cast<uint32_t>(k);
          bits_[static_cast<size_t>(first + k)] = (outputs[bit / 8] >> (bit % 8)) & 1;
        } else {
          regs_[static_cast<size_t>(first + k)] =
              static_cast<uint16_t>(outputs[p->image.offset + 2 * k] | (outputs[p->image.offset + 2 * k + 1] << 8));
        }
      }
    }
    modbus_t* ctx = dev_[b.device].ctx;
    int n = is_bits(b.table) ? modbus_write_bits(ctx, b.address, b.count, bits_.data())
                             : modbus_write_registers(ctx, b.address, b.count, regs_.data());
    ++stats_[b.device].requests;
    if (n != b.count) {
      ++stats_[b.device].failures;
      drop(b.device, now,
           fmt::format("write {} {}..{}: {}", table_name(b.table), b.address, b.address + b.count - 1,
                       n < 0 ? modbus_strerror(errno) : "short answer"));
      ok = false;
    }
  }
  return ok;
}

bool ModbusBackend::write_final(const uint8_t* outputs, int64_t) {
  for (int attempt = 0; attempt < kFinalAttempts; ++attempt) {
    for (size_t i = 0; i < dev_.size(); ++i) {
      dev_[i].next_attempt = 0;
      ensure(i, mono());
    }
    // A scan time before every broken link's window: the safe state is not held back.
    if (write(outputs, std::numeric_limits<int64_t>::min(), 0)) return true;
  }
  return false;
}

}  // namespace plcfi::io
