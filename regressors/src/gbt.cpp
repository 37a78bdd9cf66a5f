#include <cmath>
#include <cstdio>
#include <vector>

#include <dicestack/regressors/registry.hpp>

#include "xgb_call.hpp"
#include "xgb_forest.hpp"

namespace dicestack {
namespace {

using detail::BoosterPtr;
using detail::DMatrixPtr;

// A numpy-style __array_interface__ for a row-major float32 buffer (how xgboost's C API takes
// dense data and multi-column labels).
std::string array_interface(const float* data, std::size_t rows, std::size_t cols) {
  char text[192];
  std::snprintf(text, sizeof text,
                "{\"data\": [%llu, true], \"shape\": [%zu, %zu], \"typestr\": \"<f4\", \"version\": 3}",
                static_cast<unsigned long long>(reinterpret_cast<std::uintptr_t>(data)), rows, cols);
  return text;
}

// Gradient-boosted regression trees (xgboost), one model for all actions (multi-output).
// xgboost fits; predictions walk the saved trees ourselves (xgb_forest.hpp: same values,
// 10x less per-row overhead, and an edited payload is validated before it is walked).
class Gbt final : public Regressor {
 public:
  using Regressor::Regressor;

  static std::vector<ParamSpec> schema() {
    return {{"trees", ParamType::integer, "100", 1, 100000, "boosting rounds (paper VI-C: 100)", {}},
            {"max_depth", ParamType::integer, "12", 1, 64, "deepest split (paper VI-C: 12)", {}},
            {"eta", ParamType::real, "0.3", 1e-9, 1, "learning rate (xgboost's default)", {}},
            {"subsample", ParamType::real, "1", 1e-6, 1, "rows sampled per tree", {}},
            {"tree_method", ParamType::choice, "hist", 0, 0, "xgboost's split finding: hist, exact or approx", {"hist", "exact", "approx"}},
            {"threads", ParamType::integer, "1", 0, 1024, "training threads, 0 = all cores; OpenMP spin-waits make more threads slower on a busy 2-core machine (measured 88 s vs 10.5 s)", {}}};
  }

 private:
  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t seed) override {
    std::vector<float> xs(x.data(), x.data() + x.size()), ys(y.data(), y.data() + y.size());
    void* dm = nullptr;
    DICESTACK_XGB(XGDMatrixCreateFromMat(xs.data(), static_cast<bst_ulong>(x.rows()), static_cast<bst_ulong>(x.cols()),
                                         std::nanf(""), &dm));
    DMatrixPtr train(dm);
    const std::string labels = array_interface(ys.data(), static_cast<std::size_t>(y.rows()), static_cast<std::size_t>(y.cols()));
    DICESTACK_XGB(XGDMatrixSetInfoFromInterface(train.get(), "label", labels.c_str()));
    void* b = nullptr;
    DICESTACK_XGB(XGBoosterCreate(&dm, 1, &b));
    BoosterPtr booster(b);
    const std::pair<const char*, std::string> settings[] = {
        {"objective", "reg:squarederror"},
        {"tree_method", params().choice("tree_method")},
        {"max_depth", std::to_string(params().integer("max_depth"))},
        {"eta", std::to_string(params().real("eta"))},
        {"subsample", std::to_string(params().real("subsample"))},
        {"seed", std::to_string(seed & 0x7fffffff)},
        {"nthread", std::to_string(params().integer("threads"))},
        {"verbosity", "0"}};
    for (const auto& [k, v] : settings) DICESTACK_XGB(XGBoosterSetParam(booster.get(), k, v.c_str()));
    for (long long i = 0; i < params().integer("trees"); ++i)
      DICESTACK_XGB(XGBoosterUpdateOneIter(booster.get(), static_cast<int>(i), train.get()));
    bst_ulong len = 0;
    const char* buf = nullptr;
    DICESTACK_XGB(XGBoosterSaveModelToBuffer(booster.get(), "{\"format\": \"json\"}", &len, &buf));
    do_load({buf, len}, static_cast<std::size_t>(x.cols()), static_cast<std::size_t>(y.cols()));
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override { forest_.predict(x, y); }

  void do_predict(const Matrix& x, Matrix& y) const override {
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      forest_.predict({x.row(i).data(), static_cast<std::size_t>(x.cols())}, {y.row(i).data(), static_cast<std::size_t>(y.cols())});
  }

  std::string do_save() const override { return payload_; }

  void do_load(std::string_view payload, std::size_t inputs, std::size_t outputs) override {
    forest_ = detail::XgbForest::parse(payload, inputs, outputs);
    payload_ = payload;
  }

  std::string payload_;  ///< xgboost's JSON model, as saved
  detail::XgbForest forest_;
};

}  // namespace

void register_gbt(RegressorRegistry& r) {
  r.add(regressor_info<Gbt>("gbt", "gradient-boosted regression trees (xgboost, hist), one multi-output model"));
}

}  // namespace dicestack
