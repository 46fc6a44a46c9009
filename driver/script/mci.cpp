// m_ci and the ASSERT_COM verdict, written from the definition in CPTest+.
#include "script/mci.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace plcfi::script {

std::string check_params(const MciParams& p) {
  if (!(p.alpha >= 0.0 && p.alpha <= 1.0)) return fmt::format("alpha must be in [0, 1], got {}", p.alpha);
  if (!(p.beta >= 0.0 && p.beta <= 1.0)) return fmt::format("beta must be in [0, 1], got {}", p.beta);
  if (!(p.alpha < p.beta)) return fmt::format("alpha must be less than beta (alpha {}, beta {})", p.alpha, p.beta);
  // gamma - 1 divides: one cycle alone leaves no range to fall over.
  if (p.gamma < 2) return fmt::format("gamma must be at least 2 cycles, got {}", p.gamma);
  if (p.psi < 1) return fmt::format("psi must be at least 1 run, got {}", p.psi);
  if (!(p.n >= 1.0) || !std::isfinite(p.n)) return fmt::format("n must be a number >= 1, got {}", p.n);
  return {};
}

double m_ci(const MciParams& p, int64_t p_lst, int64_t c) {
  p_lst = std::clamp<int64_t>(p_lst, 0, p.psi);
  c = std::max<int64_t>(c, 1);
  // p_lst <= 0.1 psi and p_lst >= 0.9 psi, in integers.
  if (10 * p_lst <= p.psi) return 0.0;
  if (10 * p_lst >= 9 * p.psi) return 1.0;
  if (c > p.gamma) return 0.0;
  double x = std::pow(static_cast<double>(c - 1), p.n) / std::pow(static_cast<double>(p.gamma - 1), p.n);
  return p.beta + (p.alpha - p.beta) * x;
}

Verdict verdict_of(bool held, double mci) {
  if (held) return Verdict::Passed;
  return mci >= 0.5 ? Verdict::Undecidable : Verdict::Failed;
}

const char* verdict_name(Verdict v) {
  switch (v) {
    case Verdict::Passed: return "passed";
    case Verdict::Failed: return "failed";
    case Verdict::Undecidable: return "undecidable";
  }
  return "?";
}

}  // namespace plcfi::script
