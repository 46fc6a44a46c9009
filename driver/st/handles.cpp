// Variable handles: path resolution, typed reads and writes, ST text (handles.hpp).
#include "handles.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "syntax/ast.hpp"
#include "syntax/diag.hpp"
#include "syntax/parser.hpp"
#include "vm/memory.hpp"
#include "vm/cpp_functions.hpp"
#include "vm/wide.hpp"

namespace plcfi::st {

namespace {
struct PathPart {
  std::string name;
  std::vector<int64_t> indices;
  bool is_bit = false;
  uint32_t bit = 0;
};

bool split_path(std::string_view path, std::vector<PathPart>* out, std::string* err) {
  size_t i = 0;
  auto fail = [&](const std::string& msg) {
    *err = "path '" + std::string(path) + "': " + msg;
    return false;
  };
  while (i < path.size()) {
    PathPart part;
    if (std::isdigit(static_cast<unsigned char>(path[i]))) {
      size_t j = i;
      while (j < path.size() && std::isdigit(static_cast<unsigned char>(path[j]))) ++j;
      part.is_bit = true;
      // A bit of at most a LWORD: two digits; longer is out of range, not a number to read.
      if (j - i > 2) return fail("bit number at column " + std::to_string(i + 1) + " is out of range (0..63)");
      part.bit = static_cast<uint32_t>(std::stoul(std::string(path.substr(i, j - i))));
      i = j;
    } else {
      size_t j = i;
      while (j < path.size() && (std::isalnum(static_cast<unsigned char>(path[j])) || path[j] == '_')) ++j;
      if (j == i) return fail("expected a name at column " + std::to_string(i + 1));
      part.name = std::string(path.substr(i, j - i));
      i = j;
      while (i < path.size() && path[i] == '[') {
        ++i;
        for (;;) {
          size_t k = i;
          if (k < path.size() && (path[k] == '-' || path[k] == '+')) ++k;
          size_t d = k;
          while (k < path.size() && std::isdigit(static_cast<unsigned char>(path[k]))) ++k;
          if (k == d) return fail("expected a constant index at column " + std::to_string(i + 1));
          if (k - d > 18) return fail("index at column " + std::to_string(i + 1) + " is out of range");
          part.indices.push_back(std::stoll(std::string(path.substr(i, k - i))));
          i = k;
          while (i < path.size() && path[i] == ' ') ++i;
          if (i < path.size() && path[i] == ',') {
            ++i;
            while (i < path.size() && path[i] == ' ') ++i;
            continue;
          }
          if (i < path.size() && path[i] == ']') {
            ++i;
            break;
          }
          return fail("expected ',' or ']' at column " + std::to_string(i + 1));
        }
      }
    }
    out->push_back(std::move(part));
    if (i < path.size()) {
      if (path[i] != '.') return fail("unexpected '" + std::string(1, path[i]) + "' at column " + std::to_string(i + 1));
      ++i;
      if (i == path.size()) return fail("ends with '.'");
    }
  }
  if (out->empty()) return fail("empty");
  return true;
}

bool parse_direct(const Application& app, std::string_view text, VarHandle* h, std::string* err) {
  // %[IQM][XBWDL]?n(.b)?
  std::string t = canon(text);
  if (t.size() < 3 || t[0] != '%') {
    *err = "'" + std::string(text) + "' is not a direct address";
    return false;
  }
  const ImageArea* area = app.image(t[1]);
  if (!area) {
    *err = "'" + std::string(text) + "': the area must be I, Q or M";
    return false;
  }
  size_t i = 2;
  char size = 'X';
  if (i < t.size() && std::string("XBWDL").find(t[i]) != std::string::npos) size = t[i++];
  std::vector<uint64_t> parts;
  while (i < t.size()) {
    size_t j = i;
    while (j < t.size() && std::isdigit(static_cast<unsigned char>(t[j]))) ++j;
    if (j == i || j - i > 9) {
      *err = "'" + std::string(text) + "' is not a valid address";
      return false;
    }
    parts.push_back(std::stoull(t.substr(i, j - i)));
    i = j;
    if (i < t.size()) {
      if (t[i] != '.') {
        *err = "'" + std::string(text) + "' is not a valid address";
        return false;
      }
      ++i;
    }
  }
  uint32_t unit = size == 'B' || size == 'X' ? 1 : size == 'W' ? 2 : size == 'D' ? 4 : 8;
  bool bit = size == 'X';
  if ((bit && (parts.size() != 2 || parts[1] > 7)) || (!bit && parts.size() != 1)) {
    *err = "'" + std::string(text) + "': " + (bit ? "a bit address is %" + std::string(1, t[1]) + "Xbyte.bit with bit 0..7" : "a byte/word address has one number");
    return false;
  }
  uint64_t byte = parts[0] * unit;
  if (byte + unit > area->size) {
    *err = "'" + std::string(text) + "' is outside the %" + std::string(1, t[1]) + " image (" + std::to_string(area->size) + " bytes)";
    return false;
  }
  h->addr = area->addr + static_cast<uint32_t>(byte);
  h->is_bit = bit;
  h->bit = bit ? static_cast<uint8_t>(parts[1]) : 0;
  TypeKind k = bit ? TypeKind::Bool : size == 'B' ? TypeKind::Byte : size == 'W' ? TypeKind::Word : size == 'D' ? TypeKind::DWord : TypeKind::LWord;
  h->type = app.types->elementary(k);
  return true;
}
}  // namespace

std::optional<VarHandle> resolve(const Application& app, std::string_view path, std::string* err) {
  VarHandle h;
  h.path = std::string(path);
  if (!path.empty() && path[0] == '%') {
    if (!parse_direct(app, path, &h, err)) return std::nullopt;
    return h;
  }
  std::vector<PathPart> parts;
  if (!split_path(path, &parts, err)) return std::nullopt;
  size_t i = 0;
  const Type* t = nullptr;
  const PouInfo* pou = nullptr;
  auto fail = [&](const std::string& msg) -> std::optional<VarHandle> {
    *err = "path '" + std::string(path) + "': " + msg;
    return std::nullopt;
  };
  // First part: a program instance (or a linked unit's observer), a global, or a
  // global's scope (GVL, configuration).
  for (const auto* list : {&app.programs, &app.observers})
    for (const auto& pi : *list)
      if (i == 0 && iequals(pi.name, parts[0].name) && parts[0].indices.empty()) {
        t = pi.pou->type;
        pou = pi.pou;
        h.addr = pi.addr;
        i = 1;
      }
  auto from_sym = [&](const Symbol* s) {
    t = s->type;
    h.addr = s->offset;
    if (s->where == Where::AbsBit) {
      h.is_bit = true;
      h.bit = s->bit;
    }
  };
  if (!t) {
    for (const auto& g : app.globals)
      if (iequals(g.sym->name, parts[0].name)) {
        from_sym(g.sym);
        i = 1;
        break;
      }
  }
  if (!t && parts.size() > 1) {
    for (const auto& g : app.globals)
      if (iequals(g.scope, parts[0].name) && iequals(g.sym->name, parts[1].name)) {
        from_sym(g.sym);
        i = 2;
        break;
      }
  }
  if (!t) {
    std::string known;
    for (const auto& pi : app.programs) known += (known.empty() ? "" : ", ") + pi.name;
    return fail("no program instance or global variable named '" + parts[0].name + "'" +
                (known.empty() ? "" : " (program instances: " + known + ")"));
  }
  // Indices of the first part (a global array).
  auto apply_indices = [&](const PathPart& p) -> bool {
    if (p.indices.empty()) return true;
    if (t->kind != TypeKind::Array || p.indices.size() != t->dims.size()) {
      *err = "path '" + std::string(path) + "': '" + p.name + "' needs " +
             (t->kind == TypeKind::Array ? std::to_string(t->dims.size()) + " index(es)" : "no index (not an array)");
      return false;
    }
    uint64_t stride = t->elem->size, off = 0;
    for (size_t d = t->dims.size(); d-- > 0;) {
      int64_t ix = p.indices[d];
      if (ix < t->dims[d].lo || ix > t->dims[d].hi) {
        *err = "path '" + std::string(path) + "': index " + std::to_string(ix) + " outside " + std::to_string(t->dims[d].lo) + ".." +
               std::to_string(t->dims[d].hi);
        return false;
      }
      off += static_cast<uint64_t>(ix - t->dims[d].lo) * stride;
      stride *= static_cast<uint64_t>(t->dims[d].hi - t->dims[d].lo + 1);
    }
    h.addr += static_cast<uint32_t>(off);
    t = t->elem;
    return true;
  };
  if (i > 0 && !apply_indices(parts[i - 1])) return std::nullopt;
  for (; i < parts.size(); ++i) {
    const PathPart& p = parts[i];
    if (h.is_bit) return fail("a single bit has no members");
    if (p.is_bit) {
      if (!t->is_integer() && !t->is_bitstring()) return fail("bit access needs an integer or bit string, not " + t->name);
      if (p.bit >= t->bit_width()) return fail("bit " + std::to_string(p.bit) + " does not exist in " + t->name);
      h.addr += p.bit / 8;  // little-endian: bit n is in byte n / 8
      h.bit = static_cast<uint8_t>(p.bit % 8);
      h.is_bit = true;
      t = app.types->elementary(TypeKind::Bool);
      continue;
    }
    const Field* f = (t->kind == TypeKind::Struct || t->kind == TypeKind::Pou) ? t->field(p.name) : nullptr;
    if (!f && t->kind == TypeKind::Pou && t->pou) {
      // Located variables of a program live in the I/O image, not in the instance.
      if (const Symbol* s = t->pou->find_var(p.name); s && (s->where == Where::Abs || s->where == Where::AbsBit)) {
        from_sym(s);
        if (!apply_indices(p)) return std::nullopt;
        continue;
      }
    }
    if (!f) return fail("'" + t->name + "' has no member '" + p.name + "'");
    if (f->type->kind == TypeKind::Ref && t->kind == TypeKind::Pou) {
      const Symbol* s = t->pou ? t->pou->find_var(p.name) : nullptr;
      if (s && s->where == Where::InOut) return fail("'" + p.name + "' is a VAR_IN_OUT (a reference); name the variable it refers to");
    }
    h.addr += f->offset;
    t = f->type;
    if (!apply_indices(p)) return std::nullopt;
  }
  (void)pou;
  h.type = t;
  return h;
}

bool read_bool(const Machine& m, const VarHandle& h) {
  if (h.is_bit) return (m.mem()[h.addr] >> h.bit) & 1u;
  if (h.type->kind == TypeKind::Bool) return m.mem()[h.addr] != 0;  // the common case, read every scan by watchers
  return read_int(m, h) != 0;
}

int64_t read_int(const Machine& m, const VarHandle& h) {
  if (h.is_bit) return (m.mem()[h.addr] >> h.bit) & 1u;
  const uint8_t* p = m.mem() + h.addr;
  switch (h.type->storage()) {
    case Storage::I8: return load_as<int8_t>(p);
    case Storage::I16: return load_as<int16_t>(p);
    case Storage::I32: return load_as<int32_t>(p);
    case Storage::I64: return load_as<int64_t>(p);
    case Storage::U8: return load_as<uint8_t>(p);
    case Storage::U16: return load_as<uint16_t>(p);
    case Storage::U32: return load_as<uint32_t>(p);
    case Storage::U64: return static_cast<int64_t>(load_as<uint64_t>(p));
    case Storage::F32: return static_cast<int64_t>(std::nearbyint(load_as<float>(p)));
    case Storage::F64: return static_cast<int64_t>(std::nearbyint(load_as<double>(p)));
    default: return 0;
  }
}

double read_real(const Machine& m, const VarHandle& h) {
  if (h.type->kind == TypeKind::Real) return load_as<float>(m.mem() + h.addr);
  if (h.type->kind == TypeKind::LReal) return load_as<double>(m.mem() + h.addr);
  if (h.type->storage() == Storage::U64) return static_cast<double>(load_as<uint64_t>(m.mem() + h.addr));
  return static_cast<double>(read_int(m, h));
}

void write_bool(Machine& m, const VarHandle& h, bool v) { write_int(m, h, v ? 1 : 0); }

void write_int(Machine& m, const VarHandle& h, int64_t v) {
  uint8_t* p = m.mem() + h.addr;
  if (h.is_bit) {
    auto mask = static_cast<uint8_t>(1u << h.bit);
    *p = static_cast<uint8_t>(v ? (*p | mask) : (*p & ~mask));
    return;
  }
  // The width decides for integers, enums, times and bits (the hot path of drivers and
  // monitors); only the REAL types convert.
  if (h.type->kind == TypeKind::Real) return store_as<float>(p, static_cast<float>(v));
  if (h.type->kind == TypeKind::LReal) return store_as<double>(p, static_cast<double>(v));
  switch (h.type->kind) {
    case TypeKind::String: case TypeKind::WString: case TypeKind::Array: case TypeKind::Struct: case TypeKind::Pou:
    case TypeKind::Void: return;
    default: break;
  }
  switch (h.type->size) {
    case 1: store_as<uint8_t>(p, static_cast<uint8_t>(h.type->kind == TypeKind::Bool ? v != 0 : v)); break;
    case 2: store_as<uint16_t>(p, static_cast<uint16_t>(v)); break;
    case 4: store_as<uint32_t>(p, static_cast<uint32_t>(v)); break;
    case 8: store_as<uint64_t>(p, static_cast<uint64_t>(v)); break;
    default: break;
  }
}

void write_real(Machine& m, const VarHandle& h, double v) {
  if (h.type->kind == TypeKind::Real) store_as<float>(m.mem() + h.addr, static_cast<float>(v));
  else if (h.type->kind == TypeKind::LReal) store_as<double>(m.mem() + h.addr, v);
  else write_int(m, h, static_cast<int64_t>(std::nearbyint(v)));
}

namespace {
std::string duration(int64_t ns) {
  std::string out = "T#";
  if (ns < 0) {
    out += '-';
    ns = -ns;
  }
  if (ns == 0) return out + "0s";
  static constexpr std::pair<int64_t, const char*> kUnits[] = {{86'400'000'000'000, "d"}, {3'600'000'000'000, "h"},
                                                               {60'000'000'000, "m"},     {1'000'000'000, "s"},
                                                               {1'000'000, "ms"},         {1'000, "us"},
                                                               {1, "ns"}};
  for (auto [u, n] : kUnits)
    if (ns >= u) {
      out += std::to_string(ns / u) + n;
      ns %= u;
    }
  return out;
}
}  // namespace

std::string format(const Machine& m, const VarHandle& h) {
  const Type* t = h.type;
  if (h.is_bit || t->kind == TypeKind::Bool) return read_bool(m, h) ? "TRUE" : "FALSE";
  const uint8_t* p = m.mem() + h.addr;
  switch (t->kind) {
    case TypeKind::Real: return fmt::format("{}", load_as<float>(p));
    case TypeKind::LReal: return fmt::format("{}", load_as<double>(p));
    case TypeKind::LTime:
      if (t->unsigned_count) return unsigned_duration_literal(load_as<uint64_t>(p));
      return duration(load_as<int64_t>(p));
    case TypeKind::Time: return duration(load_as<int64_t>(p));
    case TypeKind::Date: return date_literal(load_as<int64_t>(p));
    case TypeKind::TimeOfDay: return tod_literal(load_as<int64_t>(p));
    case TypeKind::DateTime: return dt_literal(load_as<int64_t>(p));
    case TypeKind::String: {
      const char* s = reinterpret_cast<const char*>(p);
      return "'" + std::string(s, strnlen(s, t->str_len)) + "'";
    }
    case TypeKind::WString: return "'" + utf16_to_utf8(load_wstring(p, t->str_len)) + "'";  // users read UTF-8
    case TypeKind::Enum: {
      int64_t v = read_int(m, h);
      for (const auto& [n, x] : t->enum_values)
        if (x == v) return n;
      return t->name + "#" + std::to_string(v);
    }
    case TypeKind::ULInt: case TypeKind::LWord: return std::to_string(load_as<uint64_t>(p));
    case TypeKind::Byte: case TypeKind::Word: case TypeKind::DWord: return fmt::format("16#{:X}", read_int(m, h));
    case TypeKind::Array: case TypeKind::Struct: case TypeKind::Pou: return "(" + t->name + ")";
    default: return std::to_string(read_int(m, h));
  }
}

bool write_text(Machine& m, const VarHandle& h, std::string_view text, std::string* err) {
  const Type* t = h.type;
  if (!t->is_elementary() && !t->is_string()) {
    *err = "cannot set " + h.path + ": " + t->name + " is not an elementary type";
    return false;
  }
  if (t->kind == TypeKind::Enum) {
    for (const auto& [n, v] : t->enum_values)
      if (iequals(n, text) || iequals(t->name + "#" + n, text)) {
        write_int(m, h, v);
        return true;
      }
  }
  SourceManager sm;
  uint32_t f = sm.add("<value>", std::string(text));
  DiagEngine diags(sm);
  ExprPtr e = parse_expression(sm, f, diags);
  if (!e || diags.has_errors()) {
    *err = "'" + std::string(text) + "' is not a valid ST literal for " + h.path;
    return false;
  }
  bool neg = false;
  const Expr* x = e.get();
  if (x->kind == ExprKind::Unary && static_cast<const UnaryExpr*>(x)->op == UnaryOp::Neg) {
    neg = true;
    x = static_cast<const UnaryExpr*>(x)->operand.get();
  }
  if (x->kind != ExprKind::Literal) {
    *err = "'" + std::string(text) + "' is not a literal (expected e.g. TRUE, 42, 1.5, T#2s, 'text')";
    return false;
  }
  const auto& l = static_cast<const LiteralExpr&>(*x);
  auto bad_kind = [&]() {
    *err = "'" + std::string(text) + "' does not fit " + h.path + " (" + t->name + ")";
    return false;
  };
  if (t->is_string()) {
    if (l.lit != LiteralKind::String && l.lit != LiteralKind::WString) return bad_kind();
    if (t->kind == TypeKind::WString) {  // the literal's UTF-8 as the WSTRING's UTF-16
      store_wstring(m.mem() + h.addr, t->str_len, utf8_to_utf16(l.str_value));
      return true;
    }
    size_t n = std::min<size_t>(l.str_value.size(), t->str_len);
    std::memcpy(m.mem() + h.addr, l.str_value.data(), n);
    m.mem()[h.addr + n] = 0;
    return true;
  }
  if (t->kind == TypeKind::Bool || h.is_bit) {
    if (l.lit == LiteralKind::Bool || (l.lit == LiteralKind::Int && l.int_value <= 1 && !neg)) {
      write_bool(m, h, l.int_value != 0);
      return true;
    }
    return bad_kind();
  }
  if (t->is_real()) {
    if (l.lit != LiteralKind::Real && l.lit != LiteralKind::Int) return bad_kind();
    double v = l.lit == LiteralKind::Real ? l.real_value : static_cast<double>(l.int_value);
    write_real(m, h, neg ? -v : v);
    return true;
  }
  if (t->is_time_like()) {
    if (l.lit == LiteralKind::Int) return bad_kind();  // durations need T#
    if (l.lit != LiteralKind::Time && l.lit != LiteralKind::Date && l.lit != LiteralKind::TimeOfDay && l.lit != LiteralKind::DateTime)
      return bad_kind();
    write_int(m, h, neg ? -l.time_ns : l.time_ns);
    return true;
  }
  // TRUE/FALSE fit a bit string (a BYTE of one bit), not an integer: INT := TRUE is a type error.
  if (l.lit != LiteralKind::Int && !(l.lit == LiteralKind::Bool && t->is_bitstring())) return bad_kind();
  int64_t v = neg ? -static_cast<int64_t>(l.int_value) : static_cast<int64_t>(l.int_value);
  // Range check against the type.
  int64_t lo = 0, hi = 0;
  switch (t->storage()) {
    case Storage::I8: lo = INT8_MIN; hi = INT8_MAX; break;
    case Storage::I16: lo = INT16_MIN; hi = INT16_MAX; break;
    case Storage::I32: lo = INT32_MIN; hi = INT32_MAX; break;
    case Storage::I64: lo = INT64_MIN; hi = INT64_MAX; break;
    case Storage::U8: lo = 0; hi = UINT8_MAX; break;
    case Storage::U16: lo = 0; hi = UINT16_MAX; break;
    case Storage::U32: lo = 0; hi = UINT32_MAX; break;
    default: lo = 0; hi = INT64_MAX; break;
  }
  if (t->ranged) {
    lo = t->lo;
    hi = t->hi;
  }
  if (v < lo || v > hi) {
    *err = std::string(text) + " is outside the range of " + h.path + " (" + t->name + ": " + std::to_string(lo) + ".." + std::to_string(hi) + ")";
    return false;
  }
  write_int(m, h, v);
  return true;
}

}  // namespace plcfi::st
