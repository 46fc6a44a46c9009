// A slow, plain reference evaluator of ST: walks the parsed AST (no sema, no bytecode) and
// executes the programs the oracle's generator writes, so that the engine's compiler can be
// checked against code that shares nothing with it but the parser.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "syntax/ast.hpp"

namespace plcfi::oracle {

// A construct the evaluator does not implement: the program is outside its subset.
struct Unsupported : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A runtime error in the evaluated program (index out of range, division by zero, ...).
struct RefTrap : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Date: DATE, TOD and DT (by name), held in nanoseconds like TIME.
enum class VK { Bool, Int, Real, LReal, Time, Date, String, Struct, Array, Fb, Itf, Ref };

struct RType {
  VK kind = VK::Int;
  std::string name;          // IEC spelling (DINT, STRING[10]) or the user type's name
  int bits = 0;              // Int: 8, 16, 32, 64
  bool is_signed = false;    // Int
  size_t max_len = 0;        // String
  const RType* elem = nullptr;  // Array element, Ref target
  int64_t lo = 0, hi = 0;       // Array bounds
  std::vector<std::pair<std::string, const RType*>> fields;  // Struct
  const st::Pou* pou = nullptr;                              // Fb
};

struct Instance;

// A value tagged by its type. Integers are held sign- or zero-extended to 64 bits after
// wrapping to their width; REAL values are held as the double of a float.
struct Value {
  const RType* t = nullptr;
  int64_t i = 0;
  double r = 0;
  std::string s;
  std::vector<Value> elems;        // array elements, struct fields in declaration order
  std::shared_ptr<Instance> fb;    // Fb: the instance (owned where declared)
  Instance* ref = nullptr;         // Itf: the instance referred to, null when unassigned
  Value* ptr = nullptr;            // Ref: the variable referred to (storage never moves), or null
  // --dialect codesys: an integer result held in a 32-bit register (t is DINT or UDINT),
  // whose IEC type is this; a store cuts it to the target's width.
  const RType* nominal = nullptr;
};

// Variables of one POU instance (or one call frame): by canonical name, with the
// declaration order and spelling kept for paths.
struct Vars {
  std::map<std::string, Value> by_name;
  std::map<std::string, Value*> aliases;  // VAR_IN_OUT parameters: the caller's variable
  std::vector<std::string> order;
  Value& add(const std::string& name, Value v);
  Value* find(const std::string& canon_name);
};

struct Instance {
  const st::Pou* pou = nullptr;
  Vars vars;
};

struct Leaf {
  std::string path;  // as the engine resolves it: Main.fb.x, Main.a[3], Main.r.f
  Value v;
};

class Reference {
 public:
  // Takes the parsed units (kept alive by the caller). Throws Unsupported for what the
  // evaluator does not implement.
  explicit Reference(const std::vector<const st::CompilationUnit*>& units);
  ~Reference();
  // One scan: every PROGRAM once, in source order. Throws RefTrap or Unsupported.
  void scan();
  // Every elementary variable reachable from the programs and globals, in a stable order;
  // FOR control variables are left out (their value after the loop is the implementation's).
  std::vector<Leaf> leaves() const;
  static std::string text(const Value& v);  // for messages
  // Self-check of the oracle: integer additions yield one more than they should, so that
  // every comparison that reaches such a value must fail.
  void set_wrong_addition(bool on) { wrong_addition_ = on; }
  // CODESYS/TwinCAT conversions of TIME_OF_DAY (milliseconds) instead of MATIEC's seconds.
  void set_codesys(bool on) { codesys_ = on; }

 private:
  struct Env;
  enum class Flow { Normal, Exit, Continue, Return };

  const RType* elementary(const std::string& canon_name) const;
  const RType* type_of(const st::TypeSpec& spec);
  const RType* ref_to(const RType* target);
  Value make(const RType* t);
  void declare(Vars& vars, const std::vector<st::VarBlock>& blocks, Env* env);
  std::shared_ptr<Instance> instantiate(const st::Pou* pou);

  Flow exec(const st::StmtList& list, Env& env);
  Flow exec(const st::Stmt& s, Env& env);
  Value eval(const st::Expr& e, Env& env);
  Value* lvalue(const st::Expr& e, Env& env);
  Instance* as_instance(const st::Expr& e, Env& env);
  void assign(Value& dst, const Value& src);
  void store(const st::Expr& place, const Value& v, Env& env);  // assignment to a place or a bit
  Value binary(st::BinaryOp op, const Value& a, const Value& b);
  Value unary(st::UnaryOp op, const Value& a);
  Value call(const st::CallExpr& c, Env& env);
  Value standard(const std::string& name, const st::CallExpr& c, Env& env, bool* found);
  Value convert(const Value& v, const RType* to);
  Value run_pou(const st::Pou& pou, Instance* self, const st::Pou* owner, const st::CallExpr* c, Env& caller,
                const std::string& result_name, const st::TypeSpec* result_type, const Value* setter_value);
  const st::Pou* base_of(const st::Pou* fb) const;
  const st::Pou* find_method(const st::Pou* fb, const std::string& canon_name, const st::Pou** owner) const;
  const st::PropertyDecl* find_property(const st::Pou* fb, const std::string& canon_name, const st::Pou** owner) const;
  Value no_value() const;
  void collect(const std::string& path, const Value& v, std::vector<Leaf>& out) const;

  std::vector<std::unique_ptr<RType>> owned_;
  std::map<std::string, const RType*> named_;      // elementary and user types by canon name
  std::map<std::string, const st::Pou*> pous_;     // FUNCTION, FUNCTION_BLOCK, INTERFACE
  std::map<std::string, const st::TypeDecl*> type_decls_;
  std::vector<std::pair<std::string, std::shared_ptr<Instance>>> programs_;
  Vars globals_;
  std::map<const RType*, const RType*> ref_types_;  // REF_TO T by T
  std::map<std::string, bool> for_vars_;  // canon names used as FOR control variables
  const RType* string255_ = nullptr;
  uint64_t steps_ = 0;
  bool wrong_addition_ = false;
  bool codesys_ = false;
  int64_t count_unit(const RType* t) const;
};

}  // namespace plcfi::oracle
