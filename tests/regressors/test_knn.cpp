#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

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

TEST(Knn, PrincipalAxesSearchMatchesBruteForceOnCorrelatedStates) {
  // States on a few correlated directions (as the dice move with the cup): the rotated and the
  // unrotated tree find the brute-force neighbours.
  const Matrix mix = random_matrix(4, 24, 8);
  const Matrix x = random_matrix(1000, 4, 9) * mix + 0.01 * random_matrix(1000, 24, 10);
  const Matrix q = random_matrix(40, 4, 11) * mix + 0.01 * random_matrix(40, 24, 12);
  const Matrix y = random_matrix(1000, 3, 13);
  for (const char* rotate : {"rotate=true", "rotate=false"}) {
    auto knn = RegressorRegistry::global().create("knn", {"k=3", rotate});
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

namespace dicestack {
namespace {

TEST(RbfSvr, FastKernelSumMatchesOpenCv) {
  // The hot path sums the kernel over the support vectors itself; a model reloaded through
  // OpenCV's YAML predicts the same as OpenCV's own evaluation of that YAML would.
  const Matrix x = random_matrix(300, 24, 6), probe = random_matrix(20, 24, 7);
  Matrix y(300, 3);
  for (Eigen::Index i = 0; i < 300; ++i) y.row(i) << std::sin(x(i, 0)), x(i, 1) * x(i, 2), std::cos(x(i, 3));
  auto svr = RegressorRegistry::global().create("rbf_svr");
  svr->fit(x, y, 0);
  const Matrix fast = svr->predict(probe);
  const std::string payload = svr->save_payload();
  const auto models = nlohmann::json::parse(payload)["models"];
  for (int j = 0; j < 3; ++j) {
    cv::FileStorage fs(models[static_cast<std::size_t>(j)].get<std::string>(), cv::FileStorage::READ | cv::FileStorage::MEMORY);
    auto svm = cv::ml::SVM::create();
    svm->read(fs.root());
    for (Eigen::Index i = 0; i < probe.rows(); ++i) {
      cv::Mat row(1, 24, CV_32F);
      for (int c = 0; c < 24; ++c) row.at<float>(0, c) = static_cast<float>(probe(i, c));
      EXPECT_NEAR(fast(i, j), svm->predict(row), 1e-4) << "output " << j << " row " << i;
    }
  }
}

}  // namespace
}  // namespace dicestack
