// Calls of the standard functions, the type conversions, the temporal operators of
// requirement monitors and the test-file built-ins. Their signatures and type rules are
// in sema/stdfuncs; here each family of functions has one emitter, picked from a table.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "compiler_impl.hpp"
#include "sema/stdfuncs.hpp"

namespace plcfi::st::detail {

namespace {

// The type generic standard functions (MIN, SEL, the assertions) compute in: the common
// type of the typed arguments, null when they have none.
const Type* first_type(Compiler& cc, const std::vector<Val>& vals) {
  const Type* t = nullptr;
  for (const auto& v : vals) {
    if (!v.type) continue;
    if (!t) t = v.type;
    else {
      const Type* ct = common_type(*cc.tt_, t, v.type);
      if (!ct) return nullptr;
      t = ct;
    }
  }
  if (!t) {
    // Only untyped literals: the context's type when it can hold them (an integer
    // target for integer literals, a real one for any), else DINT / LREAL.
    bool real = false;
    for (const auto& v : vals) real = real || v.c.k == ConstV::K::Real;
    const Type* want = cc.call_expected_;
    if (want && (want->is_real() || (!real && (want->is_integer() || want->is_bitstring())))) return want;
    t = real ? cc.elem(TypeKind::LReal) : cc.elem(TypeKind::DInt);
  }
  return t;
}

std::vector<Val> eval_all(Compiler& cc, const std::vector<const Expr*>& args) {
  std::vector<Val> vals;
  for (const Expr* a : args) vals.push_back(cc.expr(*a));
  return vals;
}

bool ok_all(const std::vector<Val>& vals) {
  return std::all_of(vals.begin(), vals.end(), [](const Val& v) { return v.ok; });
}

// The REAL type math on t computes in: REAL for REAL, LREAL for anything else.
const Type* real_of(Compiler& cc, const Type* t) {
  return t && t->kind == TypeKind::Real ? t : cc.elem(TypeKind::LReal);
}

// A string function's string operand, evaluated; its representation is decided once all
// operands are known (Compiler::string_slot).
std::optional<Val> str_val(Compiler& cc, const Expr* e, std::string_view fn) {
  Val v = cc.expr(*e);
  if (!v.ok) return std::nullopt;
  const Type* t = v.type ? v.type : cc.default_type(v.c);
  if (!t->is_string()) {
    cc.diags_.error("ST203", e->loc, std::string(fn) + " needs a STRING here, not " + t->name);
    return std::nullopt;
  }
  return v;
}

// A string function's STRING operand (a WSTRING converted to its UTF-8 text).
std::optional<Slot> str_arg(Compiler& cc, const Expr* e, std::string_view fn) {
  auto v = str_val(cc, e, fn);
  if (!v) return std::nullopt;
  return cc.string_slot(*v, false, e->loc);
}

// The string functions take ANY_STRING (IEC 61131-3): their operands in one representation,
// WSTRING when any of them is one; a STRING among WSTRINGs is converted, as its assignment
// to a WSTRING would be, never reinterpreted.
bool is_wide(const Val& v) { return v.type && v.type->kind == TypeKind::WString; }

// A string function's integer operand (a length, a position), passed as LINT.
std::optional<Slot> int_arg(Compiler& cc, const Expr* e, std::string_view fn) {
  Val v = cc.expr(*e);
  if (!v.ok) return std::nullopt;
  const Type* t = v.type ? v.type : cc.elem(TypeKind::LInt);
  if (!t->is_integer()) {
    cc.diags_.error("ST203", e->loc, std::string(fn) + " needs an integer here, not " + t->name);
    return std::nullopt;
  }
  return v.is_const ? cc.konst(cc.elem(TypeKind::LInt), v.c, e->loc) : cc.convert(v.slot, t, cc.elem(TypeKind::LInt));
}

// The arguments of a test-file built-in: positional only, counted by the caller (their
// messages say more than positional()'s would).
std::optional<std::vector<const Expr*>> test_args(Compiler& cc, const StdFunc& f, const CallExpr& c) {
  std::vector<const Expr*> args;
  for (const auto& a : c.args) {
    if (a.name || a.is_output) {
      cc.diags_.error("ST210", a.loc, std::string(f.name) + " takes positional arguments");
      return std::nullopt;
    }
    args.push_back(a.value.get());
  }
  return args;
}

bool untyped_number(const Val& v) {
  return v.is_const && !v.type && (v.c.k == ConstV::K::Int || v.c.k == ConstV::K::Real);
}

double as_double(const ConstV& c) { return c.k == ConstV::K::Real ? c.r : static_cast<double>(c.i); }

// MIN, MAX and LIMIT of untyped literals only: an untyped literal again (an integer when
// all are integers), so that the context types it as it would the literal itself.
std::optional<Val> fold_untyped_pick(Pick pick, const std::vector<Val>& vals) {
  if (!std::all_of(vals.begin(), vals.end(), untyped_number)) return std::nullopt;
  bool real = std::any_of(vals.begin(), vals.end(), [](const Val& v) { return v.c.k == ConstV::K::Real; });
  auto less = [&](const Val& a, const Val& b) { return real ? as_double(a.c) < as_double(b.c) : a.c.i < b.c.i; };
  Val r;
  if (pick == Pick::Limit) {
    // LIMIT(MN, IN, MX) = MIN(MAX(IN, MN), MX)
    r = less(vals[1], vals[0]) ? vals[0] : vals[1];
    if (less(vals[2], r)) r = vals[2];
  } else {
    r = vals[0];
    for (size_t i = 1; i < vals.size(); ++i)
      if (pick == Pick::Min ? less(vals[i], r) : less(r, vals[i])) r = vals[i];
  }
  if (real && r.c.k == ConstV::K::Int) {
    r.c.k = ConstV::K::Real;
    r.c.r = static_cast<double>(r.c.i);
  }
  return r;
}

Val void_val(Compiler& cc) {
  Val none;
  none.type = cc.elem(TypeKind::Void);
  return none;
}

using Emitter = std::optional<Val> (Compiler::*)(const StdFunc&, const CallExpr&);

// The emitter of each family. A switch without a default: a family added without an
// emitter is a compile error (-Wswitch). (A static_assert over a constexpr table of member
// pointers is not a constant expression under the sanitizers.)
Emitter emitter_of(StdFamily f) {
  using F = StdFamily;
  switch (f) {
    case F::Math: return &Compiler::emit_math;
    case F::Expt: return &Compiler::emit_expt;
    case F::Abs: return &Compiler::emit_abs;
    case F::Extremum: return &Compiler::emit_extremum;
    case F::Sel:
    case F::Mux: return &Compiler::emit_select;
    case F::Operator: return &Compiler::emit_operator;
    case F::ConcatDateTod: return &Compiler::emit_concat_date_tod;
    case F::Move: return &Compiler::emit_move;
    case F::Shift: return &Compiler::emit_shift;
    case F::String: return &Compiler::emit_string;
    case F::Concat: return &Compiler::emit_concat;
    case F::Replace: return &Compiler::emit_replace;
    case F::AddressOf: return &Compiler::emit_address_of;
    case F::SizeOf: return &Compiler::emit_sizeof;
    case F::Bound: return &Compiler::emit_bound;
    case F::IsValidRef: return &Compiler::emit_is_valid_ref;
    case F::Now: return &Compiler::emit_now;
    case F::Temporal: return &Compiler::emit_temporal;
    case F::AdvanceTime: return &Compiler::emit_advance_time;
    case F::Assert: return &Compiler::emit_assert;
    case F::System: return &Compiler::emit_system;
    case F::Count_: break;
  }
  return nullptr;
}


// The unit a time-like value counts in when converted to or from a number, in the
// engine's nanoseconds. CODESYS and TwinCAT store TIME in ms, LTIME in ns, DATE and
// DATE_AND_TIME in seconds since 1970-01-01 and TIME_OF_DAY in ms since midnight, and
// their conversions give those counts. MATIEC (--dialect iec) converts DATE, DT and TOD
// to whole seconds (its tv_sec); TIME keeps plcfi's milliseconds in both dialects.
int64_t count_unit_ns(const Type* t, Dialect dialect) {
  if (t->long_date) return 1;  // LDATE, LTOD, LDT: nanoseconds
  switch (t->kind) {
    case TypeKind::Time: return 1'000'000;
    case TypeKind::Date: case TypeKind::DateTime: return 1'000'000'000;
    case TypeKind::TimeOfDay: return dialect == Dialect::Codesys ? 1'000'000 : 1'000'000'000;
    default: return 1;
  }
}

}  // namespace

// ------------------------------------------------------------------ arguments, natives

std::vector<const Expr*> Compiler::positional(const CallExpr& c, size_t min, size_t max, std::string_view name) {
  std::vector<const Expr*> out;
  const StdFunc* f = find_std_function(name);
  const std::vector<const char*>* names = f ? &f->params : nullptr;
  bool formal = false;
  for (const auto& a : c.args) {
    if (a.is_output) {
      diags_.error("ST210", a.loc, std::string(name) + " has no outputs to capture with '=>'");
      return {};
    }
    if (a.name) formal = true;
  }
  if (formal) {
    out.assign(c.args.size(), nullptr);
    for (const auto& a : c.args) {
      size_t idx = SIZE_MAX;
      if (a.name && names)
        for (size_t i = 0; i < names->size(); ++i)
          if (iequals((*names)[i], a.name->text)) idx = i;
      if (a.name && idx == SIZE_MAX) {
        // The extensible functions' inputs: IN1, IN2, ... (ADD, MAX, CONCAT, ...), or
        // IN0, IN1, ... after MUX's K.
        std::string n = canon(a.name->text);
        bool after_k = names && names->size() && iequals((*names)[0], "K");  // MUX: K comes first
        if (n.size() > 2 && n.size() < 6 && n.rfind("IN", 0) == 0 && std::all_of(n.begin() + 2, n.end(), ::isdigit)) {
          size_t k = static_cast<size_t>(std::stoul(n.substr(2)));
          if (after_k) idx = k + 1;
          else if (k >= 1) idx = k - 1;
        } else if (n == "IN") idx = 0;
      }
      if (idx == SIZE_MAX) {
        diags_.error("ST212", a.loc, std::string(name) + " has no parameter '" + (a.name ? a.name->text : "") + "'");
        return {};
      }
      if (idx >= out.size()) out.resize(idx + 1, nullptr);
      out[idx] = a.value.get();
    }
    for (size_t i = 0; i < out.size(); ++i)
      if (!out[i]) {
        diags_.error("ST210", c.loc, std::string(name) + ": parameter " + std::to_string(i + 1) + " is missing");
        return {};
      }
  } else {
    for (const auto& a : c.args) out.push_back(a.value.get());
  }
  if (out.size() < min || out.size() > max) {
    std::string count = min == max        ? std::to_string(min)
                        : max == SIZE_MAX ? std::to_string(min) + " or more"
                                          : std::to_string(min) + " to " + std::to_string(max);
    diags_.error("ST210", c.loc,
                 std::string(name) + " takes " + count + " argument(s), not " + std::to_string(out.size()));
    return {};
  }
  for (const Expr* e : out)
    if (!e) return {};
  return out;
}

std::vector<const Expr*> Compiler::positional(const CallExpr& c, const StdFunc& f) {
  return positional(c, f.min_args, f.max_count(), f.name);
}

Val Compiler::native(Native n, const Type* result, std::initializer_list<Slot> args, uint32_t cap) {
  return native_list(n, result, std::vector<Slot>(args), cap);
}

Val Compiler::native_list(Native n, const Type* result, const std::vector<Slot>& args, uint32_t cap) {
  Slot d = result->is_string() ? temp(result->size, result->align) : temp_for(result);
  Arg a[4] = {0u, 0u, 0u, 0u};
  size_t i = 0;
  for (Slot s : args) a[i++] = Arg(s);
  emit(Op::NATIVE, {static_cast<uint32_t>(n) | (cap << 16), d, a[0], a[1], a[2]});
  def(d, 2);
  return slot_val(result, d);
}

// ------------------------------------------------------------------ dispatch

std::optional<Val> Compiler::builtin(const std::string& name, const CallExpr& c) {
  const StdFunc* f = find_std_function(name);
  if (!f) {
    if (auto conv = parse_conversion(*tt_, name)) return conversion(name, *conv, c);
    return std::nullopt;
  }
  // The temporal operators are ordinary names outside monitors (a user's RISING is found
  // before this, and an unknown one is reported as unknown).
  if (f->late_only() && (!b_->pou || !is_late(b_->pou))) return std::nullopt;
  if (f->codesys_only() && opt_.dialect != Dialect::Codesys) return std::nullopt;
  if (f->library_only() && (!b_->pou || !b_->pou->is_stdlib)) return std::nullopt;
  if (f->test_only() && !b_->in_test) {
    diags_.error("ST211", c.loc, name + " is only available in TEST, SETUP and TEARDOWN blocks of test files");
    return bad();
  }
  return (this->*emitter_of(f->family))(*f, c);
}

// ------------------------------------------------------------------ conversions

// The text of a value as TO_STRING gives it: a STRING[80].
Val Compiler::to_string_text(Slot s, const Type* from) {
  const Type* st = tt_->string_type(80, false);
  const TypeKind fk = from->kind;
  if (fk == TypeKind::Bool) return native(Native::BOOL_TO_S, st, {s}, 80);
  if (fk == TypeKind::LTime && from->unsigned_count) return native(Native::LTIME_U_TO_S, st, {s}, 80);
  if (fk == TypeKind::Time || fk == TypeKind::LTime) return native(Native::TIME_TO_S, st, {s}, 80);
  if (fk == TypeKind::Date) return native(Native::DATE_TO_S, st, {s}, 80);
  if (fk == TypeKind::TimeOfDay) return native(Native::TOD_TO_S, st, {s}, 80);
  if (fk == TypeKind::DateTime) return native(Native::DT_TO_S, st, {s}, 80);
  if (fk == TypeKind::Real) return native(Native::F32_TO_S, st, {s}, 80);
  if (fk == TypeKind::LReal) return native(Native::F64_TO_S, st, {s}, 80);
  if (from->is_unsigned_int() || from->is_bitstring())
    return native(Native::U64_TO_S, st, {convert(s, from, elem(TypeKind::ULInt))}, 80);
  return native(Native::I64_TO_S, st, {convert(s, from, elem(TypeKind::LInt))}, 80);
}

std::optional<Val> Compiler::conversion(const std::string& name, const ConversionName& conv, const CallExpr& c) {
  const Type* from = conv.from;
  const Type* to = conv.to;
  auto args = positional(c, 1, 1, name);
  if (args.empty()) return bad();
  Val v = expr(*args[0], from);
  if (!v.ok) return bad();
  if (from) {
    v = coerce(v, from, args[0]->loc, name.c_str());
    if (!v.ok) return bad();
  } else if (!v.type && conv.bcd == ConversionName::Bcd::Decode && v.c.k == ConstV::K::Int) {
    from = elem(TypeKind::LWord);  // BCD_TO_INT(16#0399): the literal's digits as a bit string
  } else {
    from = v.type ? v.type : default_type(v.c);
  }
  Slot s = to_slot(v, from, args[0]->loc);
  if (conv.unit_ns) {  // TIME_TO_US: durations are held in nanoseconds
    if (conv.unit_ns == 1) return slot_val(to, s);
    Slot d = temp(8, 8);
    emit(num_op(Op::DIV_I8, Storage::I64), {d, s, konst_i64(conv.unit_ns)});
    def(d);
    return slot_val(to, d);
  }
  if (conv.bcd != ConversionName::Bcd::None) {
    bool decode = conv.bcd == ConversionName::Bcd::Decode;
    if (decode ? !from->is_bitstring() : !from->is_integer()) {
      diags_.error("ST203", args[0]->loc, name + (decode ? " needs a bit string (BYTE, WORD, ...) holding BCD digits, not "
                                                         : " needs an integer, not ") + from->name);
      return bad();
    }
    const Type* U64 = elem(TypeKind::ULInt);
    Val r = native(decode ? Native::BCD_DECODE : Native::BCD_ENCODE, U64, {convert(s, from, U64)});
    return slot_val(to, convert(r.slot, U64, to));
  }
  // Not an error: an impossible conversion is an unknown function (reported by the caller).
  ConversionKind kind = conversion_kind(from, to, conv.trunc);
  if (from->kind == TypeKind::Enum) from = from->base;  // TO_INT(enum value)
  const Type* I64 = elem(TypeKind::LInt);
  const Type* F64 = elem(TypeKind::LReal);
  auto mul = [&](Slot x, int64_t k, Op op) {
    Slot d = temp(8, 8);
    emit(num_op(op, Storage::I64), {d, x, konst_i64(k)});
    def(d);
    return d;
  };
  TypeKind fk = from->kind;
  TypeKind tk = to->kind;
  // Nanoseconds per count when a time-like value becomes a number and back (see
  // count_unit_ns): the unit is the one the PLC stores the type in.
  int64_t from_unit = count_unit_ns(from, opt_.dialect);
  int64_t to_unit = count_unit_ns(to, opt_.dialect);
  switch (kind) {
    case ConversionKind::None:
      if (!conv.trunc) return std::nullopt;
      diags_.error("ST203", args[0]->loc, "TRUNC needs a REAL or LREAL, not " + from->name);
      return bad();
    case ConversionKind::Trunc: {
      Slot t = temp_for(from);
      emit(fk == TypeKind::Real ? Op::TRUNC_F32 : Op::TRUNC_F64, {t, s});
      return slot_val(to, convert(t, from, to));
    }
    case ConversionKind::StringCopy: return restring(s, from, tk == TypeKind::WString);
    case ConversionKind::ToString: {
      // The text is computed as a STRING; TO_WSTRING converts it.
      Val text = to_string_text(s, from);
      return tk == TypeKind::WString ? restring(text.slot, text.type, true) : text;
    }
    case ConversionKind::FromString: {
      s = restring(s, from, false).slot;  // WSTRING_TO_INT parses the text of the WSTRING
      if (tk == TypeKind::Bool) return native(Native::S_TO_BOOL, to, {s});
      if (to->is_real()) {
        Val r = native(Native::S_TO_F64, F64, {s});
        return slot_val(to, convert(r.slot, F64, to));
      }
      if (tk == TypeKind::Time || tk == TypeKind::LTime) return native(Native::S_TO_TIME, to, {s});
      Val r = native(to->is_unsigned_int() || to->is_bitstring() ? Native::S_TO_U64 : Native::S_TO_I64, I64, {s});
      return slot_val(to, convert(r.slot, I64, to));
    }
    case ConversionKind::DtToDate: return native(Native::DT_TO_DATE, to, {s});
    case ConversionKind::DtToTod: return native(Native::DT_TO_TOD, to, {s});
    case ConversionKind::Retype: return slot_val(to, s);
    case ConversionKind::ToBool: {
      Slot t = temp(1, 1);
      if (from->is_real()) {
        emit(num_op(Op::NE_I8, from->storage()), {t, s, konst(from, ConstV{ConstV::K::Real, 0, 0.0, {}}, c.loc)});
        return slot_val(to, t);
      }
      Op op = from->size == 1   ? Op::TOBOOL8
              : from->size == 2 ? Op::TOBOOL16
              : from->size == 4 ? Op::TOBOOL32
                                : Op::TOBOOL64;
      emit(op, {t, s});
      def(t);
      return slot_val(to, t);
    }
    case ConversionKind::TimeToNumber: {
      Slot x = from_unit != 1 ? mul(s, from_unit, Op::DIV_I8) : s;
      if (to->is_real() && from_unit != 1) {
        Slot f = convert(s, I64, F64);
        Slot d = temp(8, 8);
        emit(Op::DIV_F64, {d, f, konst(F64, ConstV{ConstV::K::Real, 0, static_cast<double>(from_unit), {}}, c.loc)});
        return slot_val(to, convert(d, F64, to));
      }
      // An unsigned LTIME (CODESYS) converts as the ULINT count it is.
      return slot_val(to, convert(x, from->unsigned_count ? elem(TypeKind::ULInt) : I64, to));
    }
    case ConversionKind::NumberToTime: {
      if (from->is_real()) {
        Slot f = convert(s, from, F64);
        Slot d = temp(8, 8);
        emit(Op::MUL_F64, {d, f, konst(F64, ConstV{ConstV::K::Real, 0, static_cast<double>(to_unit), {}}, c.loc)});
        return slot_val(to, convert(d, F64, to->unsigned_count ? elem(TypeKind::ULInt) : I64));
      }
      if (to->unsigned_count) return slot_val(to, convert(s, from, elem(TypeKind::ULInt)));  // ULINT_TO_LTIME: the count
      Slot x = convert(s, from, I64);
      return slot_val(to, to_unit != 1 ? mul(x, to_unit, Op::MUL_I8) : x);
    }
    case ConversionKind::Round: {
      // REAL_TO_INT rounds to the nearest integer, exact halves to the even one (IEC 61131-3
      // Table 22, the IEC 60559 convention: REAL_TO_INT(2.5) = 2).
      Slot t = temp_for(from);
      emit(fk == TypeKind::Real ? Op::ROUND_F32 : Op::ROUND_F64, {t, s});
      def(t);
      return slot_val(to, convert(t, from, to));
    }
    case ConversionKind::Numeric: return slot_val(to, convert(s, from, to));
  }
  return std::nullopt;
}

// ------------------------------------------------------------------ numbers

std::optional<Val> Compiler::emit_math(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Val v = expr(*args[0]);
  if (!v.ok) return bad();
  const Type* from = v.type ? v.type : default_type(v.c);
  if (!from->is_numeric()) {
    diags_.error("ST203", args[0]->loc, std::string(f.name) + " needs a number, not " + from->name);
    return bad();
  }
  const Type* rt = real_of(*this, from);
  Slot s = v.is_const ? konst(rt, v.c, c.loc) : convert(v.slot, from, rt);
  // The LREAL variant of each native follows the REAL one.
  return native(static_cast<Native>(static_cast<uint32_t>(f.native) + (rt->kind == TypeKind::LReal ? 1 : 0)), rt, {s});
}

std::optional<Val> Compiler::emit_expt(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  auto vals = eval_all(*this, args);
  if (!ok_all(vals)) return bad();
  if (untyped_number(vals[0]) && untyped_number(vals[1])) {
    // EXPT(2.0, 3.0): an untyped REAL literal, typed where it is used (r := ... with r a REAL).
    Val out;
    out.is_const = true;
    out.c.k = ConstV::K::Real;
    out.c.r = std::pow(as_double(vals[0].c), as_double(vals[1].c));
    return out;
  }
  const Type* t = real_of(*this, vals[0].type);
  // An integer base is taken as it is and widened; an untyped or REAL one as t.
  const Type* at = vals[0].type && !vals[0].type->is_real() ? vals[0].type : t;
  Slot a = to_slot(coerce(vals[0], at, args[0]->loc, "EXPT"), at, args[0]->loc);
  a = convert(a, at, t);
  const Type* bt = vals[1].type ? vals[1].type : t;
  Slot b = vals[1].is_const ? konst(t, vals[1].c, args[1]->loc) : convert(vals[1].slot, bt, t);
  return native(t->kind == TypeKind::Real ? Native::EXPT_F32 : Native::EXPT_F64, t, {a, b});
}

std::optional<Val> Compiler::emit_abs(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Val v = expr(*args[0]);
  if (!v.ok) return bad();
  if (v.is_const && !v.type && (v.c.k == ConstV::K::Int || v.c.k == ConstV::K::Real)) {
    // ABS(-11): still an untyped literal, typed where it is used (i := ABS(-11) + i).
    if (v.c.k == ConstV::K::Int && v.c.i < 0) v.c.i = static_cast<int64_t>(0ULL - static_cast<uint64_t>(v.c.i));
    if (v.c.k == ConstV::K::Real) v.c.r = std::fabs(v.c.r);
    return v;
  }
  const Type* t = v.type ? v.type : default_type(v.c);
  if (!t->is_numeric()) {
    diags_.error("ST203", args[0]->loc, "ABS needs a number, not " + t->name);
    return bad();
  }
  Slot s = to_slot(v, t, c.loc);
  Slot d = temp_for(t);
  emit(num_op(Op::ABS_I8, t->storage()), {d, s});
  def(d);
  Val r = slot_val(t, d);
  r.nominal = v.nominal;  // a register value stays one (Val::nominal)
  return r;
}

// The IEC type of MIN/MAX/LIMIT/SEL/MUX over register values (Val::nominal): the common
// type of the inputs' IEC types, when one of them is a register value and it is narrower
// than the type `t` the selection is done in; else none.
const Type* Compiler::register_nominal(const std::vector<Val>& vals, const Type* t) {
  const Type* nom = nullptr;
  bool any = false;
  for (const Val& v : vals) {
    if (!v.type) continue;
    any = any || v.nominal;
    const Type* vt = v.nominal ? v.nominal : v.type;
    nom = nom ? common_type(*tt_, nom, vt) : vt;
    if (!nom) return nullptr;
  }
  return any && nom && nom->size < t->size ? nom : nullptr;
}

std::optional<Val> Compiler::emit_extremum(const StdFunc& f, const CallExpr& c) {
  std::string name(f.name);
  auto args = positional(c, f);
  if (args.empty()) return bad();
  auto vals = eval_all(*this, args);
  if (!ok_all(vals)) return bad();
  if (auto folded = fold_untyped_pick(f.pick, vals)) return *folded;
  const Type* t = first_type(*this, vals);
  if (!t || !is_min_max_operand(t)) {
    diags_.error("ST203", c.loc, name + " needs numbers of compatible types");
    return bad();
  }
  std::vector<Slot> slots;
  for (size_t i = 0; i < vals.size(); ++i) {
    Val cv = coerce(vals[i], t, args[i]->loc, name.c_str());
    if (!cv.ok) return bad();
    slots.push_back(to_slot(cv, t, args[i]->loc));
  }
  auto op2 = [&](Op op, Slot a, Slot b) {
    Slot d = temp_for(t);
    emit(num_op(op, t->storage()), {d, a, b});
    def(d);
    return d;
  };
  Slot r;
  if (f.pick == Pick::Limit) r = op2(Op::MIN_I8, op2(Op::MAX_I8, slots[1], slots[0]), slots[2]);
  else {
    r = slots[0];
    for (size_t i = 1; i < slots.size(); ++i) r = op2(f.pick == Pick::Min ? Op::MIN_I8 : Op::MAX_I8, r, slots[i]);
  }
  Val out = slot_val(t, r);
  out.nominal = register_nominal(vals, t);
  return out;
}

// SEL and MUX: the inputs are evaluated and converted to their common type first, then
// one of them is copied to the result (a branch, or a jump table).
std::optional<Val> Compiler::emit_select(const StdFunc& f, const CallExpr& c) {
  std::string name(f.name);
  bool mux = f.family == StdFamily::Mux;
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Val g = expr(*args[0]);
  if (!g.ok) return bad();
  std::vector<const Expr*> ins(args.begin() + 1, args.end());
  auto vals = eval_all(*this, ins);
  if (!ok_all(vals)) return bad();
  const Type* t = first_type(*this, vals);
  if (!t) {
    diags_.error("ST203", c.loc, name + " needs inputs of one type");
    return bad();
  }
  std::vector<Slot> slots;
  for (size_t i = 0; i < vals.size(); ++i) {
    Val cv = coerce(vals[i], t, ins[i]->loc, name.c_str());
    if (!cv.ok) return bad();
    slots.push_back(to_slot(cv, t, ins[i]->loc));
  }
  Slot d = t->is_string() ? temp(t->size, t->align) : temp_for(t);
  auto copy = [&](Slot src) {
    if (t->is_string()) emit(string_copy_op(t), {d, src, t->str_len});
    else if (t->size == 1 || t->size == 2 || t->size == 4 || t->size == 8) emit(mov_op(t->size), {d, src});
    else emit(Op::MOVN, {d, src, t->size});
  };
  Label end = new_label();
  if (!mux) {
    Val gc = coerce(g, elem(TypeKind::Bool), args[0]->loc, "SEL");
    if (!gc.ok) return bad();
    Slot gs = to_slot(gc, elem(TypeKind::Bool), args[0]->loc);
    if (!t->is_string() && (t->size == 1 || t->size == 2 || t->size == 4 || t->size == 8)) {
      // Both inputs are values already: one select, no branch.
      emit(sel_op(t->size), {d, gs, slots[1], slots[0]});
      def(d, 1);
      Val out = slot_val(t, d);
      out.nominal = register_nominal(vals, t);
      return out;
    }
    Label l0 = new_label();
    emit(Op::JMPF, {Arg::target(l0.id), gs});
    copy(slots[1]);
    emit(Op::JMP, {Arg::target(end.id)});
    bind(l0);
    copy(slots[0]);
  } else {
    const Type* gt = g.type ? g.type : elem(TypeKind::DInt);
    if (!gt->is_integer()) {
      diags_.error("ST203", args[0]->loc, "MUX needs an integer selector");
      return bad();
    }
    Slot k = convert(to_slot(g, gt, args[0]->loc), gt, elem(TypeKind::DInt));
    Label bad_k = new_label();
    std::vector<Label> ls;
    std::vector<Arg> jt{k, 0u, static_cast<uint32_t>(slots.size()), Arg::target(bad_k.id)};
    for (size_t i = 0; i < slots.size(); ++i) {
      ls.push_back(new_label());
      jt.push_back(Arg::target(ls.back().id));
    }
    emit_list(Op::JTAB, jt);
    for (size_t i = 0; i < slots.size(); ++i) {
      bind(ls[i]);
      copy(slots[i]);
      emit(Op::JMP, {Arg::target(end.id)});
    }
    bind(bad_k);
    mark(c.loc);
    emit(Op::TRAP, {static_cast<uint32_t>(TrapKind::IndexOutOfRange)});
  }
  bind(end);
  Val out = slot_val(t, d);
  out.nominal = register_nominal(vals, t);
  return out;
}

// Functional forms of the operators (ADD, GT, ...) and the named time functions: the
// operator applied left to right, with the operator's own type rules.
std::optional<Val> Compiler::emit_operator(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Val acc = expr(*args[0]);
  for (size_t i = 1; i < args.size() && acc.ok; ++i) {
    Val next = expr(*args[i], acc.type && acc.type->kind == TypeKind::Enum ? acc.type : nullptr);
    if (!next.ok) return bad();
    acc = combine(f.op, acc, next, c.loc);
  }
  return acc;
}

std::optional<Val> Compiler::emit_concat_date_tod(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Val d = expr(*args[0]);
  Val t = expr(*args[1]);
  if (!d.ok || !t.ok) return bad();
  if (!d.type || d.type->kind != TypeKind::Date || !t.type || t.type->kind != TypeKind::TimeOfDay) {
    diags_.error("ST203", c.loc, "CONCAT_DATE_TOD needs a DATE and a TIME_OF_DAY");
    return bad();
  }
  // Both count nanoseconds (since 1970, since midnight): the sum is the DATE_AND_TIME.
  const Type* I64 = elem(TypeKind::LInt);
  Slot a = d.is_const ? konst(I64, d.c, c.loc) : d.slot;
  Slot b = t.is_const ? konst(I64, t.c, c.loc) : t.slot;
  Slot r = temp(8, 8);
  emit(Op::ADD_I64, {r, a, b});
  def(r);
  return slot_val(elem(TypeKind::DateTime), r);
}

std::optional<Val> Compiler::emit_move(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  return expr(*args[0]);
}

std::optional<Val> Compiler::emit_shift(const StdFunc& f, const CallExpr& c) {
  std::string name(f.name);
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Val v = expr(*args[0]);
  Val n = expr(*args[1]);
  if (!v.ok || !n.ok) return bad();
  // An untyped literal is shifted in the context's width (b := ROR(16#45, 7) rotates a
  // BYTE), else as a DWORD.
  const Type* want = call_expected_;
  const Type* t = v.type ? v.type : want && (want->is_bitstring() || want->is_integer()) ? want : elem(TypeKind::DWord);
  if (t->ranged) t = elem(t->kind);
  if (!is_shift_operand(t)) {
    diags_.error("ST203", args[0]->loc, name + " needs a bit string or integer, not " + t->name);
    return bad();
  }
  const Type* nt = n.type ? n.type : elem(TypeKind::LInt);
  if (!is_shift_operand(nt)) {
    diags_.error("ST203", args[1]->loc, name + ": the shift count must be an integer");
    return bad();
  }
  const bool rotate = f.shift == Shift::Rol || f.shift == Shift::Ror;
  if (rotate && v.nominal) {  // a rotation has its IEC type's width: the register is cut first
    v = coerce(v, v.nominal, args[0]->loc, name.c_str());
    t = v.type;
  }
  Slot a = to_slot(v, t, args[0]->loc);
  // A DINT count (a loop counter, most often) is read as it is, without a ULINT copy.
  const bool dint_count = !n.is_const && nt->storage() == Storage::I32;
  Slot b = n.is_const ? konst(elem(TypeKind::ULInt), n.c, args[1]->loc)
           : dint_count ? n.slot
                        : convert(n.slot, nt, elem(TypeKind::ULInt));
  Op base = f.shift == Shift::Shl   ? (dint_count ? Op::SHLD_I8 : Op::SHL_I8)
            : f.shift == Shift::Shr ? (dint_count ? Op::SHRD_I8 : Op::SHR_I8)
            : f.shift == Shift::Rol ? (dint_count ? Op::ROLD_I8 : Op::ROL_I8)
                                    : (dint_count ? Op::RORD_I8 : Op::ROR_I8);
  Slot d = temp_for(t);
  emit(int_op(base, t->storage()), {d, a, b});
  def(d);
  Val r = slot_val(t, d);
  r.nominal = rotate ? nullptr : v.nominal;  // SHR(m - 4, 1) shifts the register and stays one
  return r;
}

// ------------------------------------------------------------------ strings

// Results of the string functions are STRING[255], on WSTRINGs WSTRING[255]; lengths and
// positions count bytes of a STRING, code units of a WSTRING.
std::optional<Val> Compiler::emit_string(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  std::vector<std::optional<Val>> strs(args.size());
  std::vector<Slot> slots(args.size());
  bool wide = false;
  for (size_t i = 0; i < args.size(); ++i) {
    if (f.operands[i] == 'S') {
      strs[i] = str_val(*this, args[i], f.name);
      if (!strs[i]) return bad();
      wide = wide || is_wide(*strs[i]);
    } else {
      auto s = int_arg(*this, args[i], f.name);
      if (!s) return bad();
      slots[i] = *s;
    }
  }
  for (size_t i = 0; i < args.size(); ++i)
    if (strs[i]) slots[i] = string_slot(*strs[i], wide, args[i]->loc);
  return native_list(wide ? wide_native(f.native) : f.native,
                     f.int_result ? elem(TypeKind::Int) : tt_->string_type(255, wide), slots, f.int_result ? 0 : 255);
}

std::optional<Val> Compiler::emit_concat(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  std::vector<Val> vals;
  bool wide = false;
  for (const Expr* a : args) {
    auto v = str_val(*this, a, f.name);
    if (!v) return bad();
    wide = wide || is_wide(*v);
    vals.push_back(*v);
  }
  const Type* rstr = tt_->string_type(255, wide);
  Slot acc = string_slot(vals[0], wide, args[0]->loc);
  for (size_t i = 1; i < args.size(); ++i)
    acc = native(wide ? Native::W_CONCAT : Native::S_CONCAT, rstr, {acc, string_slot(vals[i], wide, args[i]->loc)}, 255).slot;
  return slot_val(rstr, acc);
}

std::optional<Val> Compiler::emit_replace(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  auto a = str_val(*this, args[0], f.name);
  auto b = str_val(*this, args[1], f.name);
  auto l = int_arg(*this, args[2], f.name);
  auto p = int_arg(*this, args[3], f.name);
  if (!a || !b || !l || !p) return bad();
  const bool wide = is_wide(*a) || is_wide(*b);
  // The native takes three operands: length and position go as one pair.
  Slot lp = temp(16, 8);
  emit(Op::MOV8, {lp, *l});
  emit(Op::MOV8, {lp.plus(8), *p});
  return native(wide ? Native::W_REPLACE : Native::S_REPLACE, tt_->string_type(255, wide),
                {string_slot(*a, wide, args[0]->loc), string_slot(*b, wide, args[1]->loc), lp}, 255);
}

// ------------------------------------------------------------------ memory, clock

std::optional<Val> Compiler::emit_address_of(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Place p = place(*args[0], true);
  if (!p.ok) return bad();
  return slot_val(tt_->ref_to(p.type), addr_of(p, args[0]->loc));
}

// __ISVALIDREF(r): TRUE when the REFERENCE TO r is bound (looks at r itself, not its target).
std::optional<Val> Compiler::emit_is_valid_ref(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Place p = place_ref(*args[0], false);
  if (!p.ok) return bad();
  if (!is_reference(p.type)) {
    diags_.error("ST232", args[0]->loc, "__ISVALIDREF needs a REFERENCE TO, not " + p.type->name);
    return bad();
  }
  Val ref = load(p);
  Val null;
  null.is_const = true;
  null.type = null_type_;
  null.c = ConstV{ConstV::K::Int, 0, 0, {}};
  return combine(BinaryOp::Ne, ref, null, c.loc);
}

std::optional<Val> Compiler::emit_sizeof(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.empty()) return bad();
  Val v = expr(*args[0]);
  if (!v.ok) return bad();
  const Type* t = v.type ? v.type : default_type(v.c);
  Val out;
  out.is_const = true;
  out.type = elem(TypeKind::UDInt);
  out.c = ConstV{ConstV::K::Int, t->size, 0, {}};
  return out;
}

// LOWER_BOUND(arr, dim) / UPPER_BOUND(arr, dim): a DINT, constant for an array whose
// bounds are declared, read from the in-out's slot for an ARRAY[*].
std::optional<Val> Compiler::emit_bound(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.size() != 2) return bad();
  Place arr = place(*args[0], false);
  if (!arr.ok) return bad();
  if (arr.type->kind != TypeKind::Array) {
    diags_.error("ST210", args[0]->loc, std::string(f.name) + " needs an array, not " + arr.type->name);
    return bad();
  }
  auto dim = const_int(*args[1], b_->file);
  if (!dim) return bad();
  if (*dim < 1 || static_cast<uint64_t>(*dim) > arr.type->dims.size()) {
    diags_.error("ST210", args[1]->loc, fmt::format("{}: dimension {} of {}, which has {}", f.name, *dim, arr.type->name, arr.type->dims.size()));
    return bad();
  }
  const bool upper = f.name == "UPPER_BOUND";
  const auto d = static_cast<size_t>(*dim - 1);
  if (!arr.type->open) {
    Val out;
    out.is_const = true;
    out.type = elem(TypeKind::DInt);
    out.c = ConstV{ConstV::K::Int, upper ? arr.type->dims[d].hi : arr.type->dims[d].lo, 0, {}};
    return out;
  }
  Place b;
  if (!open_bound(arr, d, upper, c.loc, &b)) return bad();
  return load(b);
}

// The Tc2_System functions: each argument converted to its operand's type as a call of
// the library's function would convert it, then the native helper (vm/cpp_functions.cpp).
std::optional<Val> Compiler::emit_system(const StdFunc& f, const CallExpr& c) {
  auto args = positional(c, f);
  if (args.size() != std::string_view(f.operands).size()) return bad();
  auto type_of = [&](char k) -> const Type* {
    switch (k) {
      case 'A': case 'U': return elem(TypeKind::UDInt);
      case 'Y': return elem(TypeKind::USInt);
      case 'W': return elem(TypeKind::DWord);
      case 'D': return elem(TypeKind::DInt);
      case 'F': return elem(TypeKind::LReal);
      default: return tt_->string_type(255, false);
    }
  };
  std::vector<Slot> slots;
  for (size_t i = 0; i < args.size(); ++i) {
    const char k = f.operands[i];
    if (k == 'S') {
      auto s = str_arg(*this, args[i], f.name);
      if (!s) return bad();
      slots.push_back(*s);
      continue;
    }
    Val v = expr(*args[i]);
    if (!v.ok) return bad();
    const Type* to = type_of(k);
    // An address may be a pointer or a reference (ADR(x), a POINTER TO variable): its
    // value is the address, a UDINT in this engine.
    if (k == 'A' && v.type && v.type->kind == TypeKind::Ref) {
      slots.push_back(v.slot);
      continue;
    }
    const std::string what = std::string(f.name) + "'s " + f.params[i];
    Val cv = coerce(v, to, args[i]->loc, what.c_str());
    if (!cv.ok) return bad();
    slots.push_back(to_slot(cv, to, args[i]->loc));
  }
  const Type* result = f.result == 'Y' ? elem(TypeKind::Byte) : type_of(f.result);
  mark(c.loc);  // a trap of the function (MEMCPY outside the memory) points at the call
  return native_list(f.native, result, slots, 0);
}

std::optional<Val> Compiler::emit_now(const StdFunc& f, const CallExpr& c) {
  if (!f.extensible() && !c.args.empty()) {  // TIME() takes none; __NOW is the compiler's own
    diags_.error("ST210", c.loc, std::string(f.name) + " takes no arguments");
    return bad();
  }
  Slot d = temp(8, 8);
  emit(Op::NOW, {d});
  def(d);
  return slot_val(elem(TypeKind::Time), d);
}

// ------------------------------------------------------------------ monitors

// Temporal operators of requirement formulas (EDTL), only in monitors: each occurrence
// keeps its argument's current and previous value in hidden state; all are FALSE in the
// first state.
std::optional<Val> Compiler::emit_temporal(const StdFunc& f, const CallExpr& c) {
  std::string name(f.name);
  auto args = positional(c, f);
  if (args.empty()) return bad();
  const Type* BOOL = elem(TypeKind::Bool);
  if (f.temporal == Temporal::Passed) {
    // time(i) - time(j) >= t, with the elapsed time since the timer point as an input.
    const Symbol* el = lookup("__ELAPSED");
    if (!el) {
      diags_.error("ST211", c.loc, "PASSED is not available here");
      return bad();
    }
    Val t = expr(*args[0]);
    if (!t.ok) return bad();
    if (!t.type || (t.type->kind != TypeKind::Time && t.type->kind != TypeKind::LTime)) {
      diags_.error("ST203", args[0]->loc,
                   "PASSED needs a duration such as T#2s, not " + (t.type ? t.type->name : std::string("a number")));
      return bad();
    }
    Val e;
    e.type = el->type;
    e.slot = Slot{el->offset, SK::Var};
    return combine(BinaryOp::Ge, e, t, c.loc);
  }
  bool edge = f.temporal == Temporal::Rising || f.temporal == Temporal::Falling || f.temporal == Temporal::High ||
              f.temporal == Temporal::Low;
  Val v = edge ? cond(*args[0]) : expr(*args[0]);
  if (!v.ok) return bad();
  const Type* t = v.type ? v.type : default_type(v.c);
  if (!edge && !is_change_operand(t)) {
    diags_.error("ST203", args[0]->loc,
                 name + " needs a number, bit string, time or enumeration value, not " + t->name);
    return bad();
  }
  if (!edge && f.temporal != Temporal::Changes && !is_ordered_operand(t)) {
    diags_.error("ST203", args[0]->loc, name + " needs an ordered value (a number or a time), not " + t->name);
    return bad();
  }
  Slot cur = hidden(t->size, t->align), prev = hidden(t->size, t->align);
  if (!b_->started) b_->started = hidden(1, 1);
  Slot src = to_slot(v, t, args[0]->loc);
  if (!retarget(src, cur)) emit(mov_op(t->size), {cur, src});
  b_->edges.push_back({cur, prev, t->size});
  if (edge) {
    // One instruction: RISING = cur AND NOT prev, FALLING, HIGH, LOW; FALSE before the
    // first committed state.
    Op op = f.temporal == Temporal::Rising    ? Op::RISE
            : f.temporal == Temporal::Falling ? Op::FALL
            : f.temporal == Temporal::High    ? Op::STEADY_HIGH
                                              : Op::STEADY_LOW;
    Slot out = temp(1, 1);
    emit(op, {out, cur, prev, *b_->started});
    def(out);
    return slot_val(BOOL, out);
  }
  Slot r = temp(1, 1);
  Op cmp = f.temporal == Temporal::Changes ? Op::NE_I8 : f.temporal == Temporal::Increases ? Op::GT_I8 : Op::LT_I8;
  emit(num_op(cmp, t->storage()), {r, cur, prev});
  Slot out = temp(1, 1);
  emit(Op::BAND, {out, r, *b_->started});
  def(out);
  return slot_val(BOOL, out);
}

// ------------------------------------------------------------------ test files

std::optional<Val> Compiler::emit_advance_time(const StdFunc& f, const CallExpr& c) {
  auto args = test_args(*this, f, c);
  if (!args) return bad();
  if (args->size() < f.min_args || args->size() > f.max_args) {
    diags_.error("ST210", c.loc, "ADVANCE_TIME takes one duration");
    return bad();
  }
  const Expr* a = (*args)[0];
  Val v = expr(*a);
  if (!v.ok) return bad();
  const Type* t = v.type ? v.type : elem(TypeKind::LInt);
  if (!(t->kind == TypeKind::Time || t->kind == TypeKind::LTime || t->is_integer())) {
    diags_.error("ST203", a->loc, "ADVANCE_TIME needs a TIME or a number of nanoseconds, not " + t->name);
    return bad();
  }
  Slot s = v.is_const ? konst_i64(v.c.i) : convert(v.slot, t, elem(TypeKind::LInt));
  emit(Op::ADVTIME, {s});
  return void_val(*this);
}

std::optional<Val> Compiler::emit_assert(const StdFunc& f, const CallExpr& c) {
  std::string name(f.name);
  AssertKind kind = f.assert_kind;
  auto parsed = test_args(*this, f, c);
  if (!parsed) return bad();
  const std::vector<const Expr*>& args = *parsed;
  size_t nvals = f.min_args;  // the values compared; one more argument is the message
  if (args.size() < f.min_args || args.size() > f.max_args) {
    diags_.error("ST210", c.loc, name + " takes " + std::to_string(nvals) + " argument(s) and an optional message");
    return bad();
  }
  std::optional<Slot> msg;
  if (args.size() == nvals + 1) {
    Val m = expr(*args.back());
    if (!m.ok) return bad();
    if (!m.type || !m.type->is_string()) {
      diags_.error("ST203", args.back()->loc, "the assertion message must be a string");
      return bad();
    }
    msg = string_slot(m, false, args.back()->loc);  // the message is shown as UTF-8
  }
  auto emit_assert = [&](uint32_t kindword, Slot a, Slot b, Slot tol) {
    mark(c.loc);
    emit(Op::ASSERT, {kindword, a, b, tol, msg ? Arg(*msg) : Arg(0u)});
  };
  bool instance_arg = kind == AssertKind::Called || kind == AssertKind::CallCount;
  std::vector<Val> vals;
  for (size_t i = 0; i < nvals; ++i) {
    vals.push_back(instance_arg && i == 0 ? Val{} : expr(*args[i]));
    if (!vals.back().ok) return bad();
  }
  if (instance_arg) {
    Place p = place(*args[0], false);
    if (!p.ok || p.type->kind != TypeKind::Pou) {
      diags_.error("ST234", args[0]->loc, name + " needs a function block instance");
      return bad();
    }
    Slot ptr = addr_of(p, args[0]->loc);
    Slot cnt = ptr;
    if (kind == AssertKind::CallCount) {
      Val cv = coerce(vals[1], elem(TypeKind::LInt), args[1]->loc, name.c_str());
      if (!cv.ok) return bad();
      cnt = to_slot(cv, elem(TypeKind::LInt), args[1]->loc);
    }
    emit_assert(static_cast<uint32_t>(kind) << 8, ptr, cnt, ptr);
    return void_val(*this);
  }
  if (kind == AssertKind::True || kind == AssertKind::False) {
    Val cv = coerce(vals[0], elem(TypeKind::Bool), args[0]->loc, name.c_str());
    if (!cv.ok) return bad();
    Slot s = to_slot(cv, elem(TypeKind::Bool), args[0]->loc);
    emit_assert((static_cast<uint32_t>(kind) << 8) | static_cast<uint32_t>(ValueKind::Bool), s, s, s);
    return void_val(*this);
  }
  if (kind == AssertKind::Near) {
    const Type* F64 = elem(TypeKind::LReal);
    Slot s3[3];
    for (int i = 0; i < 3; ++i) {
      const Type* t = vals[i].type && vals[i].type->is_numeric() ? vals[i].type : F64;
      Val cv = coerce(vals[i], t, args[i]->loc, name.c_str());
      if (!cv.ok) return bad();
      s3[i] = convert(to_slot(cv, t, args[i]->loc), t, F64);
    }
    emit_assert((static_cast<uint32_t>(kind) << 8) | static_cast<uint32_t>(ValueKind::F64), s3[0], s3[1], s3[2]);
    return void_val(*this);
  }
  const Type* t = first_type(*this, vals);
  if (vals[0].type && vals[1].type && vals[0].type->kind == TypeKind::Enum && vals[0].type != vals[1].type) t = nullptr;
  if (vals[0].type && vals[1].type && vals[0].type->is_string() && vals[1].type->is_string())
    t = is_wide(vals[0]) || is_wide(vals[1]) ? tt_->string_type(255, true) : vals[0].type;
  if (!t) {
    auto what = [](const Val& v) { return v.type ? v.type->name : std::string("a literal"); };
    diags_.error("ST203", c.loc, name + ": cannot compare " + what(vals[0]) + " with " + what(vals[1]));
    return bad();
  }
  Val c0 = coerce(vals[0], t, args[0]->loc, name.c_str());
  Val c1 = coerce(vals[1], t, args[1]->loc, name.c_str());
  if (!c0.ok || !c1.ok) return bad();
  const bool wide = t->kind == TypeKind::WString;
  Slot a = t->is_string() ? string_slot(c0, wide, args[0]->loc) : to_slot(c0, t, args[0]->loc);
  Slot b = t->is_string() ? string_slot(c1, wide, args[1]->loc) : to_slot(c1, t, args[1]->loc);
  emit_assert((static_cast<uint32_t>(kind) << 8) | static_cast<uint32_t>(value_kind(t)), a, b, a);
  return void_val(*this);
}

}  // namespace plcfi::st::detail
