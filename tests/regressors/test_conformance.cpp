// One suite run over every registered regressor, plugins included (STYLE 13).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/regressors/registry.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/regressors.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;
using test::inputs;
using test::registered_with_plugin;
using test::target;

class Conformance : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<Regressor> make(const std::vector<std::string>& sets = {}) const {
    return RegressorRegistry::global().create(GetParam(), sets);
  }
};

TEST_P(Conformance, ShapesAndRowEqualsBatch) {
  const Matrix x = inputs(400, 24, 1), probe = inputs(20, 24, 2);
  auto r = make();
  EXPECT_FALSE(r->fitted());
  r->fit(x, target(x, false), 3);
  ASSERT_TRUE(r->fitted());
  EXPECT_EQ(r->input_dim(), 24u);
  EXPECT_EQ(r->output_dim(), 3u);
  const Matrix batch = r->predict(probe);
  ASSERT_EQ(batch.rows(), 20);
  ASSERT_EQ(batch.cols(), 3);
  double row[3];
  for (Eigen::Index i = 0; i < probe.rows(); ++i) {
    r->predict_row({probe.row(i).data(), 24}, row);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(row[j], batch(i, j), 1e-9 * (1.0 + std::abs(row[j]))) << "row " << i;
  }
}

TEST_P(Conformance, WideInputsArePredictedOrRefusedByName) {
  // 80 input columns: more than any fixed-size scratch row a hot path might keep.
  const Matrix x = inputs(200, 80, 11), probe = inputs(5, 80, 12);
  auto r = make();
  try {
    r->fit(x, target(x, false), 3);
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(GetParam() + ": 80 input dimensions"));
    return;
  }
  const Matrix batch = r->predict(probe);
  double row[3];
  for (Eigen::Index i = 0; i < probe.rows(); ++i) {
    r->predict_row({probe.row(i).data(), 80}, row);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(row[j], batch(i, j), 1e-9 * (1.0 + std::abs(row[j]))) << "row " << i;
  }
}

TEST_P(Conformance, SaveThenLoadPredictsIdentically) {
  const Matrix x = inputs(300, 24, 4), probe = inputs(15, 24, 5);
  auto r = make();
  r->fit(x, target(x, false), 6);
  const std::string payload = r->save_payload();
  auto back = make();
  back->load_payload(payload, 24, 3);
  EXPECT_EQ(back->predict(probe), r->predict(probe));
  // Through a model file, with standardisers and checksum.
  Model model = Model::train(make(), x, target(x, false), 6);
  const fs::path path = test::scratch_path("dicestack_conformance_" + GetParam() + ".dsm");
  save_model(model, path);
  const Model loaded = load_model(path);
  EXPECT_EQ(loaded.predict(probe), model.predict(probe));
  State s{};
  for (std::size_t j = 0; j < kStateDim; ++j) s[j] = probe(0, static_cast<Eigen::Index>(j));
  EXPECT_EQ(loaded.act(s), model.act(s));
  fs::remove(path);
}

TEST_P(Conformance, SameSeedSameModel) {
  const Matrix x = inputs(300, 24, 7), probe = inputs(10, 24, 8);
  auto a = make(), b = make();
  a->fit(x, target(x, false), 42);
  b->fit(x, target(x, false), 42);
  EXPECT_EQ(a->predict(probe), b->predict(probe));
}

TEST_P(Conformance, RejectsBadInputWithItsName) {
  const std::string name = GetParam();
  Matrix x = inputs(50, 24, 9);
  const Matrix y = target(x, true);
  auto r = make();
  EXPECT_THAT(test::error_of([&] { r->predict(x); }), HasSubstr(name + ": predict called before fit"));
  x(7, 3) = std::nan("");
  EXPECT_THAT(test::error_of([&] { r->fit(x, y, 1); }), HasSubstr(name + ": input row 7 holds NaN"));
  x(7, 3) = 0.0;
  EXPECT_THAT(test::error_of([&] { r->fit(x, Matrix(49, 3), 1); }), HasSubstr(name + ": 50 input rows but 49 labels"));
  r->fit(x, y, 1);
  double out[3];
  const std::vector<double> short_row(23, 0.0);
  EXPECT_THAT(test::error_of([&] { r->predict_row(short_row, out); }), HasSubstr(name + ": predict_row got 23 inputs"));
  EXPECT_THROW(r->predict(Matrix(2, 25)), InputError);
  EXPECT_THAT(test::error_of([&] { make({"no_such_parameter=1"}); }),
              HasSubstr(name + ": unknown parameter \"no_such_parameter\""));
  const auto& schema = RegressorRegistry::global().info(name).params;
  for (const auto& p : schema) {
    if (p.type == dicestack::ParamType::integer || p.type == dicestack::ParamType::real) {
      const std::string msg = test::error_of([&] { make({p.name + "=1e308x"}); });
      EXPECT_THAT(msg, HasSubstr(name + ": parameter \"" + p.name + "\" expects"));
      if (p.min > -1e300) {
        const std::string low = test::error_of([&] { make({p.name + "=-1e301"}); });
        EXPECT_THAT(low, HasSubstr(name + ": parameter \"" + p.name + "\""));
        EXPECT_THAT(low, HasSubstr("-1e301"));
      }
    }
  }
}

TEST_P(Conformance, LearnsAKnownFunction) {
  const std::string name = GetParam();
  const bool linear = name == "linear_svr" || name == "ridge";
  const Matrix x = inputs(1500, 24, 10), test_x = inputs(300, 24, 11);
  // A smooth function of few inputs that varies along the data's spread.
  Matrix xs = x, ts = test_x;
  xs.rightCols(16).setZero();
  ts.rightCols(16).setZero();
  auto r = make();
  r->fit(xs, target(xs, linear), 12);
  const Matrix truth = target(ts, linear), pred = r->predict(ts);
  const double err = (pred - truth).cwiseAbs().mean();
  const double spread = (truth.rowwise() - truth.colwise().mean()).cwiseAbs().mean();
  EXPECT_LT(err, (linear ? 0.05 : 0.45) * spread) << name << ": mean |error| " << err << " vs spread " << spread;
}

INSTANTIATE_TEST_SUITE_P(AllRegistered, Conformance, ::testing::ValuesIn(registered_with_plugin()),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace dicestack
