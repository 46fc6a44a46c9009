// The `io:` section of run and campaign files: which devices exist (Modbus TCP/RTU units)
// and which image ranges map to which of their points. Parsed and checked against the
// application's image once, before the first scan; errors name FILE:LINE:COL.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/image.hpp"

namespace plcfi::io {

enum class ModbusTable { Coils, DiscreteInputs, HoldingRegisters, InputRegisters };
const char* table_name(ModbusTable t);

struct ModbusDevice {
  std::string name;
  bool rtu = false;
  // TCP: host name or address (IPv6 too) and service/port.
  std::string host, port = "502";
  // RTU: serial device and line settings.
  std::string device;
  int baud = 19200;
  char parity = 'N';
  int data_bits = 8, stop_bits = 1;
  bool rs485 = false;
  int unit = 1;
  int64_t timeout_ns = 0;          // response timeout; 0: half the cycle time
  int64_t reconnect_min_ns = 100'000'000, reconnect_max_ns = 5'000'000'000;
  bool has_status = false;
  rt::ImageRef status;             // %IX bit: TRUE while the device answers
  int64_t lost_after_ns = 0;       // communication lost this long: the run stops in the safe state (0: never)
  int reset_register = -1;         // holding register written with 1 to restart the plant (a campaign's restart), -1: none
  std::string where;               // FILE:LINE:COL of its entry
};

// One mapping: `count` consecutive points of a device table to consecutive image
// locations starting at `image` (bits for coils/discrete inputs, words for registers).
struct ModbusPoint {
  size_t device = 0;
  ModbusTable table = ModbusTable::Coils;
  int address = 0;
  int count = 1;
  rt::ImageRef image;  // first location; area I for inputs (discrete, input/holding read), Q for outputs
  std::string where;
};

struct IoConfig {
  std::string path;
  std::vector<ModbusDevice> devices;
  std::vector<ModbusPoint> points;
  // Outputs whose safe value is not 0 (written on every way out; all others go to 0).
  std::vector<std::pair<rt::ImageRef, int64_t>> safe_state;
  bool empty() const { return devices.empty(); }
};

// Reads the `io:` section of `path` (a file whose top level has `io:`, or that is the
// section itself). Image addresses resolve against `app`. Returns false with
// "FILE:LINE:COL: message" in *err.
bool load_io_config(const std::string& path, const st::Application& app, IoConfig* out, std::string* err);

}  // namespace plcfi::io
