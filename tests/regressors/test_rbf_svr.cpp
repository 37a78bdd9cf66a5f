#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include <dicestack/regressors/registry.hpp>
#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using test::random_matrix;

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
