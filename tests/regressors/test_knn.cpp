#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

namespace dicestack {
namespace {

Matrix random_matrix(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  Rng rng(seed);
  Matrix m(n, d);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = rng.uniform(-1.0, 1.0);
  return m;
}

// The mean label of the k nearest rows by brute force (l2 or l1).
std::vector<double> brute_force(const Matrix& x, const Matrix& y, const double* q, int k, bool l1) {
  std::vector<std::pair<double, Eigen::Index>> d;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    double s = 0.0;
    for (Eigen::Index j = 0; j < x.cols(); ++j) s += l1 ? std::abs(x(i, j) - q[j]) : (x(i, j) - q[j]) * (x(i, j) - q[j]);
    d.emplace_back(s, i);
  }
  std::sort(d.begin(), d.end());
  std::vector<double> out(static_cast<std::size_t>(y.cols()), 0.0);
  for (int n = 0; n < k; ++n)
    for (Eigen::Index j = 0; j < y.cols(); ++j) out[static_cast<std::size_t>(j)] += y(d[static_cast<std::size_t>(n)].second, j) / k;
  return out;
}

TEST(Knn, MatchesBruteForceSearch) {
  for (const char* metric : {"l2", "l1"}) {
    for (const Eigen::Index dims : {Eigen::Index{24}, Eigen::Index{5}}) {  // fixed-size and dynamic trees
      const Matrix x = random_matrix(800, dims, 1), y = random_matrix(800, 3, 2), q = random_matrix(50, dims, 3);
      auto knn = RegressorRegistry::global().create("knn", {"k=4", std::string("metric=") + metric});
      knn->fit(x, y, 0);
      double out[3];
      for (Eigen::Index i = 0; i < q.rows(); ++i) {
        knn->predict_row({q.row(i).data(), static_cast<std::size_t>(dims)}, out);
        const auto expected = brute_force(x, y, q.row(i).data(), 4, std::string(metric) == "l1");
        for (int j = 0; j < 3; ++j) ASSERT_NEAR(out[j], expected[static_cast<std::size_t>(j)], 1e-12) << metric << " " << dims;
      }
    }
  }
}

TEST(Knn, KOfOneReproducesTrainingLabels) {
  const Matrix x = random_matrix(200, 24, 4), y = random_matrix(200, 3, 5);
  auto knn = RegressorRegistry::global().create("knn", {"k=1"});
  knn->fit(x, y, 0);
  EXPECT_EQ(knn->predict(x), y);
}

}  // namespace
}  // namespace dicestack
