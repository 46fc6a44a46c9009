// The communication-influence metric m_ci of CPTest+ and the verdict of an ASSERT_COM:
// how likely it is that a failed assertion which had to wait through a communication
// error was caused by the communication rather than by the program.
#pragma once

#include <cstdint>
#include <string>

namespace plcfi::script {

// alpha < beta in [0, 1]: the least and the greatest m_ci in the middle band; gamma: the
// cycles taken into account (c beyond gamma counts as the program's fault); psi: how many
// of the latest runs the pass count p_lst looks at; n >= 1: the shape of the fall from
// beta to alpha (1: linear).
struct MciParams {
  double alpha = 0.1;
  double beta = 0.9;
  int64_t gamma = 10;
  int64_t psi = 10;
  double n = 1.0;
};

// Empty when the parameters are usable, else what is wrong with them, e.g.
// "alpha must be less than beta (alpha 0.9, beta 0.1)".
std::string check_params(const MciParams& p);

// m_ci(p_lst, c), with p_lst the passes among the latest psi runs (0..psi) and c >= 1 the
// cycles the assertion needed:
//   0      when p_lst <= 0.1 psi
//   1      when p_lst >= 0.9 psi
//   delta  in between when c <= gamma, 0 when c > gamma,
//   delta = beta + (alpha - beta) (c - 1)^n / (gamma - 1)^n.
// The band edges are compared exactly (10 p_lst against psi), not in floating point.
// Requires check_params(p) to be empty; p_lst is clamped to [0, psi] and c to >= 1.
double m_ci(const MciParams& p, int64_t p_lst, int64_t c);

enum class Verdict : uint8_t { Passed, Failed, Undecidable };

// The verdict of an assertion: passed when its condition held in the end; otherwise
// undecidable when m_ci >= 0.5 (probably the communication), failed below.
Verdict verdict_of(bool held, double mci);

const char* verdict_name(Verdict v);  // "passed", "failed", "undecidable"

}  // namespace plcfi::script
