#include <dicestack/regressors/registry.hpp>

#include "opencv_models.hpp"

namespace dicestack {
namespace {

class RbfSvr final : public Regressor {
 public:
  using Regressor::Regressor;

  static std::vector<ParamSpec> schema() {
    return {{"c", ParamType::real, "1", 1e-12, 1e12, "box constraint (paper VI-C: 1.0)", {}},
            {"epsilon", ParamType::real, "0.1", 0, 1e6, "insensitive-tube half-width, standardised label units", {}},
            {"gamma", ParamType::real, "0", 0, 1e6, "RBF width; 0 means 1 / (d * var(X)) at fit time", {}},
            {"tol", ParamType::real, "0.001", 1e-12, 1, "solver stopping tolerance", {}}};
  }

 private:
  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t) override {
    double gamma = params().real("gamma");
    if (gamma == 0.0) {  // scikit-learn's "scale"
      const double mean = x.mean();
      const double var = (x.array() - mean).square().mean();
      gamma = 1.0 / (static_cast<double>(x.cols()) * (var > 0.0 ? var : 1.0));
    }
    const cv::Mat samples = opencv::to_float(x);
    models_.clear();
    for (Eigen::Index j = 0; j < y.cols(); ++j) {
      models_.push_back(opencv::guarded(name(), [&] {
        auto svm = cv::ml::SVM::create();
        svm->setType(cv::ml::SVM::EPS_SVR);
        svm->setKernel(cv::ml::SVM::RBF);
        svm->setC(params().real("c"));
        svm->setP(params().real("epsilon"));
        svm->setGamma(gamma);
        svm->setTermCriteria(cv::TermCriteria(cv::TermCriteria::EPS, 0, params().real("tol")));
        svm->train(samples, cv::ml::ROW_SAMPLE, opencv::to_float(y.col(j)));
        return svm;
      }));
    }
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override { opencv::predict_each(models_, x, y); }
  std::string do_save() const override { return opencv::save_all(models_); }
  void do_load(std::string_view payload, std::size_t, std::size_t outputs) override {
    models_ = opencv::load_all<cv::ml::SVM>(payload, outputs, name());
  }

  std::vector<cv::Ptr<cv::ml::SVM>> models_;
};

}  // namespace

void register_rbf_svr(RegressorRegistry& r) {
  r.add(regressor_info<RbfSvr>("rbf_svr", "RBF-kernel epsilon-SVR (OpenCV ml), one per action"));
}

}  // namespace dicestack
