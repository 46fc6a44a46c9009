#include "instances.hpp"

#include <fmt/format.h>

namespace plcfi::testing {

bool derives(const st::PouInfo* p, const st::PouInfo* base) {
  for (int depth = 0; p && depth < 64; p = p->base, ++depth)
    if (p == base) return true;
  return false;
}

namespace {

void collect(const st::Type* t, uint32_t addr, const std::string& path, const std::function<bool(const st::PouInfo*)>& wanted,
             int depth, std::vector<Found>* out) {
  if (!t || depth > 32 || out->size() > 10'000) return;
  if (t->kind == st::TypeKind::Pou && t->pou && wanted(t->pou)) {
    out->push_back(Found{path, t->pou, addr});
    return;  // an instance's own members are its business
  }
  if ((t->kind == st::TypeKind::Pou && t->pou) || (t->kind == st::TypeKind::Struct && !t->is_union)) {
    for (const auto& f : t->fields) collect(f.type, addr + f.offset, path + "." + f.name, wanted, depth + 1, out);
    return;
  }
  if (t->kind == st::TypeKind::Array && t->elem && t->dims.size() == 1 &&
      (t->elem->kind == st::TypeKind::Pou || t->elem->kind == st::TypeKind::Struct)) {
    const auto& d = t->dims[0];
    for (int64_t i = d.lo; i <= d.hi && out->size() <= 10'000; ++i)
      collect(t->elem, addr + static_cast<uint32_t>(i - d.lo) * t->elem->size, fmt::format("{}[{}]", path, i), wanted,
              depth + 1, out);
  }
}

}  // namespace

std::vector<Found> find_instances(const st::Application& app, const std::function<bool(const st::PouInfo*)>& wanted) {
  std::vector<Found> out;
  for (const auto& inst : app.programs)
    if (inst.pou) collect(inst.pou->type, inst.addr, inst.name, wanted, 0, &out);
  for (const auto& g : app.globals)
    if (g.sym && g.sym->where == st::Where::Abs) collect(g.sym->type, g.sym->offset, g.scope + "." + g.sym->name, wanted, 0, &out);
  return out;
}

}  // namespace plcfi::testing
