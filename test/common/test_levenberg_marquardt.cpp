/// \file test_levenberg_marquardt.cpp
/// \brief The generic Levenberg–Marquardt solver: exact fits are found to the stated tolerance,
/// a model that cannot decrease stops without moving, and the iteration cap holds.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "scanhead/common/levenberg_marquardt.hpp"

using scanhead::levenbergMarquardt;
using scanhead::LevenbergMarquardtResult;

namespace
{
/// Samples of y = a·exp(−b·t) on t = 0, 0.1, …, 2.
struct ExponentialData
{
  std::vector<double> t, y;
  ExponentialData(double a, double b)
  {
    for (int k = 0; k <= 20; ++k)
    {
      t.push_back(0.1 * k);
      y.push_back(a * std::exp(-b * t.back()));
    }
  }
  Eigen::VectorXd operator()(const Eigen::VectorXd& x) const
  {
    Eigen::VectorXd r(static_cast<Eigen::Index>(t.size()));
    for (std::size_t k = 0; k < t.size(); ++k)
      r[static_cast<Eigen::Index>(k)] = x[0] * std::exp(-x[1] * t[k]) - y[k];
    return r;
  }
};
}  // namespace

// Noise-free data: the fit recovers the parameters to 1e-8 relative from a guess 2x off.
TEST(LevenbergMarquardt, RecoversExactExponential)
{
  const ExponentialData data(2.5, 1.7);
  Eigen::VectorXd x0(2);
  x0 << 1.0, 0.8;
  const LevenbergMarquardtResult fit = levenbergMarquardt(data, x0, 200);
  EXPECT_NEAR(fit.x[0], 2.5, 2.5e-8);
  EXPECT_NEAR(fit.x[1], 1.7, 1.7e-8);
  EXPECT_LT(fit.cost, 1e-20);
  EXPECT_GT(fit.iterations, 0);
  EXPECT_LT(fit.iterations, 200);
}

// The Rosenbrock valley as residuals (10(x1 − x0²), 1 − x0): minimum 0 at (1, 1).
TEST(LevenbergMarquardt, RosenbrockValley)
{
  const auto rosenbrock = [](const Eigen::VectorXd& x) {
    Eigen::VectorXd r(2);
    r << 10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0];
    return r;
  };
  Eigen::VectorXd x0(2);
  x0 << -1.2, 1.0;
  const LevenbergMarquardtResult fit = levenbergMarquardt(rosenbrock, x0, 500);
  EXPECT_NEAR(fit.x[0], 1.0, 1e-6);
  EXPECT_NEAR(fit.x[1], 1.0, 1e-6);
}

// Already at the minimum: no step lowers the cost, so x comes back unchanged after one iteration.
TEST(LevenbergMarquardt, StopsAtTheMinimumWithoutMoving)
{
  const auto residuals = [](const Eigen::VectorXd& x) { return Eigen::VectorXd(x.array() - 3.0); };
  const Eigen::VectorXd x0 = Eigen::VectorXd::Constant(3, 3.0);
  const LevenbergMarquardtResult fit = levenbergMarquardt(residuals, x0, 50);
  EXPECT_EQ(fit.x, x0);
  EXPECT_EQ(fit.cost, 0.0);
  EXPECT_EQ(fit.iterations, 1);
}

// The iteration cap is respected, and the cost never rises above the initial one.
TEST(LevenbergMarquardt, IterationCap)
{
  const ExponentialData data(2.5, 1.7);
  Eigen::VectorXd x0(2);
  x0 << 1.0, 0.8;
  const double initial = data(x0).squaredNorm();
  const LevenbergMarquardtResult fit = levenbergMarquardt(data, x0, 2);
  EXPECT_LE(fit.iterations, 2);
  EXPECT_LT(fit.cost, initial);
}
