// Image locations and overlays.
#include "image.hpp"

#include <cstring>

#include "engine.hpp"

namespace plcfi::rt {

namespace {

// The type of the variable the program declares AT exactly this address and size
// (`StampPressure AT %IW2 : INT`), so an address reads and clamps like the program's
// variable and not like the bare WORD the address names. nullptr: none declared there.
const st::Type* declared_type_at(const st::Application& app, uint32_t addr, uint32_t size) {
  auto match = [&](const st::Symbol& s) {
    return s.kind == st::SymKind::Var && s.where == st::Where::Abs && s.offset == addr && s.type &&
           s.type->is_elementary() && s.type->size == size;
  };
  for (const auto& g : app.globals)
    if (g.sym && match(*g.sym)) return g.sym->type;
  for (const auto& inst : app.programs)
    for (const auto& v : inst.pou->vars)
      if (match(*v)) return v->type;
  return nullptr;
}

}  // namespace

bool parse_image_ref(const st::Application& app, const std::string& text, ImageRef* ref, std::string* err) {
  auto h = st::resolve(app, text, err);
  if (!h) return false;
  const st::ImageArea* areas[] = {&app.image_i, &app.image_q};
  for (const st::ImageArea* a : areas) {
    if (h->addr >= a->addr && h->addr + (h->is_bit ? 1 : h->type->size) <= a->addr + a->size) {
      ref->area = a->area;
      ref->offset = h->addr - a->addr;
      ref->is_bit = h->is_bit;
      ref->bit = h->bit;
      ref->size = static_cast<uint8_t>(h->is_bit ? 1 : h->type->size);
      ref->type = h->type;
      if (!h->is_bit && !text.empty() && text[0] == '%')
        if (const st::Type* t = declared_type_at(app, h->addr, h->type->size)) ref->type = t;
      ref->text = text;
      if (!h->is_bit && !h->type->is_elementary()) {
        *err = "'" + text + "' is not an elementary value in the I/O image";
        return false;
      }
      return true;
    }
  }
  *err = "'" + text + "' is not in the %I or %Q image";
  return false;
}

std::string ForceRule::describe() const { return "force " + ref_.text + " := " + std::to_string(value_); }

void Overlay::apply(uint8_t* dst, const uint8_t* src, size_t n, int64_t now_ns) const {
  std::memcpy(dst, src, n);
  for (const auto& r : rules_) r->apply(dst, src, now_ns);
}

}  // namespace plcfi::rt
