#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

#include "opencv_models.hpp"

namespace dicestack {
namespace {

class RandomForest final : public Regressor {
 public:
  using Regressor::Regressor;

  static std::vector<ParamSpec> schema() {
    return {{"trees", ParamType::integer, "8", 1, 100000, "number of trees (paper VI-C: 8)", {}},
            {"max_depth", ParamType::integer, "12", 1, 64, "deepest split (paper VI-C: 12)", {}},
            {"min_samples", ParamType::integer, "2", 1, 1e9, "fewest rows a node needs to split", {}},
            {"features", ParamType::integer, "0", 0, 1e6, "features tried per split; 0 means all (scikit-learn's default)", {}}};
  }

 private:
  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t seed) override {
    const cv::Mat samples = opencv::to_float(x);
    models_.clear();
    for (Eigen::Index j = 0; j < y.cols(); ++j) {
      models_.push_back(opencv::guarded(name(), [&] {
        // OpenCV draws bootstrap samples from its thread-local generator: seed it per output.
        cv::theRNG().state = derive_seed(seed, static_cast<std::uint64_t>(j)) | 1;
        auto rf = cv::ml::RTrees::create();
        rf->setMaxDepth(static_cast<int>(params().integer("max_depth")));
        rf->setMinSampleCount(static_cast<int>(params().integer("min_samples")));
        rf->setRegressionAccuracy(0.0f);
        rf->setUseSurrogates(false);
        rf->setCVFolds(0);
        rf->setCalculateVarImportance(false);
        const auto features = params().integer("features");
        rf->setActiveVarCount(static_cast<int>(features == 0 ? x.cols() : features));
        rf->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, static_cast<int>(params().integer("trees")), 0));
        rf->train(samples, cv::ml::ROW_SAMPLE, opencv::to_float(y.col(j)));
        return rf;
      }));
    }
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override { opencv::predict_each(models_, x, y); }
  std::string do_save() const override { return opencv::save_all(models_); }
  void do_load(std::string_view payload, std::size_t, std::size_t outputs) override {
    models_ = opencv::load_all<cv::ml::RTrees>(payload, outputs, name());
  }

  std::vector<cv::Ptr<cv::ml::RTrees>> models_;
};

}  // namespace

void register_random_forest(RegressorRegistry& r) {
  r.add(regressor_info<RandomForest>("random_forest", "random forest of regression trees (OpenCV ml), one per action"));
}

}  // namespace dicestack
