#include <dicestack/core/parallel.hpp>
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
            {"tol", ParamType::real, "0.001", 1e-12, 1, "solver stopping tolerance", {}},
            {"threads", ParamType::integer, "0", 0, 1024, "training threads (one SVR per action), 0 = all cores; the model is the same for any", {}}};
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
    // The per-action SVRs are independent and their solver is deterministic: fit them at once.
    std::vector<cv::Ptr<cv::ml::SVM>> models(static_cast<std::size_t>(y.cols()));
    parallel_for(models.size(), static_cast<int>(params().integer("threads")), [&](std::size_t j, int) {
      models[j] = opencv::guarded(name(), [&] {
        auto svm = cv::ml::SVM::create();
        svm->setType(cv::ml::SVM::EPS_SVR);
        svm->setKernel(cv::ml::SVM::RBF);
        svm->setC(params().real("c"));
        svm->setP(params().real("epsilon"));
        svm->setGamma(gamma);
        svm->setTermCriteria(cv::TermCriteria(cv::TermCriteria::EPS, 0, params().real("tol")));
        svm->train(samples, cv::ml::ROW_SAMPLE, opencv::to_float(y.col(static_cast<Eigen::Index>(j))));
        return svm;
      });
    });
    models_ = std::move(models);
    prepare();
  }

  // OpenCV evaluates the kernel sample by sample; the same float sum over the support vectors
  // as one vectorised matrix-vector product is faster on the hot path.
  struct Kernel {
    Eigen::MatrixXf sv;        // support vectors, one per row
    Eigen::VectorXf sv_norm2;  // |sv|^2
    Eigen::VectorXf alpha;
    float rho = 0.0f;
    float gamma = 0.0f;
  };

  void prepare() {
    kernels_.clear();
    for (const auto& m : models_) {
      Kernel k;
      const cv::Mat sv = m->getSupportVectors();
      cv::Mat alpha, index;
      k.rho = static_cast<float>(m->getDecisionFunction(0, alpha, index));
      k.gamma = static_cast<float>(m->getGamma());
      k.sv.resize(sv.rows, sv.cols);
      for (int i = 0; i < sv.rows; ++i)
        for (int j = 0; j < sv.cols; ++j) k.sv(i, j) = sv.at<float>(i, j);
      k.alpha.resize(sv.rows);
      alpha.convertTo(alpha, CV_32F);
      for (int i = 0; i < sv.rows; ++i) k.alpha[i] = alpha.at<float>(0, index.empty() ? i : index.at<int>(0, i));
      k.sv_norm2 = k.sv.rowwise().squaredNorm();
      kernels_.push_back(std::move(k));
    }
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    thread_local Eigen::VectorXf scratch;  // grows once per thread, then reused
    thread_local std::vector<float> row;  // sized once per thread (any input width), then reused
    row.assign(x.begin(), x.end());
    const Eigen::Map<const Eigen::VectorXf> v(row.data(), static_cast<Eigen::Index>(x.size()));
    const float norm2 = v.squaredNorm();
    for (std::size_t j = 0; j < y.size(); ++j) {
      const Kernel& k = kernels_[j];
      scratch.resize(k.sv.rows());
      scratch.noalias() = k.sv * v;
      scratch = ((2.0f * scratch - k.sv_norm2).array() - norm2).matrix() * k.gamma;
      y[j] = scratch.array().exp().matrix().dot(k.alpha) - k.rho;
    }
  }
  std::string do_save() const override { return opencv::save_all(models_); }
  void do_load(std::string_view payload, std::size_t, std::size_t outputs) override {
    models_ = opencv::load_all<cv::ml::SVM>(payload, outputs, name());
    prepare();
  }

  std::vector<cv::Ptr<cv::ml::SVM>> models_;
  std::vector<Kernel> kernels_;
};

}  // namespace

void register_rbf_svr(RegressorRegistry& r) {
  r.add(regressor_info<RbfSvr>("rbf_svr", "RBF-kernel epsilon-SVR (OpenCV ml), one per action"));
}

}  // namespace dicestack
