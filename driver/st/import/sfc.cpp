// PLCopen XML SFC to textual SFC; see sfc.hpp.
#include "import/sfc.hpp"
#include "import/ld.hpp"
#include "import/xml_nodes.hpp"

#include <cstdlib>
#include <map>
#include <set>

namespace plcfi::st {

namespace {

using xml::child;
using xml::children;
using xml::is;
using xml::local_name;

// Graph walks are bounded: a chart whose connections form a cycle without a step (a
// malformed file) ends in an error, not a hang.
constexpr int kMaxWalk = 256;
constexpr long kMaxVisits = 1 << 20;  // all walks of a chart: diamonds of divergences cannot blow up
constexpr int kMaxNesting = 64;

std::string all_text(const pugi::xml_node& n, int depth) {
  std::string s;
  if (depth > kMaxNesting) return s;
  for (auto c : n.children()) {
    if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata) s += c.value();
    else if (c.type() == pugi::node_element) s += all_text(c, depth + 1) + "\n";
  }
  return s;
}

std::string trimmed(std::string s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && blank(s.back())) s.pop_back();
  size_t a = 0;
  while (a < s.size() && blank(s[a])) ++a;
  return s.substr(a);
}


struct Node {
  pugi::xml_node n;
  std::string kind;              // step, transition, selectionDivergence, ...
  std::vector<long> preds;       // refLocalIds of every connectionPointIn
  std::vector<long> succs;       // filled from the others' preds
};

class Translator {
 public:
  Translator(const pugi::xml_node& pou, const std::string& what, std::vector<SfcPiece>* out, std::vector<SfcPiece>* vars,
             SfcError* err)
      : pou_(pou), what_(what), out_(out), vars_(vars), err_(err) {}

  bool run(const pugi::xml_node& sfc) {
    sfc_ = sfc;
    if (!collect(sfc)) return false;
    // Steps first, in document order, each with its action associations.
    for (long id : order_) {
      const Node& s = nodes_[id];
      if (s.kind != "step") continue;
      std::string name = s.n.attribute("name").value();
      const bool initial = std::string_view(s.n.attribute("initialStep").value()) == "true" ||
                           std::string_view(s.n.attribute("initialStep").value()) == "1";
      text(std::string(initial ? "INITIAL_STEP " : "STEP ") + name + ":", s.n);
      for (const pugi::xml_node& action : blocks_[id])
        if (!association(action, name)) return false;
      text("END_STEP", s.n);
    }
    for (long id : order_) {
      const Node& t = nodes_[id];
      if (t.kind == "transition" && !transition(id)) return false;
    }
    // The ACTION bodies, in the order the steps first name them (the order they run in).
    for (const auto& [name, node, st] : actions_) {
      text("ACTION " + name + ":", node);
      out_->push_back(SfcPiece{"", node, st, ""});
      text("END_ACTION", node);
    }
    return true;
  }

 private:
  bool fail(const char* code, const pugi::xml_node& at, std::string message) {
    *err_ = SfcError{code, at, std::move(message)};
    return false;
  }
  void text(std::string t, const pugi::xml_node& at) { out_->push_back(SfcPiece{std::move(t), at, {}, ""}); }

  static pugi::xml_node named(const pugi::xml_node& list, const char* element, const std::string& name) {
    for (auto c : children(list, element))
      if (c.attribute("name").value() == name) return c;
    return {};
  }

  bool collect(const pugi::xml_node& sfc) {
    for (auto e : sfc.children()) {
      if (e.type() != pugi::node_element) continue;
      const std::string kind(local_name(e));
      if (kind == "comment" || kind == "addData" || kind == "documentation") continue;
      // LD and FBD elements drawn beside the chart: the conditions connected to them
      // translate them (network_condition).
      static const std::set<std::string> kNetwork = {"leftPowerRail", "rightPowerRail", "contact", "coil", "block",
                                                      "inVariable", "outVariable", "inOutVariable", "connector",
                                                      "continuation"};
      if (kNetwork.count(kind)) continue;
      static const std::set<std::string> kKnown = {"step", "transition", "selectionDivergence", "selectionConvergence",
                                                    "simultaneousDivergence", "simultaneousConvergence", "jumpStep",
                                                    "actionBlock", "macroStep"};
      if (!kKnown.count(kind) || kind == "macroStep")
        return fail("ST606", e, what_ + ": the SFC element <" + kind + "> is not supported");
      char* end = nullptr;
      const long id = std::strtol(e.attribute("localId").value(), &end, 10);
      if (!end || *end != '\0' || !e.attribute("localId"))
        return fail("ST606", e, what_ + ": <" + kind + "> without a numeric localId");
      Node n{e, kind, {}, {}};
      for (auto in : children(e, "connectionPointIn"))
        for (auto c : children(in, "connection")) n.preds.push_back(std::strtol(c.attribute("refLocalId").value(), nullptr, 10));
      if (!nodes_.emplace(id, std::move(n)).second) return fail("ST606", e, what_ + ": localId " + std::to_string(id) + " is used twice");
      order_.push_back(id);
    }
    for (long id : order_)
      for (long p : nodes_[id].preds) {
        auto it = nodes_.find(p);
        if (it == nodes_.end())
          return fail("ST606", nodes_[id].n, what_ + ": <" + nodes_[id].kind + "> is connected to localId " +
                                                   std::to_string(p) + ", which is not in the chart");
        it->second.succs.push_back(id);
      }
    for (long id : order_) {
      const Node& n = nodes_[id];
      if (n.kind == "step") {
        const std::string name = n.n.attribute("name").value();
        if (name.empty()) return fail("ST606", n.n, what_ + ": a <step> without a name");
      } else if (n.kind == "actionBlock") {
        if (n.preds.size() != 1 || nodes_[n.preds[0]].kind != "step")
          return fail("ST606", n.n, what_ + ": an <actionBlock> must be connected to one step");
        for (auto a : children(n.n, "action")) blocks_[n.preds[0]].push_back(a);
      }
    }
    return true;
  }

  // One action of an action block: `Name(Q[, duration][, indicator]);`.
  bool association(const pugi::xml_node& a, const std::string& step) {
    std::string name;
    if (pugi::xml_node ref = child(a, "reference")) {
      name = ref.attribute("name").value();
      if (name.empty()) return fail("ST606", a, what_ + ": an action reference without a name");
      if (pugi::xml_node def = named(child(pou_, "actions"), "action", name); def && !used_.count(name)) {
        pugi::xml_node st = child(child(def, "body"), "ST");
        if (!st)
          return fail("ST606", def, "action '" + name + "' of " + what_ + " needs an ST body: plcfi reads SFC actions in ST");
        used_.insert(name);
        actions_.push_back({name, def, st});
      }
    } else if (pugi::xml_node in = child(a, "inline")) {
      if (!child(in, "ST"))
        return fail("ST606", a, what_ + ": an inline action of step '" + step + "' must be ST");
      name = step + "_INLINE" + std::to_string(++inline_count_);
      actions_.push_back({name, a, child(in, "ST")});
    } else {
      return fail("ST606", a, what_ + ": an <action> of step '" + step + "' has neither a reference nor inline ST");
    }
    std::string q = a.attribute("qualifier").value();
    if (q.empty()) q = "N";
    std::string line = name + "(" + q;
    if (const char* d = a.attribute("duration").value(); *d) line += ", " + std::string(d);
    if (const char* i = a.attribute("indicator").value(); *i) line += ", " + std::string(i);
    text(line + ");", a);
    return true;
  }

  // The steps a transition comes from: walk back through divergences and convergences.
  bool steps_before(long id, std::vector<std::string>* out, int depth) {
    if (depth > kMaxWalk || ++visits_ > kMaxVisits)
      return fail("ST606", nodes_[id].n, what_ + ": the chart's connections form a cycle without a step");
    const Node& n = nodes_[id];
    if (n.kind == "step") {
      out->push_back(n.n.attribute("name").value());
      return true;
    }
    if (n.kind != "selectionDivergence" && n.kind != "simultaneousConvergence" && n.kind != "selectionConvergence")
      return fail("ST606", n.n, what_ + ": a transition cannot follow <" + n.kind + ">");
    for (long p : n.preds)
      if (!steps_before(p, out, depth + 1)) return false;
    return true;
  }

  // The steps a transition leads to: walk forward through divergences, convergences and jumps.
  bool steps_after(long id, std::vector<std::string>* out, int depth) {
    if (depth > kMaxWalk || ++visits_ > kMaxVisits)
      return fail("ST606", nodes_[id].n, what_ + ": the chart's connections form a cycle without a step");
    for (long s : nodes_[id].succs) {
      const Node& n = nodes_[s];
      if (n.kind == "step") {
        out->push_back(n.n.attribute("name").value());
      } else if (n.kind == "jumpStep") {
        std::string target = n.n.attribute("targetName").value();
        if (target.empty()) return fail("ST606", n.n, what_ + ": a <jumpStep> without a targetName");
        out->push_back(target);
      } else if (n.kind == "simultaneousDivergence" || n.kind == "selectionConvergence") {
        if (!steps_after(s, out, depth + 1)) return false;
      } else if (n.kind != "actionBlock") {
        return fail("ST606", n.n, what_ + ": <" + n.kind + "> cannot follow a transition");
      }
    }
    return true;
  }

  static std::string list(const std::vector<std::string>& steps) {
    if (steps.size() == 1) return steps[0];
    std::string s = "(";
    for (size_t i = 0; i < steps.size(); ++i) s += (i ? ", " : "") + steps[i];
    return s + ")";
  }

  bool transition(long id) {
    const Node& t = nodes_[id];
    std::vector<std::string> from, to;
    for (long p : t.preds)
      if (!steps_before(p, &from, 0)) return false;
    if (!steps_after(id, &to, 0)) return false;
    if (from.empty()) return fail("ST606", t.n, what_ + ": a transition not connected to a step before it");
    if (to.empty()) return fail("ST606", t.n, what_ + ": a transition not connected to a step after it");
    std::string head = "TRANSITION";
    if (const char* p = t.n.attribute("priority").value(); *p) head += " (PRIORITY := " + std::string(p) + ")";
    head += " FROM " + list(from) + " TO " + list(to);
    pugi::xml_node cond = child(t.n, "condition");
    if (pugi::xml_node in = child(cond, "inline")) {
      pugi::xml_node st = child(in, "ST");
      if (pugi::xml_node il = child(in, "IL")) return il_condition(head, t.n, il);
      if (pugi::xml_node net = network(in)) {
        LdCondition c;
        c.name = trimmed(in.attribute("name").value());
        if (c.name.empty())
          return fail("ST606", in, what_ + ": an inline condition drawn in LD or FBD needs a name (its coil or output "
                                           "variable of that name gives the condition)");
        return network_condition(head, id, net, std::move(c));
      }
      if (!st) return fail("ST606", in, what_ + ": an inline transition condition must be ST, IL, LD or FBD");
      out_->push_back(SfcPiece{head + " := ", t.n, st, ";"});
    } else if (pugi::xml_node ref = child(cond, "reference")) {
      const std::string name = ref.attribute("name").value();
      pugi::xml_node tr = named(child(pou_, "transitions"), "transition", name);
      if (!tr) return fail("ST606", ref, what_ + ": the transition '" + name + "' it refers to is not in <transitions>");
      pugi::xml_node tbody = child(tr, "body");
      if (pugi::xml_node il = child(tbody, "IL")) return il_condition(head, tr, il);
      if (pugi::xml_node net = network(tbody)) {
        LdCondition c;
        c.name = name;
        return network_condition(head, id, net, std::move(c));
      }
      pugi::xml_node st = child(tbody, "ST");
      if (!st) return fail("ST606", tr, what_ + ": transition '" + name + "' needs a body in ST, IL, LD or FBD");
      // Its body is ":= condition;" as Beremiz writes it, or the bare condition.
      std::string body = trimmed(all_text(st, 0));
      if (body.rfind(":=", 0) == 0) {
        out_->push_back(SfcPiece{head, tr, st, ""});
      } else {
        out_->push_back(SfcPiece{head + " := ", tr, st, !body.empty() && body.back() == ';' ? "" : ";"});
      }
    } else if (pugi::xml_node point = child(cond, "connectionPointIn")) {
      // Drawn beside the chart: the value of the element the condition is connected to.
      std::vector<pugi::xml_node> links = children(point, "connection");
      if (links.size() != 1)
        return fail("ST606", point, what_ + ": a transition condition must be connected to exactly one element");
      LdCondition c;
      char* end = nullptr;
      c.root = std::strtol(links[0].attribute("refLocalId").value(), &end, 10);
      if (!end || *end || !c.root) return fail("ST606", links[0], what_ + ": a condition connection without a numeric refLocalId");
      c.formal = links[0].attribute("formalParameter").value();
      return network_condition(head, id, sfc_, std::move(c));
    } else {
      return fail("ST606", t.n, what_ + ": a transition without a condition (inline, a reference or a connection)");
    }
    text("END_TRANSITION", t.n);
    return true;
  }

  static pugi::xml_node network(const pugi::xml_node& holder) {
    if (pugi::xml_node ld = child(holder, "LD")) return ld;
    return child(holder, "FBD");
  }

  // A condition in IL: the instructions' final current result.
  bool il_condition(const std::string& head, const pugi::xml_node& at, const pugi::xml_node& il) {
    text(head + " :", at);
    out_->push_back(SfcPiece{"", at, il, ""});
    text("END_TRANSITION", at);
    return true;
  }

  // A condition drawn in LD or FBD: the network's statements set a hidden BOOL, the
  // transition's name in the generated text (parse_sfc.cpp), which is the condition.
  bool network_condition(const std::string& head, long id, const pugi::xml_node& net, LdCondition c) {
    const std::string tag = "t" + std::to_string(id) + "_";
    c.target = "_sfc" + tag + "cond";
    c.tag = tag;
    c.at = nodes_[id].n;
    LdTranslation tr;
    LdError err;
    if (!ld_condition_to_st(net, what_, true, c, &tr, &err)) return fail(err.code.c_str(), err.at, err.message);
    // Drawn beside the chart, one function block may feed two conditions: each would call
    // it, twice in a scan when both transitions are tried (an edge or a count lost).
    for (const std::string& inst : tr.instances) {
      auto [it, fresh] = called_.emplace(inst, id);
      if (!fresh && it->second != id)
        return fail("ST606", c.at, what_ + ": the function block instance '" + inst + "' feeds the conditions of two "
                                           "transitions (localId " + std::to_string(it->second) + " and " +
                                           std::to_string(id) + "): each would call it in the same scan; let one "
                                           "condition call it and the other read a variable it sets");
    }
    for (const LdLine& v : tr.vars) vars_->push_back(SfcPiece{v.text, v.at, {}, ""});
    // TRANSITION name (PRIORITY ...) FROM ...: the name goes right after the keyword.
    text("TRANSITION " + c.target + head.substr(std::string("TRANSITION").size()) + " :", c.at);
    for (const LdLine& l : tr.body) text("  " + l.text, l.at);
    text("END_TRANSITION", c.at);
    return true;
  }

  pugi::xml_node pou_;
  pugi::xml_node sfc_;
  std::string what_;
  std::vector<SfcPiece>* out_;
  std::vector<SfcPiece>* vars_;
  SfcError* err_;
  std::map<long, Node> nodes_;
  std::vector<long> order_;  // document order
  std::map<long, std::vector<pugi::xml_node>> blocks_;  // step -> its actions
  struct Action {
    std::string name;
    pugi::xml_node at, st;
  };
  std::vector<Action> actions_;  // ACTION bodies in order of first association
  std::set<std::string> used_;
  int inline_count_ = 0;
  long visits_ = 0;
  std::map<std::string, long> called_;  // FB instance -> the transition whose condition calls it
};

}  // namespace

bool sfc_to_text(const pugi::xml_node& sfc, const pugi::xml_node& pou, const std::string& what,
                 std::vector<SfcPiece>* out, std::vector<SfcPiece>* vars, SfcError* err) {
  return Translator(pou, what, out, vars, err).run(sfc);
}

}  // namespace plcfi::st
