#include <gtest/gtest.h>

#include <random>

#include "wavog_mapping/core/haar.h"

namespace {

using wavog::haar::Details;

TEST(Haar, ForwardThenBackwardIsIdentity) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int t = 0; t < 1000; ++t) {
    const std::array<double, 4> v{u(rng), u(rng), u(rng), u(rng)};
    Details<double> d;
    const double s = wavog::haar::forward(v, &d);
    const auto back = wavog::haar::backward(s, d);
    for (int q = 0; q < 4; ++q) EXPECT_NEAR(back[q], v[q], 1e-12);
    EXPECT_NEAR(s, (v[0] + v[1] + v[2] + v[3]) / 4, 1e-12);
  }
}

TEST(Haar, SingleChildFormsMatchFullTransform) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int t = 0; t < 1000; ++t) {
    const std::array<double, 4> v{u(rng), u(rng), u(rng), u(rng)};
    Details<double> d;
    const double s = wavog::haar::forward(v, &d);
    const int q = t % 4;
    EXPECT_NEAR(wavog::haar::backwardChild(s, d, q), v[q], 1e-12);
    // Adding delta to child q: single-child step equals the full transform of the new values.
    const double delta = u(rng);
    auto w = v;
    w[q] += delta;
    Details<double> d2, dd;
    const double s2 = wavog::haar::forward(w, &d2);
    const double ds = wavog::haar::forwardSingleChild(delta, q, &dd);
    EXPECT_NEAR(s + ds, s2, 1e-12);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(d[i] + dd[i], d2[i], 1e-12);
  }
}

TEST(Haar, ConstantBlockHasZeroDetails) {
  Details<double> d;
  EXPECT_DOUBLE_EQ(wavog::haar::forward(std::array<double, 4>{2.5, 2.5, 2.5, 2.5}, &d), 2.5);
  for (double x : d) EXPECT_EQ(x, 0.0);
}

TEST(Haar, ConventionMatchesAlgorithmDoc) {
  // v0 = (0,0), v1 = (1,0), v2 = (0,1), v3 = (1,1): a pure x ramp has only dx.
  Details<double> d;
  wavog::haar::forward(std::array<double, 4>{0, 1, 0, 1}, &d);
  EXPECT_DOUBLE_EQ(d[0], 1.0);
  EXPECT_DOUBLE_EQ(d[1], 0.0);
  EXPECT_DOUBLE_EQ(d[2], 0.0);
  wavog::haar::forward(std::array<double, 4>{1, 0, 0, 1}, &d);
  EXPECT_DOUBLE_EQ(d[2], 2.0);
}

}  // namespace
