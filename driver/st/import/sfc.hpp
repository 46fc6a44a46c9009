// Sequential Function Chart bodies of PLCopen XML (TC6 2.01 <SFC>) translated to the
// textual SFC the ST front end reads (INITIAL_STEP/STEP, TRANSITION FROM .. TO ..,
// ACTION), so a graphical chart runs like a textual one.
//
// The chart is a graph: every element names the elements its input is connected to
// (connectionPointIn/connection refLocalId). A transition comes FROM the steps found by
// walking back from it through selection divergences and simultaneous convergences, and
// goes TO the steps found by walking forward through simultaneous divergences, selection
// convergences and jump steps (a jump step stands for its target).
//
// Supported: steps (initialStep), transitions with a condition inline (ST, IL, or a
// network in LD or FBD whose coil or output variable of the inline's name gives it), a
// reference to a named transition of the POU (<transitions>: an ST or IL body, or an LD or
// FBD network setting the transition's name, as Beremiz draws them) or a connection to LD
// or FBD elements drawn beside the chart (the value of the element connected; only the
// elements it depends on are evaluated, when the transition is tried), priorities, the four
// divergence/convergence elements, jump steps, action blocks whose actions reference an
// action of the POU (<actions>, an ST body) or hold inline ST, each with its qualifier,
// duration and indicator. An action body in another language than ST is an error naming
// the element.
#pragma once

#include <string>
#include <vector>

#include <pugixml.hpp>

namespace plcfi::st {

// One piece of the generated chart: a line of text, or `prefix`, the text content of the
// XML element `copy` (user ST, mapped to the file column by column) and `suffix`.
struct SfcPiece {
  std::string text;
  pugi::xml_node at;    // the element a synthesized line points at
  pugi::xml_node copy;  // non-null: copy this element's text between prefix and suffix
  std::string suffix;
};

struct SfcError {
  std::string code;
  pugi::xml_node at;
  std::string message;
};

// Translates the <SFC> element of `pou` (its <actions> and <transitions> supply the named
// bodies). `what` names the POU in messages. False, with *err, on an unsupported or
// malformed chart.
// *vars: declaration blocks the chart needs (conditions drawn in LD or FBD), to go before
// the body.
bool sfc_to_text(const pugi::xml_node& sfc, const pugi::xml_node& pou, const std::string& what,
                 std::vector<SfcPiece>* out, std::vector<SfcPiece>* vars, SfcError* err);

}  // namespace plcfi::st
