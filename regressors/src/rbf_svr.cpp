#include <cmath>

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
      // Coefficient i belongs to support vector index[i] (the identity in OpenCV's regression).
      k.alpha = Eigen::VectorXf::Zero(sv.rows);
      alpha.convertTo(alpha, CV_32F);
      for (int i = 0; i < alpha.cols; ++i) k.alpha[index.empty() ? i : index.at<int>(0, i)] += alpha.at<float>(0, i);
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
  void do_load(std::string_view payload, std::size_t inputs, std::size_t outputs) override {
    auto models = opencv::load_all<cv::ml::SVM>(payload, outputs, name(), [&](const cv::FileNode& root, std::size_t j) {
      check_counts(root, j);
    });
    for (std::size_t j = 0; j < models.size(); ++j) check_loaded(*models[j], j, inputs);
    models_ = std::move(models);
    prepare();
  }

  // The counts the file states against the lists it holds: OpenCV pads a short coefficient
  // list with zeros and ignores extra support vectors.
  void check_counts(const cv::FileNode& root, std::size_t j) const {
    const std::string who = name() + ": model payload, model " + std::to_string(j) + ": ";
    const cv::FileNode sv = root["support_vectors"], df = root["decision_functions"];
    if (!root["sv_total"].isInt() || !sv.isSeq() || static_cast<std::size_t>(static_cast<int>(root["sv_total"])) != sv.size())
      throw InputError(who + "\"sv_total\" must be an integer equal to the number of support vectors (" +
                       std::to_string(sv.size()) + ")");
    if (!df.isSeq() || df.size() != 1) throw InputError(who + "must hold one decision function");
    const cv::FileNode f = df[0];
    if (!f["sv_count"].isInt() || !f["alpha"].isSeq() || static_cast<int>(f["sv_count"]) != static_cast<int>(sv.size()) ||
        f["alpha"].size() != sv.size())
      throw InputError(who + "\"sv_count\" and \"alpha\" must both count the " + std::to_string(sv.size()) +
                       " support vectors");
  }

  // What prepare() and the kernel sum rely on, checked against the counts OpenCV read: an
  // epsilon-SVR with an RBF kernel, support vectors as wide as the input, one coefficient per
  // support vector, indices in range, every number finite.
  void check_loaded(const cv::ml::SVM& m, std::size_t j, std::size_t inputs) const {
    const std::string who = name() + ": model payload, model " + std::to_string(j) + ": ";
    if (m.getType() != cv::ml::SVM::EPS_SVR || m.getKernelType() != cv::ml::SVM::RBF)
      throw InputError(who + "is not an epsilon-SVR with an RBF kernel");
    const double gamma = m.getGamma();
    if (!std::isfinite(gamma) || gamma <= 0.0) throw InputError(who + "gamma must be a positive finite number");
    const cv::Mat sv = m.getSupportVectors();
    if (sv.empty() || sv.type() != CV_32F || sv.cols != static_cast<int>(inputs))
      throw InputError(who + "holds " + std::to_string(sv.cols) + "-wide support vectors, expected " + std::to_string(inputs));
    if (!cv::checkRange(sv)) throw InputError(who + "holds a support vector with NaN or infinity");
    cv::Mat alpha, index;
    const double rho = opencv::guarded(name(), [&] { return m.getDecisionFunction(0, alpha, index); });
    if (!std::isfinite(rho)) throw InputError(who + "rho must be finite");
    if (alpha.empty() || alpha.rows != 1 || (alpha.type() != CV_64F && alpha.type() != CV_32F))
      throw InputError(who + "holds no coefficient row");
    // A regression's single decision function uses every support vector once.
    const int count = sv.rows;
    if (alpha.cols != count || (!index.empty() && (index.rows != 1 || index.cols != count || index.type() != CV_32S)))
      throw InputError(who + "holds " + std::to_string(alpha.cols) + " coefficients for " + std::to_string(count) +
                       " support vectors");
    for (int i = 0; !index.empty() && i < index.cols; ++i)
      if (index.at<int>(0, i) < 0 || index.at<int>(0, i) >= sv.rows)
        throw InputError(who + "support vector index " + std::to_string(index.at<int>(0, i)) + " is out of range (" +
                         std::to_string(sv.rows) + " vectors)");
    if (!cv::checkRange(alpha)) throw InputError(who + "holds a coefficient with NaN or infinity");
  }

  std::vector<cv::Ptr<cv::ml::SVM>> models_;
  std::vector<Kernel> kernels_;
};

}  // namespace

void register_rbf_svr(RegressorRegistry& r) {
  r.add(regressor_info<RbfSvr>("rbf_svr", "RBF-kernel epsilon-SVR (OpenCV ml), one per action"));
}

}  // namespace dicestack
