// Ladder Diagram (PLCopen XML <LD>) to ST; see ld.hpp.
#include "import/ld.hpp"
#include "import/xml_nodes.hpp"

#include <algorithm>
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
};

struct Element {
  pugi::xml_node n;
  std::string kind;
  long id = 0;
  size_t order = 0;  // document order
  std::vector<Input> inputs;
};

class Translator {
 public:
  Translator(const std::string& what, bool instances, LdTranslation* out, LdError* err)
      : what_(what), instances_(instances), out_(out), err_(err) {}

  bool run(const pugi::xml_node& ld) {
    if (!collect(ld)) return false;
    std::vector<const Element*> order;
    if (!sort(&order)) return false;
    for (const Element* e : order)
      if (!emit(*e)) return false;
    if (!temps_.empty()) {
      out_->vars.push_back({"VAR_TEMP", ld});
      for (long id : temps_) out_->vars.push_back({"  _ld" + std::to_string(id) + " : BOOL;", ld});
      out_->vars.push_back({"END_VAR", ld});
    }
    if (!edges_.empty()) {
      out_->vars.push_back({"VAR", ld});
      for (const auto& [id, type] : edges_) out_->vars.push_back({"  _lde" + std::to_string(id) + " : " + type + ";", ld});
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
      static const std::set<std::string> kKnown = {"leftPowerRail", "rightPowerRail", "contact", "coil", "block",
                                                  "inVariable", "outVariable", "inOutVariable", "connector",
                                                  "continuation"};
      if (!kKnown.count(kind))
        return fail(n, "the LD element <" + kind + "> is not supported (plcfi translates power rails, contacts, coils, "
                       "blocks, variables, connectors and continuations)");
      Element e;
      e.n = n;
      e.kind = kind;
      e.order = order++;
      const char* id = n.attribute("localId").value();
      char* end = nullptr;
      e.id = std::strtol(id, &end, 10);
      if (!*id || *end) return fail(n, "<" + kind + "> needs a numeric localId");
      if (kind == "block") {
        for (auto v : child(n, "inputVariables").children())
          if (is(v, "variable"))
            e.inputs.push_back(Input{v.attribute("formalParameter").value(), v.attribute("negated").as_bool(),
                                     connections(child(v, "connectionPointIn"))});
        for (auto v : child(n, "inOutVariables").children())
          if (is(v, "variable"))
            e.inputs.push_back(Input{v.attribute("formalParameter").value(), false, connections(child(v, "connectionPointIn"))});
      } else if (pugi::xml_node in = child(n, "connectionPointIn")) {
        e.inputs.push_back(Input{"", false, connections(in)});
      }
      if (kind == "connector") connectors_[trimmed(n.attribute("name").value())] = e.id;
      if (!by_id_.emplace(e.id, elements_.size()).second) return fail(n, "localId " + std::to_string(e.id) + " is used twice");
      elements_.push_back(std::move(e));
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

  // Connections first, document order among the ready ones (Kahn).
  bool sort(std::vector<const Element*>* out) {
    std::vector<size_t> missing(elements_.size(), 0);
    std::vector<std::vector<size_t>> users(elements_.size());
    for (size_t i = 0; i < elements_.size(); ++i)
      for (long ref : depends(elements_[i])) {
        auto it = by_id_.find(ref);
        if (it == by_id_.end())
          return fail(elements_[i].n, "<" + elements_[i].kind + " localId=\"" + std::to_string(elements_[i].id) +
                                          "\"> is connected to localId " + std::to_string(ref) + ", which is not in the network");
        ++missing[i];
        users[it->second].push_back(i);
      }
    std::priority_queue<size_t, std::vector<size_t>, std::greater<>> ready;
    for (size_t i = 0; i < elements_.size(); ++i)
      if (!missing[i]) ready.push(i);
    while (!ready.empty()) {
      size_t i = ready.top();
      ready.pop();
      out->push_back(&elements_[i]);
      for (size_t u : users[i])
        if (--missing[u] == 0) ready.push(u);
    }
    if (out->size() < elements_.size()) {
      for (size_t i = 0; i < elements_.size(); ++i)
        if (missing[i]) return fail(elements_[i].n, "the network has a loop through this <" + elements_[i].kind + "> (localId " +
                                                       std::to_string(elements_[i].id) + ")");
    }
    return true;
  }

  // The value an element gives at its output `formal` (a block's pin; empty otherwise).
  bool value(long id, const std::string& formal, const pugi::xml_node& user, std::string* v) {
    const Element& e = elements_[by_id_.at(id)];
    if (e.kind == "leftPowerRail") *v = "TRUE";
    else if (e.kind == "contact" || e.kind == "coil") *v = "_ld" + std::to_string(id);
    else if (e.kind == "inVariable" || e.kind == "inOutVariable") *v = "(" + expression(e) + ")";
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
      auto it = block_out_.find(id);
      if (it == block_out_.end()) return fail(user, "is connected to a block that gives no value");
      auto pin = it->second.find(formal);
      if (pin == it->second.end()) pin = it->second.find("");
      if (pin == it->second.end()) return fail(user, "is connected to output '" + formal + "' of a block that has no such output");
      *v = pin->second;
    } else {
      return fail(user, "is connected to a <" + e.kind + ">, which gives no value");
    }
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

  static std::string expression(const Element& e) { return trimmed(child(e.n, "expression").text().get()); }

  bool variable(const Element& e, std::string* v) {
    *v = trimmed(child(e.n, "variable").text().get());
    if (v->empty()) return fail(e.n, "<" + e.kind + "> names no <variable>");
    return true;
  }

  std::string edge(const Element& e, const char* attr) {
    const std::string kind = e.n.attribute(attr).value();
    return kind == "rising" ? "R_TRIG" : kind == "falling" ? "F_TRIG" : "";
  }

  void line(const std::string& text, const Element& e) { out_->body.push_back({text, e.n}); }

  bool emit(const Element& e) {
    const std::string id = std::to_string(e.id);
    if (e.kind == "contact" || e.kind == "coil") {
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
          line("_lde" + id + "(CLK := " + var + ");", e);
          line("_ld" + id + " := " + in + " AND _lde" + id + ".Q;", e);
        } else {
          line("_ld" + id + " := " + in + (negated ? " AND NOT " : " AND ") + var + ";", e);
        }
        return true;
      }
      line("_ld" + id + " := " + in + ";", e);
      const std::string storage = e.n.attribute("storage").value();
      if (!trig.empty()) {
        line("_lde" + id + "(CLK := _ld" + id + ");", e);
        line(var + " := _lde" + id + ".Q;", e);
      } else if (storage == "set") {
        line("IF _ld" + id + " THEN " + var + " := TRUE; END_IF;", e);
      } else if (storage == "reset") {
        line("IF _ld" + id + " THEN " + var + " := FALSE; END_IF;", e);
      } else {
        line(var + " := " + (negated ? "NOT _ld" : "_ld") + id + ";", e);
      }
      return true;
    }
    if (e.kind == "outVariable" || e.kind == "inOutVariable") {
      const std::string target = expression(e);
      if (target.empty()) return fail(e.n, "<" + e.kind + "> has no <expression>");
      if (e.inputs.empty() || e.inputs.front().from.empty()) return true;
      std::string in;
      if (!input(e, e.inputs.front(), &in)) return false;
      line(target + " := " + in + ";", e);
      return true;
    }
    if (e.kind == "block") return block(e);
    return true;  // power rails, in-variables, connectors, continuations: values only
  }

  bool block(const Element& e) {
    const std::string type = trimmed(e.n.attribute("typeName").value());
    const std::string inst = trimmed(e.n.attribute("instanceName").value());
    if (type.empty()) return fail(e.n, "<block> has no typeName");
    std::string en, args;
    bool has_en = false;
    for (const auto& in : e.inputs) {
      std::string v;
      if (!input(e, in, &v)) return false;
      if (in.formal == "EN") {
        has_en = v != "TRUE";  // EN on the left rail: always enabled
        en = v;
        continue;
      }
      if (in.from.empty()) continue;
      if (!args.empty()) args += ", ";
      args += inst.empty() ? v : in.formal + " := " + v;
    }
    auto& outs = block_out_[e.id];
    if (inst.empty()) {
      // A function: its value is the call, written where it is used.
      if (has_en) return fail(e.n, "function " + type + " has EN connected: plcfi translates EN on function block calls only");
      outs[""] = type + "(" + args + ")";
      return true;
    }
    const std::string call = inst + "(" + args + ");";
    if (has_en) line("IF " + en + " THEN " + call + " END_IF;", e);
    else line(call, e);
    for (auto v : child(e.n, "outputVariables").children()) {
      if (!is(v, "variable")) continue;
      const std::string formal = v.attribute("formalParameter").value();
      outs[formal] = formal == "ENO" ? (has_en ? en : std::string("TRUE")) : inst + "." + formal;
    }
    return true;
  }

  static constexpr int kMaxDepth = 256;
  static constexpr size_t kMaxText = 64 * 1024;
  int depth_ = 0;
  std::string what_;
  bool instances_;
  LdTranslation* out_;
  LdError* err_;
  std::vector<Element> elements_;
  std::map<long, size_t> by_id_;
  std::map<std::string, long> connectors_;
  std::map<long, std::map<std::string, std::string>> block_out_;
  std::vector<long> temps_;
  std::map<long, std::string> edges_;
};

}  // namespace

bool ld_to_st(const pugi::xml_node& ld, const std::string& what, bool instances, LdTranslation* out, LdError* err) {
  Translator t(what, instances, out, err);
  return t.run(ld);
}

}  // namespace plcfi::st
