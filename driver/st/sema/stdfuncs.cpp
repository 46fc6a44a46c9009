// The table of standard functions and the conversion rules (see stdfuncs.hpp).
#include "stdfuncs.hpp"

#include <string>
#include <unordered_map>

namespace plcfi::st {

namespace {

// Builders for the table rows: the family's payload by name, the rest defaulted.
StdFunc fn(std::string_view name, StdFamily family, uint8_t min_args, uint8_t max_args, uint8_t flags = 0,
           std::vector<const char*> params = {}) {
  StdFunc f;
  f.name = name;
  f.family = family;
  f.min_args = min_args;
  f.max_args = max_args;
  f.flags = flags;
  f.params = std::move(params);
  return f;
}
StdFunc math(std::string_view name, Native n) {
  StdFunc f = fn(name, StdFamily::Math, 1, 1);
  f.native = n;
  return f;
}
// Only the plain arithmetic and logic operators take more than two operands; the named
// time functions (ADD_TIME, ...) take exactly two.
StdFunc oper(std::string_view name, BinaryOp op) {
  bool extensible = (op == BinaryOp::Add || op == BinaryOp::Mul || op == BinaryOp::And || op == BinaryOp::Or ||
                     op == BinaryOp::Xor) &&
                    name.find('_') == std::string_view::npos;
  StdFunc f = fn(name, StdFamily::Operator, 2, 2, extensible ? kStdExtensible : 0);
  f.op = op;
  return f;
}
StdFunc pick(std::string_view name, Pick p, uint8_t min_args, uint8_t max_args, uint8_t flags,
             std::vector<const char*> params = {}) {
  StdFunc f = fn(name, StdFamily::Extremum, min_args, max_args, flags, std::move(params));
  f.pick = p;
  return f;
}
StdFunc shift(std::string_view name, Shift s) {
  StdFunc f = fn(name, StdFamily::Shift, 2, 2, 0, {"IN", "N"});
  f.shift = s;
  return f;
}
StdFunc string(std::string_view name, Native n, const char* operands, bool int_result,
               std::vector<const char*> params) {
  auto count = static_cast<uint8_t>(std::string_view(operands).size());
  StdFunc f = fn(name, StdFamily::String, count, count, 0, std::move(params));
  f.native = n;
  f.operands = operands;
  f.int_result = int_result;
  return f;
}
// A function of Beckhoff's Tc2_System computed by a native helper.
StdFunc vendor(std::string_view name, Native n, const char* operands, char result, std::vector<const char*> params) {
  auto count = static_cast<uint8_t>(std::string_view(operands).size());
  StdFunc f = fn(name, StdFamily::System, count, count, kStdCodesysOnly, std::move(params));
  f.native = n;
  f.operands = operands;
  f.result = result;
  return f;
}
// A helper of plcfi's built-in libraries (TcUnit), computed by a native helper.
StdFunc library(std::string_view name, Native n, const char* operands, char result, std::vector<const char*> params) {
  StdFunc f = vendor(name, n, operands, result, std::move(params));
  f.flags = kStdLibraryOnly;
  return f;
}
StdFunc temporal(std::string_view name, Temporal t) {
  StdFunc f = fn(name, StdFamily::Temporal, 1, 1, kStdLateOnly);
  f.temporal = t;
  return f;
}
// The assertions take their values and an optional message.
StdFunc assertion(std::string_view name, AssertKind k, uint8_t values) {
  StdFunc f = fn(name, StdFamily::Assert, values, static_cast<uint8_t>(values + 1), kStdTestOnly);
  f.assert_kind = k;
  return f;
}

std::vector<StdFunc> make_table() {
  using F = StdFamily;
  return {
      math("SQRT", Native::SQRT_F32),
      math("LN", Native::LN_F32),
      math("LOG", Native::LOG_F32),
      math("EXP", Native::EXP_F32),
      math("SIN", Native::SIN_F32),
      math("COS", Native::COS_F32),
      math("TAN", Native::TAN_F32),
      math("ASIN", Native::ASIN_F32),
      math("ACOS", Native::ACOS_F32),
      math("ATAN", Native::ATAN_F32),
      fn("EXPT", F::Expt, 2, 2, 0, {"IN1", "IN2"}),
      fn("ABS", F::Abs, 1, 1),
      pick("MIN", Pick::Min, 2, 2, kStdExtensible),
      pick("MAX", Pick::Max, 2, 2, kStdExtensible),
      pick("LIMIT", Pick::Limit, 3, 3, 0, {"MN", "IN", "MX"}),
      fn("SEL", F::Sel, 3, 3, 0, {"G", "IN0", "IN1"}),
      // MUX(K, IN0, IN1, ...): named inputs INn are argument n + 1.
      fn("MUX", F::Mux, 2, 2, kStdExtensible, {"K"}),
      oper("ADD", BinaryOp::Add),
      oper("SUB", BinaryOp::Sub),
      oper("MUL", BinaryOp::Mul),
      oper("DIV", BinaryOp::Div),
      oper("MOD", BinaryOp::Mod),
      oper("AND", BinaryOp::And),
      oper("OR", BinaryOp::Or),
      oper("XOR", BinaryOp::Xor),
      oper("GT", BinaryOp::Gt),
      oper("GE", BinaryOp::Ge),
      oper("EQ", BinaryOp::Eq),
      oper("LE", BinaryOp::Le),
      oper("LT", BinaryOp::Lt),
      oper("NE", BinaryOp::Ne),
      oper("ADD_TIME", BinaryOp::Add),
      oper("SUB_TIME", BinaryOp::Sub),
      oper("MUL_TIME", BinaryOp::Mul),
      oper("DIV_TIME", BinaryOp::Div),
      oper("ADD_TOD_TIME", BinaryOp::Add),
      oper("ADD_DT_TIME", BinaryOp::Add),
      oper("SUB_TOD_TIME", BinaryOp::Sub),
      oper("SUB_DT_TIME", BinaryOp::Sub),
      oper("SUB_DATE_DATE", BinaryOp::Sub),
      oper("SUB_TOD_TOD", BinaryOp::Sub),
      oper("SUB_DT_DT", BinaryOp::Sub),
      oper("ADD_LTIME", BinaryOp::Add),
      oper("SUB_LTIME", BinaryOp::Sub),
      oper("MUL_LTIME", BinaryOp::Mul),
      oper("DIV_LTIME", BinaryOp::Div),
      fn("CONCAT_DATE_TOD", F::ConcatDateTod, 2, 2),
      fn("MOVE", F::Move, 1, 1),
      shift("SHL", Shift::Shl),
      shift("SHR", Shift::Shr),
      shift("ROL", Shift::Rol),
      shift("ROR", Shift::Ror),
      string("LEN", Native::S_LEN, "S", true, {"IN"}),
      string("LEFT", Native::S_LEFT, "SI", false, {"IN", "L"}),
      string("RIGHT", Native::S_RIGHT, "SI", false, {"IN", "L"}),
      string("MID", Native::S_MID, "SII", false, {"IN", "L", "P"}),
      string("INSERT", Native::S_INSERT, "SSI", false, {"IN1", "IN2", "P"}),
      string("DELETE", Native::S_DELETE, "SII", false, {"IN", "L", "P"}),
      string("FIND", Native::S_FIND, "SS", true, {"IN1", "IN2"}),
      fn("CONCAT", F::Concat, 2, 2, kStdExtensible),
      fn("REPLACE", F::Replace, 4, 4, 0, {"IN1", "IN2", "L", "P"}),
      fn("ADR", F::AddressOf, 1, 1),
      fn("REF", F::AddressOf, 1, 1),
      fn("SIZEOF", F::SizeOf, 1, 1),
      fn("LOWER_BOUND", F::Bound, 2, 2, 0, {"ARR", "DIM"}),
      fn("UPPER_BOUND", F::Bound, 2, 2, 0, {"ARR", "DIM"}),
      fn("__ISVALIDREF", F::IsValidRef, 1, 1),
      // Generated by the compiler itself, which passes no arguments: none are checked.
      fn("__NOW", F::Now, 0, 0, kStdExtensible),
      // Tc2_System (Beckhoff's documentation names the parameters).
      vendor("MEMCPY", Native::MEM_CPY, "AAU", 'U', {"destAddr", "srcAddr", "n"}),
      vendor("MEMMOVE", Native::MEM_MOVE, "AAU", 'U', {"destAddr", "srcAddr", "n"}),
      vendor("MEMSET", Native::MEM_SET, "AYU", 'U', {"destAddr", "fillByte", "n"}),
      vendor("MEMCMP", Native::MEM_CMP, "AAU", 'D', {"pBuf1", "pBuf2", "n"}),
      vendor("ADSLOGSTR", Native::ADSLOG_STR, "WSS", 'D', {"msgCtrlMask", "msgFmtStr", "strArg"}),
      vendor("ADSLOGDINT", Native::ADSLOG_DINT, "WSD", 'D', {"msgCtrlMask", "msgFmtStr", "dintArg"}),
      vendor("ADSLOGLREAL", Native::ADSLOG_LREAL, "WSF", 'D', {"msgCtrlMask", "msgFmtStr", "lrealArg"}),
      // The running task's index, read by the library's GETCURTASKINDEX (stdlib/tc2_system.cpp).
      vendor("__TASKINDEX", Native::TASK_INDEX, "", 'Y', {}),
      // TcUnit's library: an event for its runner, and a message in TcUnit's log.
      library("__TCUNIT", Native::TCUNIT, "DA", 'D', {"event", "suite"}),
      library("__TCUNIT_LOG", Native::ADSLOG_STR, "WSS", 'D', {"msgCtrlMask", "msgFmtStr", "strArg"}),
      // TIME(): the scan clock, CODESYS's and TwinCAT's function of that name.
      fn("TIME", F::Now, 0, 0, kStdCodesysOnly),
      temporal("RISING", Temporal::Rising),
      temporal("FALLING", Temporal::Falling),
      temporal("HIGH", Temporal::High),
      temporal("LOW", Temporal::Low),
      temporal("CHANGES", Temporal::Changes),
      temporal("INCREASES", Temporal::Increases),
      temporal("DECREASES", Temporal::Decreases),
      temporal("PASSED", Temporal::Passed),
      fn("ADVANCE_TIME", F::AdvanceTime, 1, 1, kStdTestOnly),
      assertion("ASSERT_EQ", AssertKind::Eq, 2),
      assertion("ASSERT_NEQ", AssertKind::Neq, 2),
      assertion("ASSERT_GT", AssertKind::Gt, 2),
      assertion("ASSERT_LT", AssertKind::Lt, 2),
      assertion("ASSERT_GE", AssertKind::Ge, 2),
      assertion("ASSERT_LE", AssertKind::Le, 2),
      assertion("ASSERT_TRUE", AssertKind::True, 1),
      assertion("ASSERT_FALSE", AssertKind::False, 1),
      assertion("ASSERT_NEAR", AssertKind::Near, 3),
      assertion("MOCK_VERIFY_CALLED", AssertKind::Called, 1),
      assertion("MOCK_VERIFY_CALL_COUNT", AssertKind::CallCount, 2),
  };
}

}  // namespace

const std::vector<StdFunc>& std_functions() {
  static const std::vector<StdFunc> table = make_table();
  return table;
}

const StdFunc* find_std_function(std::string_view upper_name) {
  static const auto index = [] {
    std::unordered_map<std::string_view, const StdFunc*> m;
    for (const StdFunc& f : std_functions()) m.emplace(f.name, &f);
    return m;
  }();
  auto it = index.find(upper_name);
  return it == index.end() ? nullptr : it->second;
}

std::optional<ConversionName> parse_conversion(const TypeTable& tt, std::string_view upper_name) {
  std::string_view from_name, to_name;
  ConversionName out;
  using Bcd = ConversionName::Bcd;
  auto ends_with = [](std::string_view s, std::string_view tail) {
    return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
  };
  size_t at = upper_name.find("_TO_");
  size_t trunc_at = upper_name.find("_TRUNC_");
  if (upper_name.rfind("TRUNC_", 0) == 0) {
    to_name = upper_name.substr(6);
    out.trunc = true;
  } else if (trunc_at != std::string_view::npos) {
    from_name = upper_name.substr(0, trunc_at);
    to_name = upper_name.substr(trunc_at + 7);
    out.trunc = true;
  } else if (upper_name.rfind("BCD_TO_", 0) == 0) {
    to_name = upper_name.substr(7);
    out.bcd = Bcd::Decode;
  } else if (upper_name.rfind("TO_BCD_", 0) == 0) {
    to_name = upper_name.substr(7);
    out.bcd = Bcd::Encode;
  } else if (at != std::string_view::npos && at >= 4 && upper_name.substr(at - 4, 4) == "_BCD") {
    from_name = upper_name.substr(0, at - 4);  // WORD_BCD_TO_UINT
    to_name = upper_name.substr(at + 4);
    out.bcd = Bcd::Decode;
  } else if (at != std::string_view::npos && upper_name.substr(at + 4).rfind("BCD_", 0) == 0) {
    from_name = upper_name.substr(0, at);  // UINT_TO_BCD_WORD
    to_name = upper_name.substr(at + 8);
    out.bcd = Bcd::Encode;
  } else if (at != std::string_view::npos && ends_with(upper_name, "_TO_BCD")) {
    // INT_TO_BCD: into the bit string of the integer's width.
    from_name = upper_name.substr(0, at);
    out.from = tt.by_name(from_name);
    if (!out.from || !out.from->is_integer()) return std::nullopt;
    static constexpr TypeKind kBits[] = {TypeKind::Byte, TypeKind::Word, TypeKind::DWord, TypeKind::LWord};
    uint32_t w = out.from->size == 1 ? 0 : out.from->size == 2 ? 1 : out.from->size == 4 ? 2 : 3;
    out.to = tt.elementary(kBits[w]);
    out.bcd = Bcd::Encode;
    return out;
  } else if (at != std::string_view::npos) {
    from_name = upper_name.substr(0, at);
    to_name = upper_name.substr(at + 4);
    static constexpr std::pair<std::string_view, int64_t> kUnits[] = {
        {"NS", 1}, {"US", 1'000}, {"MS", 1'000'000}, {"S", 1'000'000'000}};
    for (auto [unit, ns] : kUnits)
      if (to_name == unit && (from_name == "TIME" || from_name == "LTIME")) {
        out.from = tt.by_name(from_name);
        out.to = tt.elementary(TypeKind::LInt);
        out.unit_ns = ns;
        return out;
      }
  } else if (upper_name.rfind("TO_", 0) == 0) {
    to_name = upper_name.substr(3);
  } else if (upper_name == "TRUNC") {
    to_name = "DINT";
    out.trunc = true;
  } else {
    return std::nullopt;
  }
  out.to = tt.by_name(to_name);
  out.from = from_name.empty() ? nullptr : tt.by_name(from_name);
  if (!out.to || (!from_name.empty() && !out.from)) return std::nullopt;
  if (out.trunc && !(out.to->is_integer() || out.to->is_bitstring())) return std::nullopt;
  if (out.trunc && out.from && !out.from->is_real()) return std::nullopt;
  if (out.bcd == Bcd::Decode && !(out.to->is_integer() && (!out.from || out.from->is_bitstring()))) return std::nullopt;
  if (out.bcd == Bcd::Encode && !(out.to->is_bitstring() && (!out.from || out.from->is_integer()))) return std::nullopt;
  return out;
}

// The order of the tests matters: strings first (any type has a text), then the dates
// that change representation, the time-like types among themselves, BOOL, and numbers.
ConversionKind conversion_kind(const Type* from, const Type* to, bool trunc) {
  using K = ConversionKind;
  if (from->kind == TypeKind::Enum) from = from->base;  // TO_INT(enum value)
  TypeKind fk = from->kind;
  TypeKind tk = to->kind;
  if (trunc) return from->is_real() ? K::Trunc : K::None;
  if (to->is_string()) {
    if (from->is_string()) return K::StringCopy;
    bool printable = fk == TypeKind::Bool || fk == TypeKind::Time || fk == TypeKind::LTime || fk == TypeKind::Date ||
                     fk == TypeKind::TimeOfDay || fk == TypeKind::DateTime || from->is_real() ||
                     from->is_bitstring() || from->is_integer();
    return printable ? K::ToString : K::None;
  }
  if (from->is_string()) {
    bool parsable = tk == TypeKind::Bool || to->is_real() || tk == TypeKind::Time || tk == TypeKind::LTime ||
                    to->is_integer() || to->is_bitstring();
    return parsable ? K::FromString : K::None;
  }
  if (fk == TypeKind::DateTime && tk == TypeKind::Date) return K::DtToDate;
  if (fk == TypeKind::DateTime && tk == TypeKind::TimeOfDay) return K::DtToTod;
  if (from->is_time_like() && to->is_time_like()) return K::Retype;
  if (tk == TypeKind::Bool) return fk == TypeKind::Bool ? K::Retype : K::ToBool;
  if (from->is_time_like()) return K::TimeToNumber;
  if (to->is_time_like()) return K::NumberToTime;
  if (from->is_real() && (to->is_integer() || to->is_bitstring())) return K::Round;
  if ((from->is_numeric() || from->is_anybit()) && (to->is_numeric() || to->is_anybit())) return K::Numeric;
  return K::None;
}

}  // namespace plcfi::st
