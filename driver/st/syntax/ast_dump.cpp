// Renders AST nodes as short S-expressions so tests can compare whole trees as strings.
#include "ast_dump.hpp"

#include <sstream>

namespace plcfi::st {

namespace {

std::string opt(const ExprPtr& e) { return e ? dump(*e) : std::string("_"); }

// " a (b := c) (NOT q => d)": the arguments of a call or of a declaration's FB_init.
std::string dump_args(const std::vector<CallArg>& args) {
  std::string s;
  for (const auto& a : args) {
    if (!a.name) {
      s += " " + opt(a.value);
      continue;
    }
    s += std::string(" (") + (a.negate ? "NOT " : "") + a.name->text + (a.is_output ? " => " : " := ") + opt(a.value) + ")";
  }
  return s;
}

std::string literal(const LiteralExpr& l) {
  std::ostringstream out;
  if (!l.type_prefix.empty()) out << l.type_prefix << '#';
  switch (l.lit) {
    case LiteralKind::Int: out << l.int_value; break;
    case LiteralKind::Real: out << l.real_value; break;
    case LiteralKind::Bool: out << (l.int_value ? "TRUE" : "FALSE"); break;
    case LiteralKind::String: out << '\'' << l.str_value << '\''; break;
    case LiteralKind::WString: out << '"' << l.str_value << '"'; break;
    case LiteralKind::Time: out << l.time_ns << "ns"; break;
    case LiteralKind::Date: out << "date:" << l.time_ns; break;
    case LiteralKind::TimeOfDay: out << "tod:" << l.time_ns; break;
    case LiteralKind::DateTime: out << "dt:" << l.time_ns; break;
  }
  return out.str();
}

}  // namespace

std::string dump(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Literal: return literal(static_cast<const LiteralExpr&>(e));
    case ExprKind::EnumLiteral: {
      const auto& x = static_cast<const EnumLiteralExpr&>(e);
      return "(enum " + x.type_name.text + " " + x.value.text + ")";
    }
    case ExprKind::Name: return static_cast<const NameExpr&>(e).name.text;
    case ExprKind::DirectAddr: return static_cast<const DirectAddrExpr&>(e).text;
    case ExprKind::Member: {
      const auto& x = static_cast<const MemberExpr&>(e);
      return "(. " + opt(x.base) + " " + x.member.text + ")";
    }
    case ExprKind::BitAccess: {
      const auto& x = static_cast<const BitAccessExpr&>(e);
      return "(bit " + opt(x.base) + " " + std::to_string(x.bit) + ")";
    }
    case ExprKind::Index: {
      const auto& x = static_cast<const IndexExpr&>(e);
      std::string s = "([] " + opt(x.base);
      for (const auto& i : x.indices) s += " " + opt(i);
      return s + ")";
    }
    case ExprKind::Deref: return "(^ " + opt(static_cast<const DerefExpr&>(e).base) + ")";
    case ExprKind::Call: {
      const auto& x = static_cast<const CallExpr&>(e);
      return "(call " + opt(x.callee) + dump_args(x.args) + ")";
    }
    case ExprKind::Unary: {
      const auto& x = static_cast<const UnaryExpr&>(e);
      const char* op = x.op == UnaryOp::Neg ? "neg" : x.op == UnaryOp::Not ? "NOT" : "plus";
      return std::string("(") + op + " " + opt(x.operand) + ")";
    }
    case ExprKind::Binary: {
      const auto& x = static_cast<const BinaryExpr&>(e);
      return std::string("(") + op_text(x.op) + " " + opt(x.lhs) + " " + opt(x.rhs) + ")";
    }
    case ExprKind::This: return "THIS";
    case ExprKind::Super: return "SUPER";
    case ExprKind::ArrayInit: {
      const auto& x = static_cast<const ArrayInitExpr&>(e);
      std::string s = "[";
      for (size_t i = 0; i < x.items.size(); ++i) {
        if (i) s += ", ";
        if (x.items[i].repeat) s += opt(x.items[i].repeat) + "(" + (x.items[i].value ? dump(*x.items[i].value) : "") + ")";
        else s += opt(x.items[i].value);
      }
      return s + "]";
    }
    case ExprKind::StructInit: {
      const auto& x = static_cast<const StructInitExpr&>(e);
      std::string s = "(";
      for (size_t i = 0; i < x.items.size(); ++i) {
        if (i) s += ", ";
        s += x.items[i].field.text + " := " + opt(x.items[i].value);
      }
      return s + ")";
    }
  }
  return "?";
}

std::string dump(const StmtList& list) {
  std::string s = "(";
  for (size_t i = 0; i < list.size(); ++i) {
    if (i) s += " ";
    s += dump(*list[i]);
  }
  return s + ")";
}

std::string dump(const Stmt& s) {
  switch (s.kind) {
    case StmtKind::Assign: {
      const auto& x = static_cast<const AssignStmt&>(s);
      return std::string("(") + (x.declares_temp ? "let" : x.is_ref_assign ? "REF=" : x.set_reset == 'S' ? "S=" : x.set_reset == 'R' ? "R=" : ":=") + " " + opt(x.lhs) + " " + opt(x.rhs) + ")";
    }
    case StmtKind::Call: {
      const auto& x = static_cast<const CallStmt&>(s);
      return x.call ? dump(*x.call) : std::string("(call _)");
    }
    case StmtKind::If: {
      const auto& x = static_cast<const IfStmt&>(s);
      std::string out = "(if";
      for (size_t i = 0; i < x.arms.size(); ++i)
        out += std::string(i ? " elsif " : " ") + opt(x.arms[i].cond) + " " + dump(x.arms[i].body);
      if (x.else_body) out += " else " + dump(*x.else_body);
      return out + ")";
    }
    case StmtKind::Case: {
      const auto& x = static_cast<const CaseStmt&>(s);
      std::string out = "(case " + opt(x.selector);
      for (const auto& arm : x.arms) {
        out += " [";
        for (size_t i = 0; i < arm.labels.size(); ++i) {
          if (i) out += ", ";
          out += opt(arm.labels[i].lo);
          if (arm.labels[i].hi) out += ".." + opt(arm.labels[i].hi);
        }
        out += "] " + dump(arm.body);
      }
      if (x.else_body) out += " else " + dump(*x.else_body);
      return out + ")";
    }
    case StmtKind::For: {
      const auto& x = static_cast<const ForStmt&>(s);
      return "(for " + opt(x.var) + " " + opt(x.from) + " " + opt(x.to) + " " + opt(x.by) + " " + dump(x.body) + ")";
    }
    case StmtKind::While: {
      const auto& x = static_cast<const WhileStmt&>(s);
      return "(while " + opt(x.cond) + " " + dump(x.body) + ")";
    }
    case StmtKind::Repeat: {
      const auto& x = static_cast<const RepeatStmt&>(s);
      return "(repeat " + dump(x.body) + " " + opt(x.until) + ")";
    }
    case StmtKind::Exit: return "EXIT";
    case StmtKind::Continue: return "CONTINUE";
    case StmtKind::Return: return "RETURN";
    case StmtKind::Empty: return ";";
    case StmtKind::Mock: return "(mock " + opt(static_cast<const MockStmt&>(s).target) + ")";
    case StmtKind::MockFunction: {
      const auto& x = static_cast<const MockFunctionStmt&>(s);
      return "(mock_function " + x.function.text + " " + opt(x.value) + ")";
    }
    case StmtKind::Label: return "(label " + static_cast<const LabelStmt&>(s).name.text + ")";
    case StmtKind::Jump: return "(jmp " + static_cast<const JumpStmt&>(s).label.text + ")";
  }
  return "?";
}

std::string dump(const TypeSpec& t) {
  switch (t.kind) {
    case TypeSpecKind::Named:
      if (t.has_init_args) return "(FB_init " + t.name.text + dump_args(t.init_args) + ")";
      return t.name.text + (t.string_length ? "[" + dump(*t.string_length) + "]" : std::string());
    case TypeSpecKind::Array: {
      std::string s = "ARRAY[";
      for (size_t i = 0; i < t.dims.size(); ++i) {
        if (i) s += ", ";
        s += t.dims[i].open ? std::string("*") : opt(t.dims[i].lo) + ".." + opt(t.dims[i].hi);
      }
      return s + "] OF " + (t.element ? dump(*t.element) : "_");
    }
    case TypeSpecKind::Struct: {
      std::string s = t.is_union ? "UNION" : "STRUCT";
      for (const auto& m : t.members) {
        s += " ";
        for (size_t i = 0; i < m.names.size(); ++i) s += (i ? "," : "") + m.names[i].text;
        s += ":" + (m.type ? dump(*m.type) : std::string("_"));
        if (m.init) s += ":=" + dump(*m.init);
        s += ";";
      }
      return s + (t.is_union ? " END_UNION" : " END_STRUCT");
    }
    case TypeSpecKind::Enum: {
      std::string s = "(";
      for (size_t i = 0; i < t.enum_values.size(); ++i) {
        if (i) s += ", ";
        s += t.enum_values[i].name.text;
        if (t.enum_values[i].value) s += " := " + dump(*t.enum_values[i].value);
      }
      s += ")";
      if (t.element) s += " " + dump(*t.element);
      return s;
    }
    case TypeSpecKind::Subrange:
      return (t.element ? dump(*t.element) : std::string("_")) + " (" + opt(t.sub_lo) + ".." + opt(t.sub_hi) + ")";
    case TypeSpecKind::Ref:
      return std::string(t.is_reference ? "REFERENCE TO " : t.is_pointer ? "POINTER TO " : "REF_TO ") + (t.element ? dump(*t.element) : "_");
  }
  return "?";
}

}  // namespace plcfi::st
