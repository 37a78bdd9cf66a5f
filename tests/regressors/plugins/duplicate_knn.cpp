// A plugin that tries to register a name the built-ins already use.
#include <dicestack/regressors/registry.hpp>

class AnotherKnn final : public dicestack::Regressor {
 public:
  using Regressor::Regressor;
  static std::vector<dicestack::ParamSpec> schema() { return {}; }

 private:
  void do_fit(const dicestack::Matrix&, const dicestack::Matrix&, std::uint64_t) override {}
  void do_predict_row(std::span<const double>, std::span<double> y) const override {
    for (double& v : y) v = 0.0;
  }
  std::string do_save() const override { return {}; }
  void do_load(std::string_view, std::size_t, std::size_t) override {}
};

DICESTACK_REGISTER_REGRESSOR(AnotherKnn, "knn", "a second knn")
