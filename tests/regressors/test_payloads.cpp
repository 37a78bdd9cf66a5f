// Payload loaders called directly, past the model file's checksums, with payloads edited the
// way fuzz/ found them to fail (or as its harnesses showed they could): each is refused with an
// InputError naming the regressor, the stored model and the field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

Matrix uniform_rows(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  Rng rng(seed);
  Matrix m(n, d);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = rng.uniform(-1.0, 1.0);
  return m;
}

std::string fitted_payload(const std::string& name, Eigen::Index inputs, Eigen::Index outputs,
                           const std::vector<std::string>& settings = {}) {
  const Matrix x = uniform_rows(20, inputs, 1), y = uniform_rows(20, outputs, 2);
  auto r = RegressorRegistry::global().create(name, settings);
  r->fit(x, y, 3);
  return r->save_payload();
}

// What load_payload throws for `payload`, or "" if it loads.
std::string load_error(const std::string& name, const std::string& payload, std::size_t inputs, std::size_t outputs,
                       const std::vector<std::string>& settings = {}) {
  auto r = RegressorRegistry::global().create(name, settings);
  try {
    r->load_payload(payload, inputs, outputs);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// rbf_svr's payload with the YAML of model `model` passed through `edit`.
std::string edit_svm(const std::string& payload, std::size_t model, const std::function<void(std::string&)>& edit) {
  auto j = nlohmann::json::parse(payload);
  std::string yaml = j["models"][model].get<std::string>();
  edit(yaml);
  j["models"][model] = yaml;
  return j.dump();
}

// Replaces the line holding `key:` (the first one) with `line`.
void replace_line(std::string& yaml, const std::string& key, const std::string& line) {
  const auto at = yaml.find(key + ":");
  ASSERT_NE(at, std::string::npos) << key;
  const auto begin = yaml.rfind('\n', at) + 1, end = yaml.find('\n', at);
  yaml.replace(begin, end - begin, line);
}

TEST(Payloads, RbfSvrModelsAreCheckedBeforeOpenCvReadsThem) {
  const std::string good = fitted_payload("rbf_svr", 4, 2);
  ASSERT_EQ(load_error("rbf_svr", good, 4, 2), "");
  auto error = [&](std::size_t model, const std::string& key, const std::string& line, std::size_t inputs = 4) {
    return load_error("rbf_svr", edit_svm(good, model, [&](std::string& y) { replace_line(y, key, line); }), inputs, 2);
  };
  // Found by fuzz/: without sv_count, OpenCV's own cv::Exception escaped from getDecisionFunction.
  EXPECT_THAT(error(1, "sv_count", "      rho_was_sv_count: 1"),
              HasSubstr("rbf_svr: model 1: the decision function must have sv_count = sv_total"));
  // A negative count resized OpenCV's vectors to 2^64 - 1 entries (std::length_error).
  EXPECT_THAT(error(0, "sv_count", "      sv_count: -1"), HasSubstr("rbf_svr: model 0: the decision function"));
  // A model of another width was summed against the row as if it had the header's.
  EXPECT_THAT(load_error("rbf_svr", good, 3, 2), HasSubstr("rbf_svr: model 0: \"var_count\" must be 3"));
  EXPECT_THAT(error(1, "var_count", "var_count: 1000000000"), HasSubstr("rbf_svr: model 1: \"var_count\" must be 4"));
  // Keys an RBF epsilon-SVR never has; OpenCV reads class weights as a whole matrix.
  EXPECT_THAT(error(0, "C", "class_weights: !!opencv-matrix\n   rows: 100000\n   cols: 100000\n   dt: d\n   data: [ 1. ]"),
              HasSubstr("rbf_svr: model 0: has \"class_weights\""));
  // The hot path sums an RBF kernel: any other kernel or type would be evaluated wrongly.
  EXPECT_THAT(error(0, "type", "   type: LINEAR"), HasSubstr("\"kernel\" must be RBF"));
  EXPECT_THAT(error(0, "svmType", "svmType: NU_SVR"), HasSubstr("\"svmType\" must be EPS_SVR"));
  EXPECT_THAT(error(1, "sv_total", "sv_total: 3"), HasSubstr("rbf_svr: model 1: \"sv_total\" must be the number"));
  EXPECT_THAT(error(0, "gamma", "   gamma: .nan"), HasSubstr("rbf_svr: model 0: rho and gamma must be finite"));
  EXPECT_THAT(error(0, "rho", "      rho: 1e39"), HasSubstr("rbf_svr: model 0: rho and gamma must be finite"));
  EXPECT_THAT(load_error("rbf_svr", edit_svm(good, 1, [](std::string& y) { y = "<?xml version=\"1.0\"?><opencv_storage/>"; }), 4, 2),
              HasSubstr("rbf_svr: model 1 is not OpenCV YAML"));
  // Found by fuzz/: OpenCV 4.6's YAML parser throws std::length_error (not cv::Exception) on an
  // empty key inside a nested map; it escaped as a non-dicestack exception.
  EXPECT_THAT(load_error("rbf_svr", edit_svm(good, 0, [](std::string& y) { y = "%YAML:1.0\nk:\n t: 1\n :\n"; }), 4, 2),
              HasSubstr("rbf_svr: model 0: OpenCV failed: "));
}

// The matrix payload layout of knn, linear_svr, mlp and random_forest (regressors/src/payload.hpp).
std::string matrices(const std::vector<Matrix>& ms) {
  std::string out = "DSMATv1\n";
  auto put = [&](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
  const std::uint64_t count = ms.size();
  put(&count, sizeof count);
  for (const Matrix& m : ms) {
    const std::uint64_t shape[2] = {static_cast<std::uint64_t>(m.rows()), static_cast<std::uint64_t>(m.cols())};
    put(shape, sizeof shape);
    put(m.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
  }
  return out;
}

TEST(Payloads, MlpRefusesRowsWiderThanItsStackBuffers) {
  // predict_row copies the row into a 1024-wide buffer on the stack: 1100 inputs overflowed it.
  const std::vector<std::string> small{"layers=1", "width=2"};
  const std::string wide = matrices({Matrix::Constant(2, 1100, 0.01), Matrix::Zero(1, 2), Matrix::Ones(3, 2), Matrix::Zero(1, 3)});
  EXPECT_THAT(load_error("mlp", wide, 1100, 3, small), HasSubstr("mlp: 1100 input dimensions and 3 outputs; at most 1024"));
  auto r = RegressorRegistry::global().create("mlp", small);
  EXPECT_THAT(test::error_of([&] { r->fit(uniform_rows(4, 1100, 1), uniform_rows(4, 3, 2), 1); }),
              HasSubstr("mlp: 1100 input dimensions"));
  EXPECT_EQ(load_error("mlp", matrices({Matrix::Constant(2, 24, 0.01), Matrix::Zero(1, 2), Matrix::Ones(3, 2), Matrix::Zero(1, 3)}),
                       24, 3, small),
            "");
}

}  // namespace
}  // namespace dicestack
