// Reader of plant files, on the project's strict YAML reader.
#include "plant_model/plant_file.hpp"

#include <cmath>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "common/yaml.hpp"

namespace plcfi::plant {

namespace {

using common::YamlDoc;
namespace fs = std::filesystem;

// Bounds far above any real plant: a generated file fails fast instead of slowly.
constexpr size_t kMaxMapEntries = 10'000;
constexpr int64_t kMaxStepNs = 3600'000'000'000;  // an hour

std::string resolve(const std::string& base_file, const std::string& rel) {
  fs::path p(rel);
  if (p.is_absolute()) return rel;
  return (fs::path(base_file).parent_path() / p).lexically_normal().string();
}

// "%IX3.5", "%QW2": the image addresses a plant signal can take (a bit or a 16-bit word).
bool parse_image(const std::string& s, bool* input, bool* bit) {
  if (s.size() < 4 || s[0] != '%' || (s[1] != 'I' && s[1] != 'Q') || (s[2] != 'X' && s[2] != 'W')) return false;
  *input = s[1] == 'I';
  *bit = s[2] == 'X';
  size_t i = 3, digits = 0;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])) && digits < 6) ++i, ++digits;
  if (digits == 0) return false;
  if (*bit) {
    if (i + 2 != s.size() || s[i] != '.' || s[i + 1] < '0' || s[i + 1] > '7') return false;
    return true;
  }
  return i == s.size();
}

std::pair<double, double> range(const YamlDoc& doc, const YAML::Node& n, const std::string& what) {
  YAML::Node l = doc.list(n, what);
  if (l.size() != 2) doc.fail(n, what + ": expected two numbers [low, high], got " + std::to_string(l.size()));
  double lo = doc.number(l[0], what), hi = doc.number(l[1], what);
  if (lo == hi) doc.fail(n, what + ": the two ends must differ");
  return {lo, hi};
}

std::string scalar_text(const YamlDoc& doc, const YAML::Node& n, const std::string& what) {
  if (!n.IsScalar()) doc.fail(n, what + ": expected a single value, got " + YamlDoc::describe(n));
  return n.Scalar();
}

}  // namespace

void check_binding(const MapEntry& m, ValueKind kind, const std::string& what) {
  const char area = m.input ? 'I' : 'Q';
  auto fail = [](const std::string& where, const std::string& message) { throw common::InputError(where + ": " + message); };
  if (kind == ValueKind::Bool && !m.bit)
    fail(m.where, fmt::format("'{}' is {}: map it to a bit (%{}X...), not {}", m.plant, what, area, m.image));
  if (kind != ValueKind::Bool && m.bit)
    fail(m.where, fmt::format("'{}' is {}: map it to a word (%{}W...), not the bit {}", m.plant, what, area, m.image));
  if (kind == ValueKind::Real && !m.scale)
    fail(m.where, fmt::format("'{}' is {}: a word needs scale: {{from: [low, high], to: [low, high]}} (plant units to "
                              "image units, e.g. to: [0, 27648])",
                              m.plant, what));
  if (kind != ValueKind::Real && m.scale)
    fail(m.scale_where, fmt::format("scale: '{}' is {}; only a real-valued variable is scaled", m.plant, what));
}

bool is_plant_file(const std::string& arg) {
  return arg.ends_with(".yaml") || arg.ends_with(".yml");
}

PlantFile read_plant_file(const std::string& path) {
  YamlDoc doc = YamlDoc::open(path);
  const YAML::Node& root = doc.root();
  PlantFile pf;
  pf.path = path;
  pf.where = path + ":1:1";
  if (!root.IsMap()) doc.fail(root, "a plant file: expected a map (builtin:, fmu: or st:, then step:, map:), got " + YamlDoc::describe(root));
  doc.check_keys(root, {"builtin", "fmu", "st", "step", "stop_time", "seed_parameter", "call_timeout", "parameters", "program", "stats", "config", "map"},
                 "the plant file");

  int kinds = (root["builtin"] ? 1 : 0) + (root["fmu"] ? 1 : 0) + (root["st"] ? 1 : 0);
  if (kinds != 1)
    doc.fail(root, kinds == 0 ? "the plant file names no plant: give one of builtin:, fmu: or st:"
                              : "the plant file names more than one plant: give one of builtin:, fmu: or st:");
  if (root["builtin"]) {
    pf.kind = PlantFile::Kind::Builtin;
    pf.builtin = doc.scalar(root["builtin"], "builtin");
  } else if (root["fmu"]) {
    pf.kind = PlantFile::Kind::Fmu;
    pf.fmu = resolve(path, doc.scalar(root["fmu"], "fmu"));
    pf.fmu_where = doc.where(root["fmu"]);
  } else {
    pf.kind = PlantFile::Kind::St;
    const auto files = root["st"];
    if (files.IsSequence()) {
      for (const auto& f : doc.list(files, "st")) pf.st.push_back(resolve(path, doc.scalar(f, "st entry")));
    } else {
      pf.st.push_back(resolve(path, doc.scalar(files, "st")));
    }
  }
  auto only_for = [&](const char* key, PlantFile::Kind kind, const char* kind_name) {
    if (root[key] && pf.kind != kind) doc.fail(root[key], fmt::format("{}: only for a plant given by {}:", key, kind_name));
  };
  only_for("stop_time", PlantFile::Kind::Fmu, "fmu");
  only_for("seed_parameter", PlantFile::Kind::Fmu, "fmu");
  only_for("call_timeout", PlantFile::Kind::Fmu, "fmu");
  only_for("program", PlantFile::Kind::St, "st");
  if (root["stats"] && pf.kind == PlantFile::Kind::Builtin)
    doc.fail(root["stats"], "stats: a built-in plant reports its own statistics");
  only_for("config", PlantFile::Kind::Builtin, "builtin");
  if (pf.kind == PlantFile::Kind::Builtin && root["parameters"])
    doc.fail(root["parameters"], "parameters: a built-in plant takes its parameters from a file: use config:");

  if (const auto n = root["step"]) {
    pf.step_ns = doc.duration(n, "step", 1);
    if (pf.step_ns > kMaxStepNs) doc.fail(n, "step: at most 1h");
    pf.step_where = doc.where(n);
  }
  if (const auto n = root["stop_time"]) pf.stop_time_ns = doc.duration(n, "stop_time", 1);
  if (const auto n = root["call_timeout"]) {
    pf.call_timeout_ns = doc.duration(n, "call_timeout", 1'000'000);
    if (pf.call_timeout_ns > 3600'000'000'000) doc.fail(n, "call_timeout: at most 1h");
  }
  if (const auto n = root["program"]) pf.program = doc.scalar(n, "program");
  if (const auto n = root["seed_parameter"]) {
    pf.seed_parameter = doc.scalar(n, "seed_parameter");
    pf.seed_where = doc.where(n);
  }
  if (const auto n = root["stats"])
    for (const auto& v : doc.list(n, "stats")) pf.stats.push_back({doc.scalar(v, "stats entry"), "", doc.where(v)});
  if (const auto n = root["config"]) pf.config = resolve(path, doc.scalar(n, "config"));

  if (const auto n = root["parameters"]) {
    if (!n.IsNull()) {
      if (!n.IsMap()) doc.fail(n, "parameters: expected a map (name: value), got " + YamlDoc::describe(n));
      for (const auto& kv : n) {
        Parameter p;
        p.name = doc.scalar(kv.first, "parameter name");
        p.value = scalar_text(doc, kv.second, "parameter " + p.name);
        p.where = doc.where(kv.second);
        pf.parameters.push_back(std::move(p));
      }
    }
  }

  if (const auto n = root["map"]) {
    std::set<std::string> images;
    for (const auto& e : doc.list(n, "map", pf.kind == PlantFile::Kind::Builtin)) {
      if (pf.map.size() >= kMaxMapEntries) doc.fail(e, fmt::format("map: more than {} entries", kMaxMapEntries));
      if (!e.IsMap()) doc.fail(e, "map entry: expected a map {image: ..., plant: ...}, got " + YamlDoc::describe(e));
      doc.check_keys(e, {"image", "plant", "scale"}, "a map entry");
      MapEntry m;
      m.where = doc.where(e);
      const auto img = doc.required(e, "image", "a map entry");
      m.image = doc.scalar(img, "image");
      if (!parse_image(m.image, &m.input, &m.bit))
        doc.fail(img, fmt::format("image: expected a bit (%IX0.0, %QX1.7) or a word (%IW2, %QW0), got '{}'", m.image));
      if (!images.insert(m.image).second) doc.fail(img, fmt::format("image: {} is mapped twice", m.image));
      const auto pl = doc.required(e, "plant", "a map entry");
      m.plant = doc.scalar(pl, "plant");
      m.plant_where = doc.where(pl);
      if (const auto sc = e["scale"]) {
        if (m.bit) doc.fail(sc, fmt::format("scale: {} is a bit; only a word (%IW/%QW) takes a scale", m.image));
        if (!sc.IsMap()) doc.fail(sc, "scale: expected {from: [low, high], to: [low, high]}, got " + YamlDoc::describe(sc));
        doc.check_keys(sc, {"from", "to"}, "scale");
        Scale s;
        std::tie(s.from_lo, s.from_hi) = range(doc, doc.required(sc, "from", "scale"), "scale.from");
        std::tie(s.to_lo, s.to_hi) = range(doc, doc.required(sc, "to", "scale"), "scale.to");
        for (double v : {s.to_lo, s.to_hi})
          if (v < -32768.0 || v > 32767.0)
            doc.fail(sc["to"], fmt::format("scale.to: {} does not fit a 16-bit word (-32768..32767)", v));
        m.scale = s;
        m.scale_where = doc.where(sc);
      }
      pf.map.push_back(std::move(m));
    }
  } else if (pf.kind != PlantFile::Kind::Builtin) {
    doc.fail(root, "missing key 'map' in the plant file (which image entry is which plant variable)");
  }
  return pf;
}

}  // namespace plcfi::plant
