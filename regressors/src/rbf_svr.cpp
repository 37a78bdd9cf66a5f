#include <cmath>
#include <set>

#include <dicestack/core/parallel.hpp>
#include <dicestack/regressors/registry.hpp>

#include "opencv_models.hpp"

namespace dicestack {
namespace {

// A stored model, checked before OpenCV's SVM::read sees it: that reader trusts its counts (a
// negative sv_count resizes a vector to 2^64 - 1 entries, a large var_count allocates
// gigabytes) and reads keys an RBF epsilon-SVR never has (class weights as whole matrices).
void check_stored_svm(const cv::FileNode& n, std::size_t inputs, const std::string& where) {
  auto fail = [&](const std::string& what) { throw InputError(where + ": " + what); };
  auto is_number = [](const cv::FileNode& v) { return v.isInt() || v.isReal(); };
  if (!n.isMap()) fail("is not an OpenCV model");
  static const std::set<std::string> known{"format", "svmType", "kernel", "C", "p", "term_criteria",
                                           "var_count", "sv_total", "support_vectors", "decision_functions"};
  for (const auto& key : n.keys())
    if (!known.contains(key)) fail("has \"" + key.substr(0, 40) + "\", which an RBF epsilon-SVR never has");
  if (n["svmType"].string() != "EPS_SVR") fail("\"svmType\" must be EPS_SVR");
  const cv::FileNode kernel = n["kernel"];
  if (!kernel.isMap() || kernel["type"].string() != "RBF" || !is_number(kernel["gamma"]))
    fail("\"kernel\" must be RBF with a gamma");
  if (!n["var_count"].isInt() || static_cast<int>(n["var_count"]) != static_cast<int>(inputs))
    fail("\"var_count\" must be " + std::to_string(inputs) + " (the header's input width)");
  const cv::FileNode svs = n["support_vectors"];
  const int total = n["sv_total"].isInt() ? static_cast<int>(n["sv_total"]) : -1;
  if (!svs.isSeq() || total < 1 || svs.size() != static_cast<std::size_t>(total))
    fail("\"sv_total\" must be the number of support vectors listed (at least 1)");
  for (const auto& sv : svs) {
    if (!sv.isSeq() || sv.size() != inputs) fail("a support vector does not hold " + std::to_string(inputs) + " numbers");
    for (const auto& v : sv)
      if (!is_number(v)) fail("a support vector holds something that is not a number");
  }
  const cv::FileNode dfs = n["decision_functions"];
  if (!dfs.isSeq() || dfs.size() != 1) fail("\"decision_functions\" must hold exactly one function");
  const cv::FileNode df = dfs[0];
  if (!df.isMap() || !df["sv_count"].isInt() || static_cast<int>(df["sv_count"]) != total || !is_number(df["rho"]))
    fail("the decision function must have sv_count = sv_total and a rho");
  const cv::FileNode alpha = df["alpha"];
  if (!alpha.isSeq() || alpha.size() != static_cast<std::size_t>(total))
    fail("the decision function must hold one alpha per support vector");
  for (const auto& v : alpha)
    if (!is_number(v)) fail("an alpha is not a number");
}

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
    prepare(static_cast<std::size_t>(x.cols()));
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

  // Also checks what a stored model gave OpenCV: shapes, and finite numbers within float range.
  void prepare(std::size_t inputs) {
    std::vector<Kernel> kernels;
    for (std::size_t o = 0; o < models_.size(); ++o) opencv::guarded(name() + ": model " + std::to_string(o), [&] {
      const cv::ml::SVM& m = *models_[o];
      auto fail = [&](const std::string& what) { throw InputError(name() + ": model " + std::to_string(o) + ": " + what); };
      Kernel k;
      const cv::Mat sv = m.getSupportVectors();
      if (sv.type() != CV_32F || sv.rows < 1 || sv.cols != static_cast<int>(inputs) || !cv::checkRange(sv))
        fail("support vectors must be finite " + std::to_string(inputs) + "-wide rows");
      cv::Mat alpha, index;
      const double rho = m.getDecisionFunction(0, alpha, index), gamma = m.getGamma();
      auto is_float = [](double v) { return std::isfinite(v) && std::abs(v) <= 3e38; };
      if (!is_float(rho) || !is_float(gamma) || !(gamma > 0.0)) fail("rho and gamma must be finite and gamma > 0");
      if (alpha.type() != CV_64F || alpha.total() != static_cast<std::size_t>(sv.rows) ||
          (!index.empty() && (index.type() != CV_32S || index.total() != alpha.total())))
        fail("the decision function must hold one alpha per support vector");
      for (std::size_t i = 0; i < alpha.total(); ++i)
        if (!is_float(alpha.at<double>(0, static_cast<int>(i))) ||
            (!index.empty() && (index.at<int>(0, static_cast<int>(i)) < 0 || index.at<int>(0, static_cast<int>(i)) >= sv.rows)))
          fail("alpha " + std::to_string(i) + " or its support vector index is out of range");
      k.rho = static_cast<float>(rho);
      k.gamma = static_cast<float>(gamma);
      k.sv.resize(sv.rows, sv.cols);
      for (int i = 0; i < sv.rows; ++i)
        for (int j = 0; j < sv.cols; ++j) k.sv(i, j) = sv.at<float>(i, j);
      k.alpha.resize(sv.rows);
      alpha.convertTo(alpha, CV_32F);
      for (int i = 0; i < sv.rows; ++i) k.alpha[i] = alpha.at<float>(0, index.empty() ? i : index.at<int>(0, i));
      k.sv_norm2 = k.sv.rowwise().squaredNorm();
      kernels.push_back(std::move(k));
    });
    kernels_ = std::move(kernels);
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
    models_ = opencv::load_all<cv::ml::SVM>(payload, outputs, name(), [&](const cv::FileNode& n, const std::string& where) {
      check_stored_svm(n, inputs, where);
    });
    prepare(inputs);
  }

  std::vector<cv::Ptr<cv::ml::SVM>> models_;
  std::vector<Kernel> kernels_;
};

}  // namespace

void register_rbf_svr(RegressorRegistry& r) {
  r.add(regressor_info<RbfSvr>("rbf_svr", "RBF-kernel epsilon-SVR (OpenCV ml), one per action"));
}

}  // namespace dicestack
