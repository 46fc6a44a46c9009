// Ports, manifest and schedule of the program FMU (see program_fmu.hpp).
#include "fmu/program_fmu.hpp"

#include <algorithm>
#include <sstream>

#include <fmt/format.h>

#include "common/duration.hpp"
#include "runtime/image.hpp"

namespace plcfi::fmu {

const char* fmi_type_name(FmiType t) {
  switch (t) {
    case FmiType::Boolean: return "Boolean";
    case FmiType::Integer: return "Integer";
    case FmiType::Real: return "Real";
  }
  return "?";
}

namespace {

// The FMI type that carries every value of an ST type exactly, or false.
bool fmi_type_of(const st::Type* t, FmiType* out) {
  using st::TypeKind;
  const st::Type* v = t->kind == TypeKind::Enum ? nullptr : t;
  if (!v) return false;
  switch (v->kind) {
    case TypeKind::Bool: *out = FmiType::Boolean; return true;
    case TypeKind::SInt: case TypeKind::Int: case TypeKind::DInt:
    case TypeKind::USInt: case TypeKind::UInt: case TypeKind::Byte: case TypeKind::Word:
      *out = FmiType::Integer;
      return true;
    // 32-bit unsigned values do not fit fmi2Integer; a double holds each one exactly.
    case TypeKind::UDInt: case TypeKind::DWord: case TypeKind::Real: case TypeKind::LReal:
      *out = FmiType::Real;
      return true;
    default: return false;
  }
}

std::string address_of(const rt::ImageRef& r) {
  if (r.is_bit) return fmt::format("%{}X{}.{}", r.area, r.offset, r.bit);
  const char* letter = r.size == 1 ? "B" : r.size == 2 ? "W" : r.size == 4 ? "D" : "L";
  if (r.offset % r.size == 0) return fmt::format("%{}{}{}", r.area, letter, r.offset / r.size);
  return fmt::format("%{}B{}", r.area, r.offset);  // not aligned to its size: its first byte
}

bool in_image(const st::Application& app, const st::Symbol& s) {
  if (s.kind != st::SymKind::Var || (s.where != st::Where::Abs && s.where != st::Where::AbsBit)) return false;
  for (const st::ImageArea* a : {&app.image_i, &app.image_q})
    if (a->size && s.offset >= a->addr && s.offset < a->addr + a->size) return true;
  return false;
}

}  // namespace

bool list_ports(const st::Application& app, std::vector<Port>* out, std::string* err) {
  struct Found {
    std::string path;
    const st::Symbol* sym;
  };
  std::vector<Found> found;
  for (const auto& g : app.globals) {
    if (!in_image(app, *g.sym)) continue;
    size_t same = std::count_if(app.globals.begin(), app.globals.end(),
                                [&](const st::GlobalVar& o) { return st::iequals(o.sym->name, g.sym->name); });
    found.push_back({same > 1 && !g.scope.empty() ? g.scope + "." + g.sym->name : g.sym->name, g.sym});
  }
  for (const auto& pi : app.programs)
    for (const auto& v : pi.pou->vars)
      if (v->section != st::VarSection::External && in_image(app, *v)) found.push_back({pi.name + "." + v->name, v.get()});

  struct Placed {
    Port port;
    rt::ImageRef ref;
  };
  std::vector<Placed> placed;
  for (const auto& f : found) {
    rt::ImageRef ref;
    std::string e;
    if (!rt::parse_image_ref(app, f.path, &ref, &e)) {
      *err = fmt::format("{}: {}", app.where(f.sym->loc), e);
      return false;
    }
    Port p;
    p.input = ref.area == 'I';
    p.path = f.path;
    p.address = address_of(ref);
    p.type = ref.type->name;
    if (!fmi_type_of(ref.type, &p.fmi)) {
      *err = fmt::format(
          "{}: {} at {} is {}: FMI 2.0 has no type that holds every value of it exactly (ports may be BOOL, "
          "SINT..DINT, USINT..UDINT, BYTE..DWORD, REAL, LREAL)",
          app.where(f.sym->loc), f.path, p.address, p.type);
      return false;
    }
    placed.push_back({std::move(p), std::move(ref)});
  }
  auto bits = [](const rt::ImageRef& r) {  // [first, last) bit index in the area
    uint64_t first = uint64_t{r.offset} * 8 + (r.is_bit ? r.bit : 0);
    return std::pair<uint64_t, uint64_t>{first, first + (r.is_bit ? 1 : uint64_t{r.size} * 8)};
  };
  std::stable_sort(placed.begin(), placed.end(), [&](const Placed& a, const Placed& b) {
    if (a.ref.area != b.ref.area) return a.ref.area == 'I';
    return bits(a.ref).first < bits(b.ref).first;
  });
  for (size_t i = 1; i < placed.size(); ++i) {
    const Placed& a = placed[i - 1];
    const Placed& b = placed[i];
    if (a.ref.area == b.ref.area && bits(b.ref).first < bits(a.ref).second) {
      *err = fmt::format("{} at {} and {} at {} share bits of the {} image: each FMU {} needs an address of its own",
                         a.port.path, a.port.address, b.port.path, b.port.address, a.port.input ? "input" : "output",
                         a.port.input ? "input" : "output");
      return false;
    }
  }
  out->clear();
  for (auto& p : placed) out->push_back(std::move(p.port));
  if (out->empty()) {
    *err = "the program declares no variable at a %I or %Q address: the FMU would have no inputs and no outputs";
    return false;
  }
  return true;
}

std::string write_manifest(const Manifest& m) {
  std::string s = "plcfi-program-fmu 1\n";
  s += fmt::format("guid {}\nmodel_identifier {}\nmodel_name {}\ndialect {}\nstrict {}\n", m.guid, m.model_identifier,
                   m.model_name, st::dialect_name(m.dialect), m.strict ? 1 : 0);
  if (!m.program.empty()) s += fmt::format("program {}\n", m.program);
  s += fmt::format("cycle_ns {}\ntick_ns {}\n", m.cycle_ns, m.tick_ns);
  for (const auto& f : m.libraries) s += fmt::format("library {}\n", f);
  for (const auto& f : m.sources) s += fmt::format("source {}\n", f);
  for (const auto& p : m.ports)
    s += fmt::format("port {} {} {} {} {}\n", p.input ? "input" : "output", fmi_type_name(p.fmi), p.path, p.address,
                     p.type);
  return s;
}

bool read_manifest(const std::string& text, Manifest* m, std::string* err) {
  std::istringstream in(text);
  std::string line;
  int n = 0;
  auto bad = [&](const std::string& what) {
    *err = fmt::format("line {}: {}", n, what);
    return false;
  };
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    const size_t sp = line.find(' ');
    const std::string key = line.substr(0, sp);
    const std::string rest = sp == std::string::npos ? "" : line.substr(sp + 1);
    if (n == 1) {
      if (line != "plcfi-program-fmu 1") return bad("not a plcfi program FMU manifest (version 1)");
      continue;
    }
    if (key == "guid") m->guid = rest;
    else if (key == "model_identifier") m->model_identifier = rest;
    else if (key == "model_name") m->model_name = rest;
    else if (key == "dialect") {
      if (!st::parse_dialect(rest, &m->dialect)) return bad("unknown dialect '" + rest + "'");
    } else if (key == "strict") m->strict = rest == "1";
    else if (key == "program") m->program = rest;
    else if (key == "cycle_ns" || key == "tick_ns") {
      int64_t v = 0;
      try {
        size_t used = 0;
        v = std::stoll(rest, &used);
        if (used != rest.size() || v <= 0) return bad(key + " must be a positive number of nanoseconds");
      } catch (const std::exception&) {
        return bad(key + " must be a positive number of nanoseconds");
      }
      (key == "cycle_ns" ? m->cycle_ns : m->tick_ns) = v;
    } else if (key == "library" || key == "source") {
      // Files of the archive's resources/plcfi/ folder, nowhere else.
      if (rest.empty() || rest[0] == '/' || rest == ".." || rest.rfind("../", 0) == 0 ||
          rest.find("/../") != std::string::npos || (rest.size() >= 3 && rest.compare(rest.size() - 3, 3, "/..") == 0))
        return bad("'" + rest + "' is not a file inside resources/plcfi/");
      (key == "library" ? m->libraries : m->sources).push_back(rest);
    }
    else if (key == "port") {
      std::istringstream ps(rest);
      std::string dir, type, path, address, st_type;
      if (!(ps >> dir >> type >> path >> address) || (dir != "input" && dir != "output") ||
          !std::getline(ps >> std::ws, st_type) || st_type.empty())
        return bad("a port is 'port input|output Boolean|Integer|Real PATH ADDRESS TYPE'");
      Port p;
      p.input = dir == "input";
      if (type == "Boolean") p.fmi = FmiType::Boolean;
      else if (type == "Integer") p.fmi = FmiType::Integer;
      else if (type == "Real") p.fmi = FmiType::Real;
      else return bad("unknown FMI type '" + type + "'");
      p.path = path;
      p.address = address;
      p.type = st_type;
      m->ports.push_back(std::move(p));
    } else {
      return bad("unknown key '" + key + "'");
    }
  }
  if (n == 0) return bad("empty manifest");
  if (m->guid.empty() || m->sources.empty() || m->ports.empty() || m->tick_ns <= 0)
    return bad("incomplete manifest (guid, tick_ns, sources and ports are needed)");
  return true;
}

bool make_schedule(const st::Application& app, const Manifest& m, rt::Schedule* sched, std::string* err) {
  if (app.has_configuration && m.program.empty()) return sched->from_configuration(app, err);
  return sched->single_program(app, m.program, m.cycle_ns, err);
}

}  // namespace plcfi::fmu
