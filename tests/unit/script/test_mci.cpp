// m_ci against its definition, over its whole domain: the three bands of p_lst with their
// edges at 0.1 psi and 0.9 psi, c = 1, c = gamma, c > gamma, n = 1 and n = 2.
#include <gtest/gtest.h>

#include <cmath>

#include "script/mci.hpp"

namespace plcfi::script {
namespace {

// The formula, evaluated independently in floating point from the published text.
double reference(const MciParams& p, double p_lst, double c) {
  if (p_lst >= 0 && p_lst <= 0.1 * static_cast<double>(p.psi) + 1e-12) return 0.0;
  if (p_lst >= 0.9 * static_cast<double>(p.psi) - 1e-12) return 1.0;
  if (c > static_cast<double>(p.gamma)) return 0.0;
  return p.beta + (p.alpha - p.beta) * std::pow(c - 1, p.n) / std::pow(static_cast<double>(p.gamma) - 1, p.n);
}

TEST(Mci, DefaultsAreThePublishedOnes) {
  MciParams p;
  EXPECT_DOUBLE_EQ(p.alpha, 0.1);
  EXPECT_DOUBLE_EQ(p.beta, 0.9);
  EXPECT_EQ(p.gamma, 10);
  EXPECT_EQ(p.psi, 10);
  EXPECT_DOUBLE_EQ(p.n, 1.0);
  EXPECT_EQ(check_params(p), "");
}

TEST(Mci, LowBandIncludingItsUpperEdgeIsZero) {
  MciParams p;  // psi 10: 0.1 psi = 1
  for (int c : {1, 5, 10, 11, 100}) {
    EXPECT_EQ(m_ci(p, 0, c), 0.0) << c;
    EXPECT_EQ(m_ci(p, 1, c), 0.0) << c;  // the edge 0.1 psi belongs to the low band
  }
}

TEST(Mci, HighBandIncludingItsLowerEdgeIsOne) {
  MciParams p;  // 0.9 psi = 9
  for (int c : {1, 5, 10, 11, 100}) {
    EXPECT_EQ(m_ci(p, 9, c), 1.0) << c;  // the edge 0.9 psi belongs to the high band
    EXPECT_EQ(m_ci(p, 10, c), 1.0) << c;
  }
}

TEST(Mci, MiddleBandFallsLinearlyFromBetaToAlpha) {
  MciParams p;
  for (int p_lst = 2; p_lst <= 8; ++p_lst) {
    EXPECT_DOUBLE_EQ(m_ci(p, p_lst, 1), 0.9) << p_lst;       // c = 1: beta
    EXPECT_DOUBLE_EQ(m_ci(p, p_lst, 10), 0.1) << p_lst;      // c = gamma: alpha
    EXPECT_EQ(m_ci(p, p_lst, 11), 0.0) << p_lst;             // c > gamma: the program
    EXPECT_NEAR(m_ci(p, p_lst, 5), 0.9 - 0.8 * 4.0 / 9.0, 1e-12) << p_lst;
  }
}

TEST(Mci, QuadraticShapeStaysAboveTheLine) {
  MciParams p;
  p.n = 2;
  EXPECT_DOUBLE_EQ(m_ci(p, 5, 1), 0.9);
  EXPECT_DOUBLE_EQ(m_ci(p, 5, 10), 0.1);
  EXPECT_NEAR(m_ci(p, 5, 4), 0.9 - 0.8 * 9.0 / 81.0, 1e-12);
  MciParams lin;
  for (int c = 2; c < 10; ++c) EXPECT_GT(m_ci(p, 5, c), m_ci(lin, 5, c)) << c;
}

TEST(Mci, AgreesWithTheFormulaEverywhere) {
  for (int64_t psi : {1, 3, 10, 20, 25}) {
    for (int64_t gamma : {2, 3, 10, 17}) {
      for (double n : {1.0, 2.0, 3.5}) {
        MciParams p;
        p.psi = psi;
        p.gamma = gamma;
        p.n = n;
        p.alpha = 0.2;
        p.beta = 0.7;
        ASSERT_EQ(check_params(p), "");
        for (int64_t k = 0; k <= psi; ++k)
          for (int64_t c = 1; c <= gamma + 3; ++c)
            EXPECT_NEAR(m_ci(p, k, c), reference(p, static_cast<double>(k), static_cast<double>(c)), 1e-12)
                << "psi " << psi << " gamma " << gamma << " n " << n << " p_lst " << k << " c " << c;
      }
    }
  }
}

TEST(Mci, PublishedRunEndsUndecidableWithFactorOne) {
  // Eleven passes in a row (p_lst = psi = 10), then a run that failed while the link was
  // broken: the condition never held, whatever the cycles.
  MciParams p;
  double m = m_ci(p, 10, 57);
  EXPECT_EQ(m, 1.0);
  EXPECT_EQ(verdict_of(false, m), Verdict::Undecidable);
  // The same failure with no passing history is the program's.
  EXPECT_EQ(verdict_of(false, m_ci(p, 0, 1)), Verdict::Failed);
}

TEST(Mci, VerdictThresholdIsOneHalf) {
  EXPECT_EQ(verdict_of(true, 0.0), Verdict::Passed);
  EXPECT_EQ(verdict_of(true, 1.0), Verdict::Passed);
  EXPECT_EQ(verdict_of(false, 0.5), Verdict::Undecidable);
  EXPECT_EQ(verdict_of(false, std::nextafter(0.5, 0.0)), Verdict::Failed);
  EXPECT_STREQ(verdict_name(Verdict::Undecidable), "undecidable");
}

TEST(Mci, BadParametersAreNamed) {
  MciParams p;
  p.alpha = 0.9;
  p.beta = 0.1;
  EXPECT_EQ(check_params(p), "alpha must be less than beta (alpha 0.9, beta 0.1)");
  p = {};
  p.gamma = 1;
  EXPECT_EQ(check_params(p), "gamma must be at least 2 cycles, got 1");
  p = {};
  p.psi = 0;
  EXPECT_EQ(check_params(p), "psi must be at least 1 run, got 0");
  p = {};
  p.n = 0.5;
  EXPECT_EQ(check_params(p), "n must be a number >= 1, got 0.5");
  p = {};
  p.beta = 1.5;
  EXPECT_EQ(check_params(p), "beta must be in [0, 1], got 1.5");
}

}  // namespace
}  // namespace plcfi::script
