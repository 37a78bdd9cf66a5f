#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/standardizer.hpp>

namespace dicestack {
namespace {

TEST(Standardizer, MeanAndPopulationSigmaByHand) {
  Matrix m(3, 2);
  m << 1.0, 5.0, 2.0, 5.0, 3.0, 5.0;
  std::vector<std::string> warnings;
  const std::vector<std::string> names{"a", "b"};
  const Standardizer s = Standardizer::fit(m, &warnings, &names);
  EXPECT_DOUBLE_EQ(s.mean[0], 2.0);
  EXPECT_DOUBLE_EQ(s.sigma[0], std::sqrt(2.0 / 3.0));  // ddof 0
  EXPECT_DOUBLE_EQ(s.sigma[1], 1.0);                     // constant column
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], ::testing::HasSubstr("b is constant"));
  const Matrix z = s.apply(m);
  EXPECT_DOUBLE_EQ(z(0, 0), -1.0 / std::sqrt(2.0 / 3.0));
  EXPECT_DOUBLE_EQ(z(2, 1), 0.0);
  double back[2];
  s.invert_row({z.row(2).data(), 2}, back);
  EXPECT_DOUBLE_EQ(back[0], 3.0);
  EXPECT_THROW(s.apply(Matrix(2, 3)), InputError);
  EXPECT_THROW(Standardizer::fit(Matrix(0, 2)), InputError);
}

TEST(Standardizer, AColumnOfEqualValuesIsConstantWhateverTheRoundingOfItsMean) {
  // 78 copies of 2.6333333969116213 (the paper start's cup y in single precision) sum to a mean
  // one ulp off, and a sigma of 1e-16: a value 2 cm away would then stand 1e14 apart.
  Matrix m(78, 1);
  m.setConstant(2.6333333969116213);
  const Standardizer s = Standardizer::fit(m);
  EXPECT_EQ(s.sigma[0], 1.0);
  EXPECT_EQ(s.mean[0], 2.6333333969116213);
  double in[1] = {2.6533333969116213}, out[1];
  s.apply_row(in, out);
  EXPECT_NEAR(out[0], 0.02, 1e-12);
}

}  // namespace
}  // namespace dicestack
