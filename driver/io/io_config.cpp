// Parsing of the `io:` section (devices and image mappings).
#include "io_config.hpp"

#include <fstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "runtime/schedule.hpp"

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

namespace {

struct Fail {
  std::string message;
};

class Reader {
 public:
  Reader(std::string path, const st::Application& app) : path_(std::move(path)), app_(app) {}

  std::string at(const YAML::Node& n) const { return fmt::format("{}:{}:{}", path_, n.Mark().line + 1, n.Mark().column + 1); }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& m) const { throw Fail{at(n) + ": " + m}; }
  std::string str(const YAML::Node& n, const char* what) const {
    if (!n.IsScalar()) fail(n, std::string(what) + " must be a single value");
    return n.Scalar();
  }
  int64_t integer(const YAML::Node& n, const char* what, int64_t lo, int64_t hi) const {
    std::string s = str(n, what);
    try {
      size_t used = 0;
      long long v = std::stoll(s, &used, 0);
      if (used != s.size()) throw std::invalid_argument(s);
      if (v < lo || v > hi) fail(n, fmt::format("{} {} is outside {}..{}", what, v, lo, hi));
      return v;
    } catch (const std::exception&) {
      fail(n, fmt::format("{}: '{}' is not an integer", what, s));
    }
  }
  int64_t duration(const YAML::Node& n, const char* what) const {
    std::string e;
    int64_t ns = 0;
    if (!rt::parse_duration(str(n, what), &ns, &e)) fail(n, std::string(what) + ": " + e);
    if (ns <= 0) fail(n, std::string(what) + " must be positive");
    return ns;
  }
  void keys(const YAML::Node& m, std::initializer_list<const char*> allowed, const char* what) const {
    if (!m.IsMap()) fail(m, std::string(what) + " must be a map");
    for (const auto& kv : m) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || kv.first.Scalar() == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(kv.first, fmt::format("unknown key '{}' in {} (expected one of: {})", kv.first.Scalar(), what, list));
      }
    }
  }
  rt::ImageRef image(const YAML::Node& n, const char* what) const {
    rt::ImageRef r;
    std::string e;
    if (!rt::parse_image_ref(app_, str(n, what), &r, &e)) fail(n, e);
    return r;
  }

  void device(const YAML::Node& n, IoConfig* cfg) const {
    keys(n, {"name", "tcp", "rtu", "unit", "timeout", "status", "reconnect", "lost_after", "reset_register"}, "a device");
    ModbusDevice d;
    d.where = at(n);
    if (!n["name"]) fail(n, "a device needs a name");
    d.name = str(n["name"], "name");
    for (const auto& other : cfg->devices)
      if (other.name == d.name) fail(n["name"], "device '" + d.name + "' is defined twice");
    if (bool(n["tcp"]) == bool(n["rtu"])) fail(n, "a device is either tcp: HOST:PORT or rtu: {device: ...}");
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
      if (!r["device"]) fail(r, "rtu needs a device (e.g. /dev/ttyUSB0)");
      d.device = str(r["device"], "device");
      if (r["baud"]) d.baud = static_cast<int>(integer(r["baud"], "baud", 50, 4'000'000));
      if (r["parity"]) {
        std::string p = str(r["parity"], "parity");
        if (p != "N" && p != "E" && p != "O") fail(r["parity"], "parity must be N, E or O");
        d.parity = p[0];
      }
      if (r["data_bits"]) d.data_bits = static_cast<int>(integer(r["data_bits"], "data_bits", 5, 8));
      if (r["stop_bits"]) d.stop_bits = static_cast<int>(integer(r["stop_bits"], "stop_bits", 1, 2));
      if (r["mode"]) {
        std::string m = str(r["mode"], "mode");
        if (m != "rs232" && m != "rs485") fail(r["mode"], "mode must be rs232 or rs485");
        d.rs485 = m == "rs485";
      }
    }
    if (n["unit"]) d.unit = static_cast<int>(integer(n["unit"], "unit", 0, 247));
    if (n["timeout"]) d.timeout_ns = duration(n["timeout"], "timeout");
    if (n["status"]) {
      d.status = image(n["status"], "status");
      if (d.status.area != 'I' || !d.status.is_bit) fail(n["status"], "status must be an input bit (%IXn.m)");
      d.has_status = true;
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

  void point(const YAML::Node& n, IoConfig* cfg) const {
    keys(n, {"image", "count", "device", "coils", "discrete_inputs", "holding_registers", "input_registers"}, "a mapping");
    ModbusPoint p;
    p.where = at(n);
    if (!n["image"]) fail(n, "a mapping needs image: (the first %I/%Q address)");
    p.image = image(n["image"], "image");
    if (n["count"]) p.count = static_cast<int>(integer(n["count"], "count", 1, 2000));
    if (!n["device"]) fail(n, "a mapping needs a device");
    std::string dev = str(n["device"], "device");
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
    // Two mappings must not feed the same image bytes (which one would win?).
    for (const auto& q : cfg->points) {
      if (q.image.area != p.image.area) continue;
      bool qbits = q.table == ModbusTable::Coils || q.table == ModbusTable::DiscreteInputs;
      uint64_t a0 = bits ? p.image.offset * 8u + p.image.bit : p.image.offset * 8u;
      uint64_t a1 = a0 + (bits ? p.count : 16u * static_cast<uint32_t>(p.count));
      uint64_t b0 = qbits ? q.image.offset * 8u + q.image.bit : q.image.offset * 8u;
      uint64_t b1 = b0 + (qbits ? q.count : 16u * static_cast<uint32_t>(q.count));
      if (a0 < b1 && b0 < a1) fail(n["image"], "overlaps the mapping at " + q.where);
    }
    cfg->points.push_back(p);
  }

 private:
  std::string path_;
  const st::Application& app_;
};

}  // namespace

bool load_io_config(const std::string& path, const st::Application& app, IoConfig* out, std::string* err) {
  std::ifstream in(path);
  if (!in) {
    *err = path + ": cannot open";
    return false;
  }
  YAML::Node root;
  try {
    root = YAML::Load(in);
  } catch (const YAML::Exception& e) {
    *err = fmt::format("{}:{}:{}: {}", path, e.mark.line + 1, e.mark.column + 1, e.msg);
    return false;
  }
  out->path = path;
  Reader r(path, app);
  try {
    YAML::Node io = root.IsMap() && root["io"] ? root["io"] : root;
    r.keys(io, {"devices", "map", "safe_state"}, "the io section");
    const YAML::Node devs = io["devices"];
    if (!devs || !devs.IsSequence() || devs.size() == 0) r.fail(io, "io needs a list of devices");
    for (const auto& d : devs) r.device(d, out);
    const YAML::Node map = io["map"];
    if (!map || !map.IsSequence() || map.size() == 0) r.fail(io, "io needs a map: list of image ranges");
    for (const auto& p : map) r.point(p, out);
    if (const YAML::Node safe = io["safe_state"]) {
      if (!safe.IsMap()) r.fail(safe, "safe_state maps outputs to values, e.g. {\"%QX0.0\": TRUE}");
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
  } catch (const Fail& f) {
    *err = f.message;
    return false;
  }
  return true;
}

}  // namespace plcfi::io
