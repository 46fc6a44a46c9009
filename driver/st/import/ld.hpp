// Ladder Diagram and Function Block Diagram bodies of PLCopen XML (TC6 2.01 <LD>, <FBD>)
// translated to ST, so a project with such a POU runs like one written in ST. The network
// is a graph: every element names the elements its input is connected to
// (connectionPointIn/connection refLocalId); several connections into one input are a
// parallel branch (OR). Elements are evaluated in an order that respects the connections,
// ties kept in document order (the rungs top to bottom); in FBD, executionOrderId on
// every element that does something gives the order instead. A loop through an in-out
// variable or a function block's output is a feedback path: that connection reads the
// previous value (the variable, the instance's output). Any other loop is an error.
//
// Supported: left and right power rails; contacts (normally open, negated, rising and
// falling edge); coils (plain, negated, set, reset, rising and falling edge); function and
// function block calls (<block>; EN/ENO as ST has them; negated inputs and outputs; edges
// on function block inputs); input (negated), output (negated) and in-out variables;
// connectors and continuations; comments. A function's value is written where it is used.
// A function with EN connected: an output variable wired to it alone is assigned under EN
// (with EN FALSE it keeps its value); a value other boxes read is held in a hidden
// temporary, evaluated once in its place, worth the result type's initial value with EN
// FALSE (as MATIEC computes it); its ENO can be read like a block's. Labels divide
// the body into networks (each ordered on its own); a jump or a return is taken when the
// power flow or the BOOL connected to it is TRUE. Anything else is an error naming the
// element.
#pragma once

#include <string>
#include <vector>

#include <pugixml.hpp>

namespace plcfi::st {

// One line of generated ST and the element it came from (for diagnostics).
struct LdLine {
  std::string text;
  pugi::xml_node at;
};

struct LdTranslation {
  std::vector<LdLine> vars;  // declaration blocks the body needs (before the body)
  std::vector<LdLine> body;  // the statements
  std::vector<std::string> instances;  // the function block instances the statements call
};

struct LdError {
  std::string code;
  pugi::xml_node at;
  std::string message;
};

// Translates the <LD> element `ld` of `what` (e.g. "POU 'Conveyor'"). `instances`: the
// POU may hold FB instances (edges need R_TRIG/F_TRIG); false for a FUNCTION. False, with
// *err, at the first element that cannot be translated.
bool ld_to_st(const pugi::xml_node& ld, const std::string& what, bool instances, LdTranslation* out, LdError* err);

// A transition condition of an SFC chart drawn in LD or FBD, translated to statements that
// set the BOOL `target`.
struct LdCondition {
  // Drawn beside the chart (the transition's <condition><connectionPointIn>): `root` is the
  // element the transition is connected to (`formal` its output), `network` the <SFC>
  // element; only the elements the root's value depends on are translated.
  long root = 0;
  std::string formal;
  // A network of its own (an <inline> or a named transition's body): `root` 0; the coils
  // and output variables named `name` set the target.
  std::string name;
  std::string target;
  pugi::xml_node at;  // the transition, for diagnostics
  std::string tag;    // inserted into the network's hidden names, unique in the POU
};
bool ld_condition_to_st(const pugi::xml_node& network, const std::string& what, bool instances, const LdCondition& cond,
                        LdTranslation* out, LdError* err);

}  // namespace plcfi::st
