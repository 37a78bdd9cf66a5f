#pragma once
// Plumbing for the OpenCV ml regressor (rbf_svr): one model per action dimension (OpenCV's SVR
// takes a single response column), cv::Exception turned into InputError at
// this edge with the regressor's name, and models saved as OpenCV YAML inside one JSON payload.
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/regressors/regressor.hpp>

namespace dicestack::opencv {

/// Runs fn, rethrowing OpenCV's errors as InputError("<who>: OpenCV: ..."). OpenCV also lets
/// standard exceptions out (its YAML parser throws std::length_error on an empty key in a
/// nested map); those become InputError too. Our own errors pass through unchanged.
template <class F>
auto guarded(const std::string& who, F&& fn) {
  try {
    return fn();
  } catch (const Error&) {
    throw;
  } catch (const cv::Exception& e) {
    throw InputError(who + ": OpenCV: " + e.err + " (in " + e.func + ")");
  } catch (const std::exception& e) {
    throw InputError(who + ": OpenCV failed: " + e.what());
  }
}

inline cv::Mat to_float(const Matrix& m) {
  cv::Mat out(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_32F);
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) out.at<float>(static_cast<int>(i), static_cast<int>(j)) = static_cast<float>(m(i, j));
  return out;
}

inline std::string save_yaml(const cv::Ptr<cv::ml::StatModel>& model) {
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  model->write(fs);
  return fs.releaseAndGetString();
}

/// Payload: {"models": [yaml, ...]}, one per output.
template <class T>
std::string save_all(const std::vector<cv::Ptr<T>>& models) {
  nlohmann::json j;
  for (const auto& m : models) j["models"].push_back(save_yaml(m));
  return j.dump();
}

/// Reads save_all's payload: `outputs` OpenCV YAML models. `check` sees each model's parsed
/// YAML (and "<who>: model <i>" for its messages) before OpenCV reads it: OpenCV's readers trust
/// the counts they find, so a caller checks them against what the text holds.
template <class T>
std::vector<cv::Ptr<T>> load_all(std::string_view payload, std::size_t outputs, const std::string& who,
                                 const std::function<void(const cv::FileNode&, const std::string&)>& check) {
  nlohmann::json j;
  try {
    j = parse_json_limited<nlohmann::json>(payload, who + ": model payload");
  } catch (const nlohmann::json::exception&) {
    throw InputError(who + ": model payload is not the expected JSON");
  }
  if (!j.contains("models") || !j["models"].is_array() || j["models"].size() != outputs)
    throw InputError(who + ": model payload must hold " + std::to_string(outputs) + " models");
  std::vector<cv::Ptr<T>> models;
  for (const auto& text : j["models"]) {
    const std::string where = who + ": model " + std::to_string(models.size());
    if (!text.is_string()) throw InputError(where + " is not text");
    // Only the YAML save_yaml writes; OpenCV would also parse XML, JSON and base64 blocks.
    if (text.get_ref<const std::string&>().rfind("%YAML:1.0\n", 0) != 0) throw InputError(where + " is not OpenCV YAML");
    models.push_back(guarded(where, [&] {
      cv::FileStorage fs(text.get<std::string>(), cv::FileStorage::READ | cv::FileStorage::MEMORY);
      check(fs.root(), where);
      cv::Ptr<T> m = T::create();
      m->read(fs.root());
      if (!m->isTrained()) throw InputError(where + " is empty");
      return m;
    }));
  }
  return models;
}

}  // namespace dicestack::opencv
