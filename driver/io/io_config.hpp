// The `io:` section of run and campaign files: which devices exist (Modbus TCP/RTU units,
// GPIO chips) and which image ranges map to which of their points. Parsed and checked against the
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

// A GPIO chip (libgpiod): by name (gpiochip0), path (/dev/gpiochip0), label or number.
struct GpioDevice {
  std::string name;
  std::string chip;
  std::string where;
};

enum class GpioBias { AsIs, Disabled, PullUp, PullDown };
enum class GpioDrive { PushPull, OpenDrain, OpenSource };
const char* bias_name(GpioBias b);
const char* drive_name(GpioDrive d);

// Lines of one chip to consecutive image bits from `image` (%IX: inputs, %QX: outputs).
// Each line is an offset or a line name (resolved when the chip is opened).
struct GpioPoint {
  size_t device = 0;  // index in gpio_devices
  struct Line {
    int offset = -1;   // -1: by name
    std::string name;
  };
  std::vector<Line> lines;
  rt::ImageRef image;
  bool active_low = false;
  GpioBias bias = GpioBias::AsIs;
  GpioDrive drive = GpioDrive::PushPull;
  std::string where;
};

struct IoConfig {
  std::string path;
  std::vector<ModbusDevice> devices;  // Modbus units
  std::vector<ModbusPoint> points;
  std::vector<GpioDevice> gpio_devices;
  std::vector<GpioPoint> gpio_points;
  // Outputs whose safe value is not 0 (written on every way out; all others go to 0).
  std::vector<std::pair<rt::ImageRef, int64_t>> safe_state;
  bool empty() const { return devices.empty() && gpio_devices.empty(); }
};

// Reads the `io:` section of `path` (a file whose top level has `io:`, or that is the
// section itself). Image addresses resolve against `app`. Returns false with
// "FILE:LINE:COL: message" in *err.
bool load_io_config(const std::string& path, const st::Application& app, IoConfig* out, std::string* err);

}  // namespace plcfi::io
