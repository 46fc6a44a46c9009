// Small helpers over the syntax tree shared by the compiler's messages and the tree dump.
#include "ast.hpp"

namespace plcfi::st {

const char* op_text(BinaryOp op) {
  switch (op) {
    case BinaryOp::Pow: return "**";
    case BinaryOp::Mul: return "*";
    case BinaryOp::Div: return "/";
    case BinaryOp::Mod: return "MOD";
    case BinaryOp::Add: return "+";
    case BinaryOp::Sub: return "-";
    case BinaryOp::Lt: return "<";
    case BinaryOp::Gt: return ">";
    case BinaryOp::Le: return "<=";
    case BinaryOp::Ge: return ">=";
    case BinaryOp::Eq: return "=";
    case BinaryOp::Ne: return "<>";
    case BinaryOp::And: return "AND";
    case BinaryOp::Xor: return "XOR";
    case BinaryOp::Or: return "OR";
    case BinaryOp::AndThen: return "AND_THEN";
    case BinaryOp::OrElse: return "OR_ELSE";
  }
  return "?";
}

}  // namespace plcfi::st
