#include <cmath>
#include <cstdio>
#include <vector>

#include <dicestack/regressors/registry.hpp>

#include "xgb_call.hpp"

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
    booster_ = std::move(booster);
    ready_for_rows();
  }

  // One thread per prediction: predict_row is called from many threads at once, one row each.
  void ready_for_rows() { DICESTACK_XGB(XGBoosterSetParam(booster_.get(), "nthread", "1")); }

  void predict_rows(const float* data, std::size_t rows, std::size_t cols, double* out, std::size_t outputs) const {
    const std::string values = array_interface(data, rows, cols);
    static const char* config =
        "{\"type\": 0, \"training\": false, \"iteration_begin\": 0, \"iteration_end\": 0, \"strict_shape\": true, \"cache_id\": 0, "
        "\"missing\": NaN}";
    const bst_ulong* shape = nullptr;
    bst_ulong dims = 0;
    const float* result = nullptr;
    DICESTACK_XGB(XGBoosterPredictFromDense(booster_.get(), values.c_str(), config, nullptr, &shape, &dims, &result));
    for (std::size_t i = 0; i < rows * outputs; ++i) out[i] = result[i];
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    thread_local std::vector<float> row;  // sized once per thread (any input width), then reused
    row.assign(x.begin(), x.end());
    predict_rows(row.data(), 1, x.size(), y.data(), y.size());
  }

  void do_predict(const Matrix& x, Matrix& y) const override {
    const std::vector<float> xs(x.data(), x.data() + x.size());
    predict_rows(xs.data(), static_cast<std::size_t>(x.rows()), static_cast<std::size_t>(x.cols()), y.data(),
                 static_cast<std::size_t>(y.cols()));
  }

  std::string do_save() const override {
    bst_ulong len = 0;
    const char* buf = nullptr;
    DICESTACK_XGB(XGBoosterSaveModelToBuffer(booster_.get(), "{\"format\": \"json\"}", &len, &buf));
    return std::string(buf, len);
  }

  void do_load(std::string_view payload, std::size_t, std::size_t) override {
    void* b = nullptr;
    DICESTACK_XGB(XGBoosterCreate(nullptr, 0, &b));
    BoosterPtr booster(b);
    DICESTACK_XGB(XGBoosterLoadModelFromBuffer(booster.get(), payload.data(), payload.size()));
    booster_ = std::move(booster);
    ready_for_rows();
  }

  BoosterPtr booster_;
};

}  // namespace

void register_gbt(RegressorRegistry& r) {
  r.add(regressor_info<Gbt>("gbt", "gradient-boosted regression trees (xgboost, hist), one multi-output model"));
}

}  // namespace dicestack
