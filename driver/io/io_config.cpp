// Parsing of the `io:` section (devices and image mappings).
#include "io_config.hpp"

#include <cctype>

#include <fmt/format.h>

#include "common/yaml.hpp"

namespace plcfi::io {

const char* table_name(ModbusTable t) {
  switch (t) {
    case ModbusTable::Coils: return "coils";
    case ModbusTable::DiscreteInputs: return "discrete_inputs";
    case ModbusTable::HoldingRegisters: return "holding_registers";
    case ModbusTable::InputRegisters: return "input_registers";
  }
  return "?";
}

const char* bias_name(GpioBias b) {
  switch (b) {
    case GpioBias::AsIs: return "as-is";
    case GpioBias::Disabled: return "disabled";
    case GpioBias::PullUp: return "pull-up";
    case GpioBias::PullDown: return "pull-down";
  }
  return "?";
}

const char* drive_name(GpioDrive d) {
  switch (d) {
    case GpioDrive::PushPull: return "push-pull";
    case GpioDrive::OpenDrain: return "open-drain";
    case GpioDrive::OpenSource: return "open-source";
  }
  return "?";
}

namespace {

// The io section's reader: the shared strict YAML getters (common/yaml.hpp) plus the
// image addresses and overlap checks of this file.
class Reader {
 public:
  Reader(const common::YamlDoc& doc, const st::Application& app) : doc_(doc), app_(app) {}

  std::string at(const YAML::Node& n) const { return doc_.where(n); }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& m) const { doc_.fail(n, m); }
  std::string str(const YAML::Node& n, const char* what) const { return doc_.scalar(n, what); }
  int64_t integer(const YAML::Node& n, const char* what, int64_t lo, int64_t hi) const { return doc_.integer(n, what, lo, hi); }
  int64_t duration(const YAML::Node& n, const char* what) const { return doc_.duration(n, what, 1); }
  void keys(const YAML::Node& m, std::initializer_list<std::string_view> allowed, const char* what) const {
    doc_.check_keys(m, allowed, what);
  }
  rt::ImageRef image(const YAML::Node& n, const char* what) const {
    rt::ImageRef r;
    std::string e;
    if (!rt::parse_image_ref(app_, str(n, what), &r, &e)) fail(n, e);
    return r;
  }

  void device(const YAML::Node& n, IoConfig* cfg) {
    if (!n.IsMap()) fail(n, "a device: expected a map (name:, and tcp:, rtu: or gpio:), got " + common::YamlDoc::describe(n));
    std::string name = str(doc_.required(n, "name", "a device"), "name");
    for (const auto& other : cfg->devices)
      if (other.name == name) fail(n["name"], "device '" + name + "' is defined twice");
    for (const auto& other : cfg->gpio_devices)
      if (other.name == name) fail(n["name"], "device '" + name + "' is defined twice");
    if (n["gpio"]) {
      keys(n, {"name", "gpio"}, "a GPIO device");
      GpioDevice g;
      g.where = at(n);
      g.name = name;
      g.chip = str(n["gpio"], "gpio");
      if (g.chip.empty()) fail(n["gpio"], "gpio names a chip: gpiochip0, /dev/gpiochip0, its label or its number");
      cfg->gpio_devices.push_back(g);
      return;
    }
    keys(n, {"name", "tcp", "rtu", "unit", "timeout", "status", "reconnect", "lost_after", "reset_register"}, "a device");
    ModbusDevice d;
    d.where = at(n);
    d.name = name;
    if (bool(n["tcp"]) == bool(n["rtu"])) fail(n, "a device is either tcp: HOST:PORT, rtu: {device: ...} or gpio: CHIP");
    if (n["tcp"]) {
      // "host:port", "[v6::addr]:port" or "host" (port 502).
      std::string t = str(n["tcp"], "tcp");
      if (!t.empty() && t[0] == '[') {
        size_t close = t.find(']');
        if (close == std::string::npos) fail(n["tcp"], "missing ']' in an IPv6 address");
        d.host = t.substr(1, close - 1);
        if (close + 1 < t.size()) {
          if (t[close + 1] != ':') fail(n["tcp"], "expected ':PORT' after ']'");
          d.port = t.substr(close + 2);
        }
      } else {
        size_t colon = t.rfind(':');
        if (colon != std::string::npos && t.find(':') == colon) {
          d.host = t.substr(0, colon);
          d.port = t.substr(colon + 1);
        } else {
          d.host = t;  // a bare host, or an IPv6 address without a port
        }
      }
      if (d.host.empty()) fail(n["tcp"], "empty host");
      if (d.port.empty()) fail(n["tcp"], "empty port");
    } else {
      const YAML::Node r = n["rtu"];
      keys(r, {"device", "baud", "parity", "data_bits", "stop_bits", "mode"}, "rtu");
      d.rtu = true;
      d.device = str(doc_.required(r, "device", "rtu"), "device");
      if (r["baud"]) d.baud = static_cast<int>(integer(r["baud"], "baud", 50, 4'000'000));
      if (r["parity"]) d.parity = doc_.word(r["parity"], "parity", {"N", "E", "O"})[0];
      if (r["data_bits"]) d.data_bits = static_cast<int>(integer(r["data_bits"], "data_bits", 5, 8));
      if (r["stop_bits"]) d.stop_bits = static_cast<int>(integer(r["stop_bits"], "stop_bits", 1, 2));
      if (r["mode"]) d.rs485 = doc_.word(r["mode"], "mode", {"rs232", "rs485"}) == "rs485";
    }
    if (n["unit"]) d.unit = static_cast<int>(integer(n["unit"], "unit", 0, 247));
    if (n["timeout"]) d.timeout_ns = duration(n["timeout"], "timeout");
    if (n["status"]) {
      d.status = image(n["status"], "status");
      if (d.status.area != 'I' || !d.status.is_bit) fail(n["status"], "status must be an input bit (%IXn.m)");
      d.has_status = true;
      uint64_t b = d.status.offset * 8u + d.status.bit;
      claim(n["status"], 'I', b, b + 1, d.where);
    }
    if (const YAML::Node rc = n["reconnect"]) {
      keys(rc, {"min", "max"}, "reconnect");
      if (rc["min"]) d.reconnect_min_ns = duration(rc["min"], "reconnect min");
      if (rc["max"]) d.reconnect_max_ns = duration(rc["max"], "reconnect max");
      if (d.reconnect_max_ns < d.reconnect_min_ns) fail(rc, "reconnect max is below min");
    }
    if (n["lost_after"]) d.lost_after_ns = duration(n["lost_after"], "lost_after");
    if (n["reset_register"]) d.reset_register = static_cast<int>(integer(n["reset_register"], "reset_register", 0, 65535));
    cfg->devices.push_back(d);
  }

  // Two mappings must not feed the same image bits (which one would win?).
  void claim(const YAML::Node& at_node, char area, uint64_t bit0, uint64_t bit1, const std::string& where) {
    for (const auto& r : ranges_)
      if (r.area == area && bit0 < r.bit1 && r.bit0 < bit1) fail(at_node, "overlaps the mapping at " + r.where);
    ranges_.push_back({area, bit0, bit1, where});
  }

  void gpio_point(const YAML::Node& n, size_t device, IoConfig* cfg) {
    keys(n, {"image", "device", "lines", "active_low", "bias", "drive"}, "a GPIO mapping");
    GpioPoint p;
    p.where = at(n);
    p.device = device;
    p.image = image(doc_.required(n, "image", "a GPIO mapping"), "image");
    if (!p.image.is_bit || (p.image.area != 'I' && p.image.area != 'Q'))
      fail(n["image"], "GPIO lines map to bits: %IXn.m (inputs) or %QXn.m (outputs)");
    const YAML::Node lines = doc_.required(n, "lines", "a GPIO mapping");
    doc_.list(lines, "lines");
    if (lines.size() > 64) fail(lines, "at most 64 lines per mapping (one bulk request)");
    for (const auto& l : lines) {
      GpioPoint::Line line;
      std::string t = str(l, "a line");
      if (!t.empty() && std::isdigit(static_cast<unsigned char>(t[0])))
        line.offset = static_cast<int>(integer(l, "line offset", 0, 65535));
      else if (t.empty())
        fail(l, "empty line name");
      else
        line.name = t;
      for (const auto& q : cfg->gpio_points) {
        if (q.device != device) continue;
        for (const auto& o : q.lines)
          if ((line.offset >= 0 && o.offset == line.offset) || (!line.name.empty() && o.name == line.name))
            fail(l, "line " + t + " is already mapped at " + q.where);
      }
      for (const auto& o : p.lines)
        if ((line.offset >= 0 && o.offset == line.offset) || (!line.name.empty() && o.name == line.name))
          fail(l, "line " + t + " is listed twice");
      p.lines.push_back(line);
    }
    if (n["active_low"]) p.active_low = doc_.boolean(n["active_low"], "active_low");
    if (n["bias"]) {
      std::string v = doc_.word(n["bias"], "bias", {"as-is", "disabled", "pull-up", "pull-down"});
      if (v == "as-is") p.bias = GpioBias::AsIs;
      else if (v == "disabled") p.bias = GpioBias::Disabled;
      else if (v == "pull-up") p.bias = GpioBias::PullUp;
      else p.bias = GpioBias::PullDown;
      if (p.image.area == 'Q') fail(n["bias"], "bias applies to inputs (%IX)");
    }
    if (n["drive"]) {
      std::string v = doc_.word(n["drive"], "drive", {"push-pull", "open-drain", "open-source"});
      if (v == "push-pull") p.drive = GpioDrive::PushPull;
      else if (v == "open-drain") p.drive = GpioDrive::OpenDrain;
      else p.drive = GpioDrive::OpenSource;
      if (p.image.area == 'I') fail(n["drive"], "drive applies to outputs (%QX)");
    }
    uint32_t area_size = p.image.area == 'I' ? app_.image_i.size : app_.image_q.size;
    uint64_t b0 = p.image.offset * 8u + p.image.bit, b1 = b0 + p.lines.size();
    if ((b1 + 7) / 8 > area_size)
      fail(n["lines"], fmt::format("the range ends beyond the %{} image ({} bytes)", p.image.area, area_size));
    claim(n["image"], p.image.area, b0, b1, p.where);
    cfg->gpio_points.push_back(p);
  }

  void point(const YAML::Node& n, IoConfig* cfg) {
    if (!n.IsMap()) fail(n, "a mapping: expected a map (image:, device:, ...), got " + common::YamlDoc::describe(n));
    std::string dev = str(doc_.required(n, "device", "a mapping"), "device");
    for (size_t i = 0; i < cfg->gpio_devices.size(); ++i)
      if (cfg->gpio_devices[i].name == dev) return gpio_point(n, i, cfg);
    keys(n, {"image", "count", "device", "coils", "discrete_inputs", "holding_registers", "input_registers"}, "a mapping");
    ModbusPoint p;
    p.where = at(n);
    p.image = image(doc_.required(n, "image", "a mapping"), "image");
    if (n["count"]) p.count = static_cast<int>(integer(n["count"], "count", 1, 2000));
    p.device = SIZE_MAX;
    for (size_t i = 0; i < cfg->devices.size(); ++i)
      if (cfg->devices[i].name == dev) p.device = i;
    if (p.device == SIZE_MAX) fail(n["device"], "unknown device '" + dev + "'");
    int tables = 0;
    const std::pair<const char*, ModbusTable> kTables[] = {{"coils", ModbusTable::Coils},
                                                           {"discrete_inputs", ModbusTable::DiscreteInputs},
                                                           {"holding_registers", ModbusTable::HoldingRegisters},
                                                           {"input_registers", ModbusTable::InputRegisters}};
    for (const auto& [key, table] : kTables)
      if (n[key]) {
        ++tables;
        p.table = table;
        p.address = static_cast<int>(integer(n[key], "address", 0, 65535));
        if (p.address + p.count > 65536) fail(n[key], "the range passes address 65535");
      }
    if (tables != 1) fail(n, "name one table: coils, discrete_inputs, holding_registers or input_registers: ADDRESS");
    bool bits = p.table == ModbusTable::Coils || p.table == ModbusTable::DiscreteInputs;
    if (bits && !p.image.is_bit) fail(n["image"], std::string(table_name(p.table)) + " map to bits (%IXn.m / %QXn.m)");
    if (!bits && (p.image.is_bit || p.image.size != 2))
      fail(n["image"], std::string(table_name(p.table)) + " map to 16-bit words (%IWn / %QWn)");
    bool input = p.image.area == 'I';
    if (!input && (p.table == ModbusTable::DiscreteInputs || p.table == ModbusTable::InputRegisters))
      fail(n["image"], std::string(table_name(p.table)) + " are read-only: map them to %I");
    uint32_t area_size = input ? app_.image_i.size : app_.image_q.size;
    uint32_t end = bits ? (p.image.offset * 8 + p.image.bit + static_cast<uint32_t>(p.count) + 7) / 8
                        : p.image.offset + 2 * static_cast<uint32_t>(p.count);
    if (end > area_size) fail(n["count"] ? n["count"] : n["image"], fmt::format("the range ends beyond the %{} image ({} bytes)", p.image.area, area_size));
    uint64_t a0 = bits ? p.image.offset * 8u + p.image.bit : p.image.offset * 8u;
    uint64_t a1 = a0 + (bits ? p.count : 16u * static_cast<uint32_t>(p.count));
    claim(n["image"], p.image.area, a0, a1, p.where);
    cfg->points.push_back(p);
  }

 private:
  struct Range {
    char area;
    uint64_t bit0, bit1;
    std::string where;
  };
  const common::YamlDoc& doc_;
  const st::Application& app_;
  std::vector<Range> ranges_;
};

}  // namespace

bool load_io_config(const std::string& path, const st::Application& app, IoConfig* out, std::string* err) {
  out->path = path;
  return common::catch_input_error(err, [&] {
    const common::YamlDoc doc = common::YamlDoc::open(path);
    const YAML::Node& root = doc.root();
    Reader r(doc, app);
    YAML::Node io = root.IsMap() && root["io"] ? root["io"] : root;
    r.keys(io, {"devices", "map", "safe_state"}, "the io section");
    for (const auto& d : doc.list(doc.required(io, "devices", "the io section"), "devices")) r.device(d, out);
    for (const auto& p : doc.list(doc.required(io, "map", "the io section"), "map (image ranges)")) r.point(p, out);
    if (const YAML::Node safe = io["safe_state"]) {
      if (!safe.IsMap()) r.fail(safe, "safe_state: expected a map of outputs to values, e.g. {\"%QX0.0\": TRUE}, got " +
                                          common::YamlDoc::describe(safe));
      for (const auto& kv : safe) {
        rt::ImageRef ref = r.image(kv.first, "safe_state");
        if (ref.area != 'Q') r.fail(kv.first, "safe_state lists outputs (%Q)");
        std::string v = r.str(kv.second, "a safe value");
        int64_t x = 0;
        if (v == "TRUE" || v == "true") x = 1;
        else if (v == "FALSE" || v == "false") x = 0;
        else x = r.integer(kv.second, "a safe value", ref.is_bit ? 0 : -32768, ref.is_bit ? 1 : 65535);
        out->safe_state.emplace_back(ref, x);
      }
    }
  });
}

}  // namespace plcfi::io
