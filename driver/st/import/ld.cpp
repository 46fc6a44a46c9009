// Ladder Diagram (PLCopen XML <LD>) to ST; see ld.hpp.
#include "import/ld.hpp"
#include "import/xml_nodes.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <queue>
#include <set>

namespace plcfi::st {

namespace {

using xml::child;
using xml::is;
using xml::local_name;

std::string trimmed(std::string s) {
  const auto blank = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!s.empty() && blank(static_cast<unsigned char>(s.back()))) s.pop_back();
  size_t a = 0;
  while (a < s.size() && blank(static_cast<unsigned char>(s[a]))) ++a;
  return s.substr(a);
}

// A connection into an input: the element it comes from and, for a block, its output.
struct Conn {
  long ref = 0;
  std::string formal;
};

// One input of an element: a block's formal parameter (empty for a contact, coil, ...).
struct Input {
  std::string formal;
  bool negated = false;
  std::vector<Conn> from;
  std::string edge;  // a block input's edge attribute: rising, falling or none
};

struct Element {
  pugi::xml_node n;
  std::string kind;
  long id = 0;
  size_t order = 0;  // document order
  long exec_order = 0;  // executionOrderId (FBD), 0 when not given
  std::string instance;  // a block's instanceName, trimmed (empty: a function)
  std::string target;    // a coil's or output variable's variable, when a condition renames it
  std::vector<Input> inputs;
};

class Translator {
 public:
  Translator(const std::string& what, bool fbd, bool instances, LdTranslation* out, LdError* err,
             const LdCondition* cond = nullptr)
      : what_(what), fbd_(fbd), instances_(instances), out_(out), err_(err), cond_(cond) {
    if (cond_) tag_ = cond_->tag;
  }

  bool run(const pugi::xml_node& ld) {
    if (!collect(ld)) return false;
    if (cond_ && !condition()) return false;
    std::vector<const Element*> order;
    if (!sort(&order)) return false;
    for (const Element* e : order)
      if (!emit(*e)) return false;
    if (!temps_.empty() || !enos_.empty()) {
      out_->vars.push_back({"VAR_TEMP", ld});
      for (long id : temps_) out_->vars.push_back({"  " + nm("", id) + " : BOOL;", ld});
      for (long id : enos_) out_->vars.push_back({"  " + nm("eno", id) + " : BOOL;", ld});
      out_->vars.push_back({"END_VAR", ld});
    }
    if (!edges_.empty() || !edge_inputs_.empty()) {
      out_->vars.push_back({"VAR", ld});
      for (const auto& [id, type] : edges_) out_->vars.push_back({"  " + nm("e", id) + " : " + type + ";", ld});
      for (const auto& [name, type] : edge_inputs_) out_->vars.push_back({"  " + name + " : " + type + ";", ld});
      out_->vars.push_back({"END_VAR", ld});
    }
    return true;
  }

 private:
  bool fail(const pugi::xml_node& at, const std::string& message) {
    *err_ = LdError{"ST604", at, what_ + ": " + message};
    return false;
  }

  static std::vector<Conn> connections(const pugi::xml_node& point) {
    std::vector<Conn> out;
    for (auto c : point.children())
      if (is(c, "connection")) out.push_back(Conn{std::atol(c.attribute("refLocalId").value()), c.attribute("formalParameter").value()});
    return out;
  }

  bool collect(const pugi::xml_node& ld) {
    size_t order = 0;
    for (auto n : ld.children()) {
      if (n.type() != pugi::node_element) continue;
      const std::string kind(local_name(n));
      if (kind == "comment" || kind == "addData" || kind == "documentation") continue;
      static const std::set<std::string> kLd = {"leftPowerRail", "rightPowerRail", "contact", "coil", "block",
                                               "inVariable", "outVariable", "inOutVariable", "connector",
                                               "continuation", "jump", "label", "return"};
      static const std::set<std::string> kFbd = {"block", "inVariable", "outVariable", "inOutVariable", "connector",
                                                "continuation", "jump", "label", "return"};
      static const std::set<std::string> kSfc = {"step", "transition", "selectionDivergence", "selectionConvergence",
                                                "simultaneousDivergence", "simultaneousConvergence", "jumpStep",
                                                "actionBlock", "macroStep"};
      if (cond_ && cond_->root && kSfc.count(kind)) continue;  // the chart around a condition's network
      if (cond_ && cond_->root ? !kLd.count(kind) && !kFbd.count(kind) : !(fbd_ ? kFbd : kLd).count(kind))
        return fail(n, fbd_ ? "the FBD element <" + kind + "> is not supported (plcfi translates blocks, variables, "
                              "connectors, continuations, jumps, labels and returns)"
                            : "the LD element <" + kind + "> is not supported (plcfi translates power rails, contacts, "
                              "coils, blocks, variables, connectors, continuations, jumps, labels and returns)");
      Element e;
      e.n = n;
      e.kind = kind;
      e.order = order++;
      e.exec_order = std::strtol(n.attribute("executionOrderId").value(), nullptr, 10);
      const char* id = n.attribute("localId").value();
      char* end = nullptr;
      e.id = std::strtol(id, &end, 10);
      if (!*id || *end) return fail(n, "<" + kind + "> needs a numeric localId");
      if (kind == "block") {
        e.instance = trimmed(n.attribute("instanceName").value());
        for (auto v : child(n, "inputVariables").children())
          if (is(v, "variable"))
            e.inputs.push_back(Input{v.attribute("formalParameter").value(), v.attribute("negated").as_bool(),
                                     connections(child(v, "connectionPointIn")), v.attribute("edge").value()});
        for (auto v : child(n, "inOutVariables").children())
          if (is(v, "variable"))
            e.inputs.push_back(Input{v.attribute("formalParameter").value(), false, connections(child(v, "connectionPointIn")), ""});
      } else if (pugi::xml_node in = child(n, "connectionPointIn")) {
        e.inputs.push_back(Input{"", false, connections(in), ""});
      }
      if (kind == "connector") connectors_[trimmed(n.attribute("name").value())] = e.id;
      for (const auto& in : e.inputs)
        for (const auto& c : in.from) {
          read_.insert(c.ref);
          if (c.formal == "ENO") eno_read_.insert(c.ref);
        }
      if (!by_id_.emplace(e.id, elements_.size()).second) return fail(n, "localId " + std::to_string(e.id) + " is used twice");
      elements_.push_back(std::move(e));
    }
    // A function box with EN connected (or its ENO read) whose value other elements read is
    // held: evaluated once, in its place in the order, into a hidden temporary
    // (`_ldv<id> := F(EN := ..., ENO => _ldeno<id>)`: with EN FALSE it holds the result
    // type's initial value, as MATIEC computes it), which its readers read.
    // One output variable wired alone to such a box is assigned under EN instead (see
    // emit): with EN FALSE it keeps its value.
    std::map<long, int> readers, direct;
    for (const Element& e : elements_)
      for (const auto& in : e.inputs)
        for (const auto& c : in.from) {
          ++readers[c.ref];
          if ((e.kind == "outVariable" || e.kind == "inOutVariable") && in.from.size() == 1 && !in.negated &&
              !e.n.attribute("negated").as_bool())
            ++direct[c.ref];
        }
    for (const Element& e : elements_) {
      if (e.kind != "block" || !e.instance.empty() || !read_.count(e.id)) continue;
      bool enabled = false;
      for (const auto& in : e.inputs)
        if (in.formal == "EN" && !in.from.empty()) enabled = true;
      if (eno_read_.count(e.id) || (enabled && (readers[e.id] > 1 || direct[e.id] == 0))) held_.insert(e.id);
    }
    return true;
  }

  // The elements an element's value depends on.
  std::vector<long> depends(const Element& e) const {
    std::vector<long> out;
    for (const auto& in : e.inputs)
      for (const auto& c : in.from) out.push_back(c.ref);
    if (e.kind == "continuation") {
      auto it = connectors_.find(trimmed(e.n.attribute("name").value()));
      if (it != connectors_.end()) out.push_back(it->second);
    }
    return out;
  }

  // Whether element i only gives a value (written where it is used) rather than doing
  // something in the evaluation order.
  bool is_statement(const Element& e) const {
    if (e.kind == "block") return !e.instance.empty() || held_.count(e.id);
    return e.kind == "outVariable" || e.kind == "inOutVariable" || e.kind == "contact" || e.kind == "coil" ||
           e.kind == "jump" || e.kind == "return" || e.kind == "label";
  }

  // A connection that may close a loop: it reads a variable (an in-out variable) or a
  // function block instance's output, so it gives the value of the previous evaluation
  // (the standard's feedback path) and need not come first.
  bool is_feedback_source(const Element& e) const {
    return e.kind == "inOutVariable" || (e.kind == "block" && !e.instance.empty());
  }

  // The evaluation order. FBD with an executionOrderId on every element that does something
  // (a function block call, an output or in-out variable): that order; an input wired from
  // a block evaluated later reads that block's output of the previous evaluation. Otherwise
  // data flow: an element after the ones it reads, document order among the ready ones
  // (Kahn). A loop through an in-out variable or a function block's output is a feedback
  // path (that connection reads the previous value and does not order); any other loop is
  // an error.
  //
  // Labels divide the body into networks, in document order (by executionOrderId when
  // every element that acts has one): each network is ordered on its own and follows the
  // label that starts it, so a jump to the label runs the networks from there on.
  bool sort(std::vector<const Element*>* out) {
    const size_t n = elements_.size();
    std::vector<std::vector<size_t>> deps(n);
    for (size_t i = 0; i < n; ++i)
      for (long ref : depends(elements_[i])) {
        auto it = by_id_.find(ref);
        if (it == by_id_.end())
          return fail(elements_[i].n, "<" + elements_[i].kind + " localId=\"" + std::to_string(elements_[i].id) +
                                          "\"> is connected to localId " + std::to_string(ref) + ", which is not in the network");
        deps[i].push_back(it->second);
      }
    if (fbd_) {
      bool all = true, any = false;
      for (const Element& e : elements_) {
        if (!is_statement(e)) continue;
        if (e.exec_order > 0) any = true;
        else all = false;
      }
      if (any && all) {
        for (const Element& e : elements_) out->push_back(&e);
        std::stable_sort(out->begin(), out->end(), [&](const Element* a, const Element* b) {
          const long ka = is_statement(*a) ? a->exec_order : 0, kb = is_statement(*b) ? b->exec_order : 0;
          return ka < kb;
        });
        return true;
      }
    }
    std::vector<size_t> members;
    for (size_t i = 0; i < n; ++i) {
      if (elements_[i].kind != "label") {
        members.push_back(i);
        continue;
      }
      if (!sort_network(members, deps, out)) return false;
      members.clear();
      out->push_back(&elements_[i]);
    }
    return sort_network(members, deps, out);
  }

  // One network (the elements `members`, indices into elements_): data flow within it; a
  // connection from another network reads what that one left.
  bool sort_network(const std::vector<size_t>& members, const std::vector<std::vector<size_t>>& all_deps,
                    std::vector<const Element*>* out) {
    const size_t n = elements_.size();
    std::vector<bool> in(n, false);
    for (size_t i : members) in[i] = true;
    std::vector<std::vector<size_t>> deps(n);
    for (size_t i : members)
      for (size_t d : all_deps[i])
        if (in[d]) deps[i].push_back(d);
    const size_t target = out->size() + members.size();
    std::vector<size_t> missing(n, 0);
    std::vector<std::vector<size_t>> users(n);
    for (size_t i : members)
      for (size_t d : deps[i]) {
        ++missing[i];
        users[d].push_back(i);
      }
    std::vector<bool> done(n, false);
    std::priority_queue<size_t, std::vector<size_t>, std::greater<>> ready;
    for (size_t i : members)
      if (!missing[i]) ready.push(i);
    for (;;) {
      while (!ready.empty()) {
        size_t i = ready.top();
        ready.pop();
        done[i] = true;
        out->push_back(&elements_[i]);
        for (size_t u : users[i])
          if (!done[u] && missing[u] > 0 && --missing[u] == 0) ready.push(u);
      }
      if (out->size() == target) return true;
      // Stuck on a loop: cut one feedback connection (the first in document order).
      bool cut = false;
      for (size_t i : members) {
        if (cut) break;
        if (done[i]) continue;
        for (size_t d : deps[i]) {
          if (done[d] || !is_feedback_source(elements_[d])) continue;
          auto& us = users[d];
          us.erase(std::find(us.begin(), us.end(), i));
          if (--missing[i] == 0) ready.push(i);
          cut = true;
          break;
        }
      }
      if (!cut) {
        for (size_t i : members)
          if (!done[i])
            return fail(elements_[i].n, "the network has a loop through this <" + elements_[i].kind + "> (localId " +
                                            std::to_string(elements_[i].id) +
                                            ") that passes no in-out variable or function block output (a feedback "
                                            "path needs one to hold the previous value)");
      }
    }
  }

  // The value an element gives at its output `formal` (a block's pin; empty otherwise).
  bool value(long id, const std::string& formal, const pugi::xml_node& user, std::string* v) {
    const Element& e = elements_[by_id_.at(id)];
    if (e.kind == "leftPowerRail") *v = "TRUE";
    else if (e.kind == "contact" || e.kind == "coil") *v = nm("", id);
    else if (e.kind == "inVariable" || e.kind == "inOutVariable")
      *v = std::string(e.n.attribute("negated").as_bool() ? "NOT " : "") + "(" + expression(e) + ")";
    else if (e.kind == "continuation") {
      auto named = connectors_.find(trimmed(e.n.attribute("name").value()));
      if (named == connectors_.end())
        return fail(e.n, "<continuation name=\"" + trimmed(e.n.attribute("name").value()) + "\"> has no <connector> of that name");
      if (++depth_ > kMaxDepth) return fail(e.n, "connectors and continuations chained too deep");
      const Element& c = elements_[by_id_.at(named->second)];
      const bool ok = input(c, c.inputs.empty() ? Input{} : c.inputs.front(), v);
      --depth_;
      return ok;
    } else if (e.kind == "block") {
      return block_value(e, formal, user, v);
    } else {
      return fail(user, "is connected to a <" + e.kind + ">, which gives no value");
    }
    return true;
  }

  static const std::string& inst_of(const Element& e) { return e.instance; }
  static std::string type_of(const Element& e) { return trimmed(e.n.attribute("typeName").value()); }

  // Whether output `formal` of block e is drawn negated.
  static bool output_negated(const Element& e, const std::string& formal) {
    for (auto v : child(e.n, "outputVariables").children())
      if (is(v, "variable") && formal == v.attribute("formalParameter").value()) return v.attribute("negated").as_bool();
    return false;
  }

  // A block's EN input, if it is connected to something other than the left rail.
  bool enable(const Element& e, std::string* en) {
    for (const auto& in : e.inputs)
      if (in.formal == "EN" && !in.from.empty()) {
        if (!input(e, in, en)) return false;
        if (*en == "TRUE") en->clear();
        return true;
      }
    en->clear();
    return true;
  }

  // The arguments of a block's call (EN apart), `formal := value` for an instance (or
  // when `named`), in the order of its inputs.
  bool arguments(const Element& e, bool named, std::string* args) {
    args->clear();
    size_t k = 0;
    for (const auto& in : e.inputs) {
      ++k;
      if (in.formal == "EN" || in.from.empty()) continue;
      std::string v;
      if (!input(e, in, &v)) return false;
      if (!in.edge.empty() && in.edge != "none") {
        if (!instances_) return fail(e.n, "an edge on input '" + in.formal + "' needs an R_TRIG/F_TRIG instance, which a FUNCTION cannot hold");
        const std::string trig = nm("e", e.id) + "_" + std::to_string(k);
        edge_inputs_.emplace_back(trig, in.edge == "falling" ? "F_TRIG" : "R_TRIG");
        pending_.push_back(trig + "(CLK := " + v + ");");
        v = trig + ".Q";
      }
      if (!args->empty()) *args += ", ";
      *args += named ? in.formal + " := " + v : v;
    }
    return true;
  }

  // The value at output `formal` of block e: a function's call, written where it is used,
  // or a function block instance's output (before the instance's call in this evaluation:
  // the previous value, a feedback path).
  bool block_value(const Element& e, const std::string& formal, const pugi::xml_node& user, std::string* v) {
    const std::string inst = inst_of(e);
    if (!inst.empty()) {
      if (formal == "ENO") {
        enos_.insert(e.id);
        *v = nm("eno", e.id);
      } else {
        *v = (output_negated(e, formal) ? "NOT " : "") + inst + "." + (formal.empty() ? "Q" : formal);
      }
      return true;
    }
    if (held_.count(e.id)) {
      if (formal == "ENO") {
        *v = nm("eno", e.id);
      } else {
        *v = (output_negated(e, formal) ? "NOT " : "") + nm("v", e.id);
      }
      return true;
    }
    static_cast<void>(user);
    if (++depth_ > kMaxDepth) return fail(e.n, "function boxes nest too deep");
    std::string args;
    const bool ok = arguments(e, false, &args);
    --depth_;
    if (!ok) return false;
    *v = (output_negated(e, formal) ? "NOT " : "") + type_of(e) + "(" + args + ")";
    return true;
  }

  // An input's value: its connections ORed (a parallel branch), FALSE when unconnected.
  bool input(const Element& e, const Input& in, std::string* v) {
    std::vector<std::string> parts;
    for (const auto& c : in.from) {
      std::string p;
      if (!value(c.ref, c.formal, e.n, &p)) return false;
      parts.push_back(std::move(p));
    }
    if (parts.empty()) *v = "FALSE";
    else if (parts.size() == 1) *v = parts[0];
    else {
      *v = "(" + parts[0];
      for (size_t k = 1; k < parts.size(); ++k) *v += " OR " + parts[k];
      *v += ")";
    }
    if (in.negated) *v = "NOT " + *v;
    // Function boxes are written where their value is used: a value used twice at every
    // level doubles at every level.
    if (v->size() > kMaxText) return fail(e.n, "the expression this input stands for is too large (function boxes nest too deep)");
    return true;
  }

  static bool is_name(const std::string& s) {
    if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
    for (char c : s)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
    return true;
  }

  static std::string expression(const Element& e) { return trimmed(child(e.n, "expression").text().get()); }

  bool variable(const Element& e, std::string* v) {
    *v = trimmed(child(e.n, "variable").text().get());
    if (!e.target.empty()) *v = e.target;
    if (v->empty()) return fail(e.n, "<" + e.kind + "> names no <variable>");
    return true;
  }

  std::string edge(const Element& e, const char* attr) {
    const std::string kind = e.n.attribute(attr).value();
    return kind == "rising" ? "R_TRIG" : kind == "falling" ? "F_TRIG" : "";
  }

  void line(const std::string& text, const Element& e) { out_->body.push_back({text, e.n}); }

  bool emit(const Element& e) {
    if (e.kind == "contact" || e.kind == "coil") {
      const std::string t = nm("", e.id), te = nm("e", e.id);
      std::string in, var;
      if (!input(e, e.inputs.empty() ? Input{} : e.inputs.front(), &in) || !variable(e, &var)) return false;
      const bool negated = e.n.attribute("negated").as_bool();
      const std::string trig = edge(e, "edge");
      if (!trig.empty()) {
        if (!instances_) return fail(e.n, "an edge-sensing " + e.kind + " needs an " + trig + " instance, which a FUNCTION cannot hold");
        edges_[e.id] = trig;
      }
      temps_.push_back(e.id);
      if (e.kind == "contact") {
        if (!trig.empty()) {
          line(te + "(CLK := " + var + ");", e);
          line(t + " := " + in + " AND " + te + ".Q;", e);
        } else {
          line(t + " := " + in + (negated ? " AND NOT " : " AND ") + var + ";", e);
        }
        return true;
      }
      line(t + " := " + in + ";", e);
      const std::string storage = e.n.attribute("storage").value();
      if (!trig.empty()) {
        line(te + "(CLK := " + t + ");", e);
        line(var + " := " + te + ".Q;", e);
      } else if (storage == "set") {
        line("IF " + t + " THEN " + var + " := TRUE; END_IF;", e);
      } else if (storage == "reset") {
        line("IF " + t + " THEN " + var + " := FALSE; END_IF;", e);
      } else {
        line(var + " := " + (negated ? "NOT " : "") + t + ";", e);
      }
      return true;
    }
    if (e.kind == "outVariable" || e.kind == "inOutVariable") {
      const std::string target = e.target.empty() ? expression(e) : e.target;
      if (target.empty()) return fail(e.n, "<" + e.kind + "> has no <expression>");
      if (e.inputs.empty() || e.inputs.front().from.empty()) return true;
      const bool negated = e.n.attribute("negated").as_bool();
      if (const Element* f = enabled_function(e.inputs.front())) {
        // target := F(EN := en, ..., ENO => _ldenoN): with EN FALSE the target keeps its value.
        std::string en, args;
        if (!enable(*f, &en) || !arguments(*f, true, &args)) return false;
        flush_pending(e);
        enos_.insert(f->id);
        line(target + " := " + type_of(*f) + "(EN := " + en + (args.empty() ? "" : ", " + args) + ", ENO => " + nm("eno", f->id) + ");",
             e);
        return true;
      }
      std::string in;
      if (!input(e, e.inputs.front(), &in)) return false;
      flush_pending(e);
      line(target + " := " + (negated ? "NOT (" + in + ")" : in) + ";", e);
      return true;
    }
    if (e.kind == "block") return block(e);
    if (e.kind == "label" || e.kind == "jump") {
      const std::string label = trimmed(e.n.attribute("label").value());
      if (!is_name(label)) return fail(e.n, "<" + e.kind + "> needs a label that is a name, not '" + label + "'");
      if (e.kind == "label") {
        line(label + ":", e);
        return true;
      }
    }
    if (e.kind == "jump" || e.kind == "return") {
      // Taken when the power flow (LD) or the BOOL connected to it (FBD) is TRUE.
      std::string cond = "TRUE";
      if (!e.inputs.empty() && !e.inputs.front().from.empty() && !input(e, e.inputs.front(), &cond)) return false;
      const std::string action =
          e.kind == "jump" ? "JMP " + trimmed(e.n.attribute("label").value()) + ";" : std::string("RETURN;");
      flush_pending(e);
      line(cond == "TRUE" ? action : "IF " + cond + " THEN " + action + " END_IF;", e);
      return true;
    }
    return true;  // power rails, in-variables, connectors, continuations: values only
  }

  // The function with EN connected whose value `in` takes directly, if any.
  const Element* enabled_function(const Input& in) {
    if (in.from.size() != 1 || in.negated) return nullptr;
    auto it = by_id_.find(in.from.front().ref);
    if (it == by_id_.end()) return nullptr;
    const Element& f = elements_[it->second];
    if (f.kind != "block" || !inst_of(f).empty() || held_.count(f.id)) return nullptr;
    for (const auto& x : f.inputs)
      if (x.formal == "EN" && !x.from.empty()) return &f;
    return nullptr;
  }

  // Edge detectors of block inputs, called before the statement that reads them.
  void flush_pending(const Element& e) {
    for (const auto& p : pending_) line(p, e);
    pending_.clear();
  }

  // A function block call is a statement (with EN/ENO as ST writes them); a function is a
  // value, written where it is used (block_value).
  bool block(const Element& e) {
    if (type_of(e).empty()) return fail(e.n, "<block> has no typeName");
    const std::string inst = inst_of(e);
    if (held_.count(e.id)) {
      std::string en, args;
      if (!enable(e, &en) || !arguments(e, true, &args)) return false;
      flush_pending(e);
      enos_.insert(e.id);
      line(nm("v", e.id) + " := " + type_of(e) + "(EN := " + (en.empty() ? "TRUE" : en) +
               (args.empty() ? "" : ", " + args) + ", ENO => " + nm("eno", e.id) + ");",
           e);
      return true;
    }
    if (inst.empty() && read_.count(e.id)) return true;  // a value, written where it is read
    std::string en, args;
    if (!enable(e, &en) || !arguments(e, true, &args)) return false;
    flush_pending(e);
    if (!inst.empty()) out_->instances.push_back(inst);
    if (inst.empty()) {  // a function nobody reads still runs (its in-out parameters, its effects)
      line(type_of(e) + "(" + (en.empty() ? args : "EN := " + en + (args.empty() ? "" : ", " + args)) + ");", e);
      return true;
    }
    if (en.empty()) {
      line(inst + "(" + args + ");", e);
      if (enos_.count(e.id)) line(nm("eno", e.id) + " := TRUE;", e);
    } else {
      enos_.insert(e.id);
      line(inst + "(EN := " + en + (args.empty() ? "" : ", " + args) + ", ENO => " + nm("eno", e.id) + ");", e);
    }
    return true;
  }

  // The hidden name of kind `kind` ("" a contact's or coil's power flow, "e" an edge
  // detector, "eno" an ENO, "v" a held function value) of element `id`.
  std::string nm(const char* kind, long id) const { return std::string("_ld") + kind + tag_ + std::to_string(id); }

  // A transition condition (cond_): with a root, only the elements the root's value
  // depends on, and an output variable assigning that value to the target; without one,
  // the whole network, whose coils and output variables of the transition's name set the
  // target instead.
  bool condition() {
    if (!cond_->root) {
      bool any = false;
      for (Element& e : elements_) {
        if (e.kind != "coil" && e.kind != "outVariable") continue;
        std::string v = trimmed(child(e.n, e.kind == "coil" ? "variable" : "expression").text().get());
        if (!iequal(v, cond_->name)) continue;
        e.target = cond_->target;
        any = true;
      }
      if (!any) return fail(cond_->at, "the network of transition '" + cond_->name + "' has no coil or output variable named '" +
                                           cond_->name + "' to give the condition");
      return true;
    }
    auto root = by_id_.find(cond_->root);
    if (root == by_id_.end())
      return fail(cond_->at, "the condition is connected to localId " + std::to_string(cond_->root) + ", which is not in the chart");
    std::set<long> cone;
    std::vector<long> todo{cond_->root};
    while (!todo.empty()) {
      const long id = todo.back();
      todo.pop_back();
      auto it = by_id_.find(id);
      if (it == by_id_.end() || !cone.insert(id).second) continue;
      for (long d : depends(elements_[it->second])) todo.push_back(d);
    }
    std::vector<Element> kept;
    for (Element& e : elements_)
      if (cone.count(e.id)) kept.push_back(std::move(e));
    elements_ = std::move(kept);
    Element out;
    out.n = cond_->at;
    out.kind = "outVariable";
    out.order = elements_.size();
    out.target = cond_->target;
    for (const Element& e : elements_) out.id = std::max(out.id, e.id + 1);
    out.inputs.push_back(Input{"", false, {Conn{cond_->root, cond_->formal}}, ""});
    elements_.push_back(std::move(out));
    by_id_.clear();
    for (size_t i = 0; i < elements_.size(); ++i) by_id_[elements_[i].id] = i;
    read_.insert(cond_->root);
    return true;
  }

  static bool iequal(const std::string& a, const std::string& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
             return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
  }

  static constexpr int kMaxDepth = 256;
  static constexpr size_t kMaxText = 64 * 1024;
  int depth_ = 0;
  std::string what_;
  bool fbd_;
  bool instances_;
  LdTranslation* out_;
  LdError* err_;
  const LdCondition* cond_;
  std::string tag_;  // inserted into hidden names (nm), unique per condition of a chart
  std::vector<Element> elements_;
  std::map<long, size_t> by_id_;
  std::map<std::string, long> connectors_;
  std::vector<long> temps_;
  std::set<long> read_;                                        // elements some input is connected to
  std::set<long> enos_;                                        // blocks whose ENO is read
  std::set<long> eno_read_;                                    // blocks an input reads the ENO of
  std::set<long> held_;                                        // function boxes held in _ldv<id> (see collect)
  std::vector<std::pair<std::string, std::string>> edge_inputs_;  // edge-sensing inputs: name, type
  std::vector<std::string> pending_;                           // their calls, before the next statement
  std::map<long, std::string> edges_;
};

}  // namespace

bool ld_to_st(const pugi::xml_node& ld, const std::string& what, bool instances, LdTranslation* out, LdError* err) {
  Translator t(what, is(ld, "FBD"), instances, out, err);
  return t.run(ld);
}

bool ld_condition_to_st(const pugi::xml_node& network, const std::string& what, bool instances, const LdCondition& cond,
                        LdTranslation* out, LdError* err) {
  Translator t(what, is(network, "FBD"), instances, out, err, &cond);
  return t.run(network);
}

}  // namespace plcfi::st
