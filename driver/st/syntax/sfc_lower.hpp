// Lowering of a textual SFC (Pou::sfc) into ST: variables for the steps and the action
// controls, and statements that make the chart evolve once per call. Everything after the
// parser (type checks, both tiers, variable paths, traces, coverage) then sees ordinary
// ST; a step is a variable `S` of type __SFC_STEP (S.X active, S.T time active) and an
// action a variable of type __SFC_ACTION (A.Q its control output, A.A active incl. the
// final scan), so `Main.Fill.X` is a path like any other.
//
// One call of the POU, in this order (the order MATIEC's generated code uses, with the
// standard's action control):
//  1. Step times: every active step's T grows by the time since the last call.
//  2. Transitions, tried in priority order (PRIORITY := n first, lowest n first, then in
//     text order): one whose FROM steps are all active and whose condition is TRUE fires,
//     and its FROM steps become inactive at once, so a later transition competing for the
//     same step (a selection divergence) is no longer enabled. The TO steps of every fired
//     transition become active (T := 0) after all were tried: a step entered in this call
//     cannot be left in the same call. In the first call no transition is tried: the
//     initial steps become active in it and their actions run.
//  3. Action control (IEC 61131-3 action control block): per action, from the
//     associations of the active steps, Q := NOT R AND (N OR P-edge OR P0-edge OR S_FF OR
//     L-window OR D-timer OR SD OR DS OR SL); A := Q OR (Q fell in this call: the final
//     scan).
//  4. Boolean actions (a variable named in an association, not an ACTION): TRUE while Q,
//     FALSE in the final scan. Then the bodies of the ACTIONs whose A is TRUE, in the order
//     they are declared.
#pragma once

#include "ast.hpp"
#include "diag.hpp"

namespace plcfi::st {

// Checks the chart (an initial step, known and unique names, qualifiers with their
// durations) and appends its variables and statements to the POU. Errors ST141/ST142.
void lower_sfc(Pou& pou, DiagEngine& diags);

}  // namespace plcfi::st
