// gbt predicts by walking xgboost's saved trees itself: the same values as xgboost, and an
// edited payload is refused with the tree and node named (it used to crash xgboost's predictor).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>
#include <xgboost/c_api.h>

#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

Matrix rows(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  Rng rng(seed);
  Matrix x(n, d);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < d; ++j) x(i, j) = rng.normal();
  return x;
}

Matrix gbt_labels(const Matrix& x) {
  Matrix y(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    y.row(i) << std::sin(x(i, 0)) + x(i, 1) * x(i, 2), x(i, 3) > 0 ? 1.0 : -0.5, x(i, x.cols() - 1);
  return y;
}

std::unique_ptr<Regressor> fitted() {
  auto r = RegressorRegistry::global().create("gbt", {"trees=20", "max_depth=6"});
  const Matrix x = rows(600, 27, 1);
  r->fit(x, gbt_labels(x), 3);
  return r;
}

TEST(Gbt, PredictsWhatXgboostPredictsFromTheSamePayload) {
  const auto r = fitted();
  const std::string payload = r->save_payload();
  BoosterHandle booster = nullptr;
  ASSERT_EQ(XGBoosterCreate(nullptr, 0, &booster), 0);
  ASSERT_EQ(XGBoosterLoadModelFromBuffer(booster, payload.data(), payload.size()), 0);
  const Matrix probe = rows(200, 27, 2);
  std::vector<float> xs(probe.data(), probe.data() + probe.size());
  DMatrixHandle dm = nullptr;
  ASSERT_EQ(XGDMatrixCreateFromMat(xs.data(), 200, 27, std::nanf(""), &dm), 0);
  bst_ulong len = 0;
  const float* want = nullptr;
  ASSERT_EQ(XGBoosterPredict(booster, dm, 0, 0, 0, &len, &want), 0);
  ASSERT_EQ(len, 600u);
  const Matrix got = r->predict(probe);
  for (Eigen::Index i = 0; i < 200; ++i)
    for (Eigen::Index k = 0; k < 3; ++k)
      EXPECT_EQ(static_cast<float>(got(i, k)), want[i * 3 + k]) << "row " << i << " output " << k;
  XGDMatrixFree(dm);
  XGBoosterFree(booster);
}

// The payload with one edit, loaded into a fresh gbt.
std::string load_edited(const std::function<void(nlohmann::json&)>& edit, std::size_t outputs = 3) {
  nlohmann::json j = nlohmann::json::parse(fitted()->save_payload());
  edit(j);
  auto r = RegressorRegistry::global().create("gbt");
  return test::error_of([&] { r->load_payload(j.dump(), 27, outputs); });
}

TEST(Gbt, EditedPayloadsAreRefusedBeforeAnyWalk) {
  auto tree = [](nlohmann::json& j, std::size_t t) -> nlohmann::json& {
    return j["learner"]["gradient_booster"]["model"]["trees"][t];
  };
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { tree(j, 2)["left_children"][0] = 100000; }),
              HasSubstr("gbt: tree 2: node 0: child 100000 is out of range"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { tree(j, 1)["right_children"][0] = 0; }),
              HasSubstr("gbt: tree 1: node 0: child 0 is out of range"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) {
                auto& t = tree(j, 0);
                t["left_children"][1] = t["left_children"][0];  // node 1 points back to node 0's child
                t["right_children"][1] = t["right_children"][0];
              }),
              HasSubstr("reached twice; not a tree"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { tree(j, 2)["left_children"][0] = 1.5; }),
              HasSubstr("gbt: tree 2: node 0: left child is not an integer index, got 1.5"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { tree(j, 2)["right_children"][0] = 1e30; }),
              HasSubstr("right child is not an integer index"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { j["learner"]["learner_model_param"]["num_target"] = "-3"; }),
              HasSubstr("num_target is not a count, got \"-3\""));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { tree(j, 0)["split_indices"][0] = 999; }),
              HasSubstr("gbt: tree 0: node 0: splits on feature 999 of 27"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { j["learner"]["gradient_booster"]["model"]["tree_info"][4] = 7; }),
              HasSubstr("gbt: tree 4: target 7 is not below 3"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { j["learner"]["gradient_booster"]["model"]["tree_info"].push_back(0); }),
              HasSubstr("tree_info lists 61 trees, the model holds 60"));
  EXPECT_THAT(load_edited([](nlohmann::json&) {}, 1), HasSubstr("the model has 3 targets, the header says 1"));
  EXPECT_THAT(load_edited([&](nlohmann::json& j) { tree(j, 0)["split_conditions"].erase(0); }),
              HasSubstr("gbt: tree 0: its node arrays differ in length"));
  auto r = RegressorRegistry::global().create("gbt");
  EXPECT_THROW(r->load_payload("{\"learner\": 5}", 27, 3), InputError);
  EXPECT_THROW(r->load_payload("not json", 27, 3), InputError);
}

}  // namespace
}  // namespace dicestack
