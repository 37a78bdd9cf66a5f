#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <cmath>
#include <numeric>
#include <vector>

#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>
#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using test::random_matrix;
using Index = Eigen::Index;

// The mean label of the k nearest rows by brute force (l2 or l1); equal distances: the earlier row.
std::vector<double> brute_force(const Matrix& x, const Matrix& y, const double* q, int k, bool l1) {
  std::vector<std::pair<double, Eigen::Index>> d;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    double s = 0.0;
    for (Eigen::Index j = 0; j < x.cols(); ++j) s += l1 ? std::abs(x(i, j) - q[j]) : (x(i, j) - q[j]) * (x(i, j) - q[j]);
    d.emplace_back(s, i);
  }
  std::sort(d.begin(), d.end());  // pairs: equal distances by row
  std::vector<double> out(static_cast<std::size_t>(y.cols()), 0.0);
  for (int n = 0; n < k; ++n)
    for (Eigen::Index j = 0; j < y.cols(); ++j) out[static_cast<std::size_t>(j)] += y(d[static_cast<std::size_t>(n)].second, j) / k;
  return out;
}

TEST(Knn, MatchesBruteForceSearch) {
  for (const char* search : {"search=cluster_tree", "search=kdtree"})
    for (const char* metric : {"l2", "l1"}) {
      for (const Eigen::Index dims : {Eigen::Index{24}, Eigen::Index{5}, Eigen::Index{49}}) {  // fixed-size and dynamic trees
        const Matrix x = random_matrix(800, dims, 1), y = random_matrix(800, 3, 2), q = random_matrix(50, dims, 3);
        auto knn = RegressorRegistry::global().create("knn", {"k=4", std::string("metric=") + metric, search});
        knn->fit(x, y, 0);
        double out[3];
        for (Eigen::Index i = 0; i < q.rows(); ++i) {
          knn->predict_row({q.row(i).data(), static_cast<std::size_t>(dims)}, out);
          const auto expected = brute_force(x, y, q.row(i).data(), 4, std::string(metric) == "l1");
          for (int j = 0; j < 3; ++j)
            ASSERT_NEAR(out[j], expected[static_cast<std::size_t>(j)], 1e-12) << search << " " << metric << " " << dims;
        }
      }
    }
}

TEST(Knn, ClusterTreeIsExactOnWideTrajectoryLikeRowsWithRepeats) {
  // dart's rows: 49 wide, a start block shared by each episode's rows, smooth paths, repeated
  // rows with different labels (a cup at rest). Queries from new starts, between the rows and
  // far from them; equal distances go to the earlier row, as brute force orders them.
  const Index episodes = 40, steps = 50, wide = 49;
  Matrix x(episodes * steps, wide);
  const Matrix starts = random_matrix(episodes, 24, 21), paths = random_matrix(episodes, 24, 22);
  for (Index e = 0; e < episodes; ++e)
    for (Index t = 0; t < steps; ++t) {
      const Index r = e * steps + t;
      const double phase = t < 10 ? 0.0 : static_cast<double>(t) / steps;  // at rest for 10 steps: repeats
      x.row(r).head(24) = starts.row(e) + phase * paths.row(e);
      x(r, 24) = phase;
      x.row(r).tail(24) = starts.row(e);
    }
  const Matrix y = random_matrix(x.rows(), 3, 23);
  Matrix q = x.topRows(30) + 0.3 * random_matrix(30, wide, 24);
  q.bottomRows(10) *= 5.0;  // far from every row
  for (const char* metric : {"metric=l2", "metric=l1"})
    for (const char* k : {"k=1", "k=3", "k=64"}) {
      auto knn = RegressorRegistry::global().create("knn", {k, metric, "leaf_size=4"});
      knn->fit(x, y, 0);
      const int kk = std::stoi(std::string(k).substr(2));
      double out[3];
      for (Index i = 0; i < q.rows() + 24; ++i) {
        Eigen::VectorXd near;
        const double* query = i < q.rows() ? q.row(i).data() : x.row(((i - q.rows()) % 12) * steps + 3).data();  // a repeated row
        if (i >= q.rows() + 12) {  // a hair (1e-6) off a training row in one column: bounds near distance 0
          near = x.row(((i - q.rows()) % 12) * steps + 17).transpose();
          near((i * 7) % wide) += 1e-6;
          query = near.data();
        }
        knn->predict_row({query, static_cast<std::size_t>(wide)}, out);
        const auto expected = brute_force(x, y, query, kk, std::string(metric) == "metric=l1");
        for (int j = 0; j < 3; ++j) ASSERT_NEAR(out[j], expected[static_cast<std::size_t>(j)], 1e-12) << metric << " " << k << " query " << i;
      }
    }
}

// The cluster tree's distance (ClusterTree::search): float differences, each of 8 lanes
// summing columns j = lane, lane + 8, ... in order, then the lanes as ((0+4)+(2+6))+((1+5)+(3+7)).
float documented_distance(const float* a, const float* b, Index cols, bool l1) {
  float lane[8] = {};
  for (Index j = 0; j < cols; ++j) {
    const float t = a[j] - b[j];
    lane[j % 8] += l1 ? std::abs(t) : t * t;
  }
  return ((lane[0] + lane[4]) + (lane[2] + lane[6])) + ((lane[1] + lane[5]) + (lane[3] + lane[7]));
}

// The same terms summed in another order (column by column): the negative control.
float sequential_distance(const float* a, const float* b, Index cols, bool l1) {
  float sum = 0.0f;
  for (Index j = 0; j < cols; ++j) {
    const float t = a[j] - b[j];
    sum += l1 ? std::abs(t) : t * t;
  }
  return sum;
}

TEST(Knn, ClusterTreeSumsDistancesInTheDocumentedOrderBitForBit) {
  // Rows with the same values in other columns lie at the same real distance from the origin,
  // but float sums in another order differ in their last bits: which of them is nearest depends
  // on the summation order. The tree (its AVX2 code on a CPU that has it, else the baseline
  // code) must pick what a brute-force search with the documented order picks. Each row comes
  // with its negative, so the column means are exactly 0 and knn's centring changes nothing.
  const Index wide = 49, bases = 30, perms = 6;
  Matrix x(2 * bases * perms, wide);
  Rng rng(31);
  for (Index b = 0; b < bases; ++b) {
    std::vector<float> base(static_cast<std::size_t>(wide));
    for (float& v : base) v = static_cast<float>(rng.uniform(-1.0, 1.0));
    for (Index p = 0; p < perms; ++p) {
      std::vector<float> row = base;
      std::rotate(row.begin(), row.begin() + 1 + 3 * p, row.end());
      for (Index j = 0; j < wide; ++j) {
        x(2 * (b * perms + p), j) = row[static_cast<std::size_t>(j)];
        x(2 * (b * perms + p) + 1, j) = -row[static_cast<std::size_t>(j)];
      }
    }
  }
  Matrix y(x.rows(), 1);
  for (Index i = 0; i < x.rows(); ++i) y(i, 0) = static_cast<double>(1 << (i % 20)) + static_cast<double>(i);  // distinct labels
  Matrix q = Matrix::Zero(8, wide);
  for (Index i = 1; i < q.rows(); ++i)
    for (Index j = 0; j < wide; ++j) q(i, j) = static_cast<double>(static_cast<float>(1e-3 * rng.uniform(-1.0, 1.0)));
  int order_tells = 0;  // queries where the other order picks other rows
  for (const bool l1 : {false, true})
    for (const int k : {1, 3}) {
      auto knn = RegressorRegistry::global().create("knn", {"k=" + std::to_string(k), l1 ? "metric=l1" : "metric=l2", "leaf_size=4"});
      knn->fit(x, y, 0);
      for (Index i = 0; i < q.rows(); ++i) {
        std::vector<float> qf(static_cast<std::size_t>(wide)), row(static_cast<std::size_t>(wide));
        for (Index j = 0; j < wide; ++j) qf[static_cast<std::size_t>(j)] = static_cast<float>(q(i, j));
        auto mean_of_nearest = [&](float (*distance)(const float*, const float*, Index, bool)) {
          std::vector<std::pair<float, Index>> d;
          for (Index r = 0; r < x.rows(); ++r) {
            for (Index j = 0; j < wide; ++j) row[static_cast<std::size_t>(j)] = static_cast<float>(x(r, j));
            d.emplace_back(distance(row.data(), qf.data(), wide, l1), r);
          }
          std::sort(d.begin(), d.end());
          double mean = 0.0;
          for (int n = 0; n < k; ++n) mean += y(d[static_cast<std::size_t>(n)].second, 0);
          return mean / k;
        };
        const double expected = mean_of_nearest(documented_distance);
        order_tells += mean_of_nearest(sequential_distance) != expected;
        double out = 0.0;
        knn->predict_row({q.row(i).data(), static_cast<std::size_t>(wide)}, {&out, 1});
        EXPECT_EQ(out, expected) << (l1 ? "l1" : "l2") << " k " << k << " query " << i;
      }
    }
  EXPECT_GT(order_tells, 0) << "the rows must tell the documented summation order from another";
}

TEST(Knn, ClusterTreeStaysExactWhenItsQueueOfNodesIsFull) {
  // Many leaves and far queries with a large k: nearly every node passes its bound, more than
  // the best-first queue holds, and the search goes on depth first; still brute force's rows.
  const Index rows = 40000, wide = 24;
  const Matrix x = random_matrix(rows, wide, 41), y = random_matrix(rows, 3, 42);
  const Matrix q = 6.0 * random_matrix(4, wide, 43);
  auto knn = RegressorRegistry::global().create("knn", {"k=64", "leaf_size=4"});
  knn->fit(x, y, 0);
  double out[3];
  for (Index i = 0; i < q.rows(); ++i) {
    knn->predict_row({q.row(i).data(), static_cast<std::size_t>(wide)}, out);
    const auto expected = brute_force(x, y, q.row(i).data(), 64, false);
    for (int j = 0; j < 3; ++j) ASSERT_NEAR(out[j], expected[static_cast<std::size_t>(j)], 1e-12) << "query " << i;
  }
}

TEST(Knn, PrincipalAxesSearchMatchesBruteForceOnCorrelatedStates) {
  // States on a few correlated directions (as the dice move with the cup): the rotated and the
  // unrotated tree find the brute-force neighbours.
  const Matrix mix = random_matrix(4, 24, 8);
  const Matrix x = random_matrix(1000, 4, 9) * mix + 0.01 * random_matrix(1000, 24, 10);
  const Matrix q = random_matrix(40, 4, 11) * mix + 0.01 * random_matrix(40, 24, 12);
  const Matrix y = random_matrix(1000, 3, 13);
  for (const char* rotate : {"rotate=true", "rotate=false"}) {
    auto knn = RegressorRegistry::global().create("knn", {"k=3", rotate, "search=kdtree"});
    knn->fit(x, y, 0);
    double out[3];
    for (Eigen::Index i = 0; i < q.rows(); ++i) {
      knn->predict_row({q.row(i).data(), 24}, out);
      const auto expected = brute_force(x, y, q.row(i).data(), 3, false);
      for (int j = 0; j < 3; ++j) ASSERT_NEAR(out[j], expected[static_cast<std::size_t>(j)], 1e-12) << rotate << " row " << i;
    }
  }
}

TEST(Knn, RejectsMoreInputsThanItSearches) {
  auto knn = RegressorRegistry::global().create("knn");
  try {
    knn->fit(random_matrix(10, 65, 14), random_matrix(10, 3, 15), 0);
    FAIL() << "65 inputs accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("65 input dimensions; at most 64"), std::string::npos) << e.what();
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
