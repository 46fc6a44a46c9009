// Compact S-expression rendering of AST nodes, for tests and `--dump-ast` style debugging.
#pragma once

#include <string>

#include "ast.hpp"

namespace plcfi::st {

// e.g. "(+ a (* 2 b))", "(call f (IN := x) (Q => y))", "(lit INT#5)".
std::string dump(const Expr& e);
// e.g. "(:= x 1)", "(if (> a 1) ((:= x 1)) else ((:= x 2)))".
std::string dump(const Stmt& s);
// e.g. "ARRAY[1..10] OF INT", "STRING[20]", "(A, B := 5) INT".
std::string dump(const TypeSpec& t);
std::string dump(const StmtList& list);

}  // namespace plcfi::st
