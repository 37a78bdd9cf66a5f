// dicestack.register_regressor: a Python object with fit(X, Y) / predict(X) as a C++ Regressor in
// the process-wide registry. The C++ side holds the factory and the fitted estimator and calls
// dicestack.regressors' helpers with the GIL acquired, from whatever thread a learner or a
// rollout runs on; Python regressors therefore serialise on the GIL.
#include <cstring>
#include <memory>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <dicestack/core/error.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/regressors/registry.hpp>

#include "bindings.hpp"
#include "convert.hpp"

namespace dicestack::python {
namespace {

constexpr const char* kPythonSource = "Python (dicestack.register_regressor)";

/// A Python object that C++ owns: copies share it, and the last one lets it go with the GIL held,
/// whichever thread that is (models are destroyed inside C++ calls that run without the GIL).
class PyRef {
 public:
  explicit PyRef(py::object object) : object_(std::move(object)) {}
  ~PyRef() {
    if (!Py_IsInitialized()) {  // the interpreter is gone: leak rather than touch it
      object_.release();
      return;
    }
    py::gil_scoped_acquire gil;
    object_ = py::object();
  }
  PyRef(const PyRef&) = delete;
  PyRef& operator=(const PyRef&) = delete;
  const py::object& get() const { return object_; }

 private:
  py::object object_;
};

/// dicestack.regressors' helpers (_fit, _predict, _dumps, _loads, _type_name); call with the GIL.
py::object helper(const char* name) {
  static PyRef* module = new PyRef(py::module_::import("dicestack.regressors"));  // never destroyed
  return module->get().attr(name);
}

py::array_t<double> array_of(const double* data, Eigen::Index rows, Eigen::Index cols) {
  py::array_t<double> out({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
  if (rows * cols > 0) std::memcpy(out.mutable_data(), data, sizeof(double) * static_cast<std::size_t>(rows * cols));
  return out;
}

/// Params as the factory's keyword arguments, typed by the schema.
py::dict keyword_arguments(const Params& params, const std::vector<ParamSpec>& schema) {
  py::dict kwargs;
  for (const auto& spec : schema) {
    const py::str key(spec.name);
    switch (spec.type) {
      case ParamType::integer: kwargs[key] = params.integer(spec.name); break;
      case ParamType::real: kwargs[key] = params.real(spec.name); break;
      case ParamType::boolean: kwargs[key] = params.boolean(spec.name); break;
      case ParamType::choice:
      case ParamType::text: kwargs[key] = params.choice(spec.name); break;
    }
  }
  return kwargs;
}

class PyRegressor final : public PickledRegressor {
 public:
  /// A registered regressor, to be fitted: `factory(**params)` makes the estimator.
  PyRegressor(std::string name, Params params, std::vector<ParamSpec> schema, std::shared_ptr<PyRef> factory)
      : PickledRegressor(std::move(name), std::move(params)), schema_(std::move(schema)), factory_(std::move(factory)) {}
  /// A fitted estimator read back from a model's pickle.
  PyRegressor(std::string name, Params params, std::shared_ptr<PyRef> estimator)
      : PickledRegressor(std::move(name), std::move(params)), estimator_(std::move(estimator)) {}

  std::string pickle() const override {
    py::gil_scoped_acquire gil;
    return helper("_dumps")(estimator_->get()).cast<std::string>();
  }

  std::string object_type() const override {
    py::gil_scoped_acquire gil;
    return helper("_type_name")(estimator_->get()).cast<std::string>();
  }

 private:
  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t seed) override {
    if (!factory_) throw InputError(name() + ": a model read from a pickle cannot be refitted; register the regressor");
    py::gil_scoped_acquire gil;
    py::object estimator = helper("_fit")(name(), factory_->get(), keyword_arguments(params(), schema_),
                                          array_of(x.data(), x.rows(), x.cols()), array_of(y.data(), y.rows(), y.cols()), seed);
    estimator_ = std::make_shared<PyRef>(std::move(estimator));
  }

  // predict_row is called from any thread, several at once: the GIL serialises the calls.
  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    py::gil_scoped_acquire gil;
    const auto out = helper("_predict")(name(), estimator_->get(), array_of(x.data(), 1, static_cast<Eigen::Index>(x.size())),
                                        y.size()).cast<DoubleArray>();
    std::memcpy(y.data(), out.data(), sizeof(double) * y.size());
  }

  void do_predict(const Matrix& x, Matrix& y) const override {
    py::gil_scoped_acquire gil;
    const auto out = helper("_predict")(name(), estimator_->get(), array_of(x.data(), x.rows(), x.cols()), y.cols())
                         .cast<DoubleArray>();
    std::memcpy(y.data(), out.data(), sizeof(double) * static_cast<std::size_t>(y.size()));
  }

  void do_load(std::string_view payload, std::size_t, std::size_t) override {
    if (!estimator_ || !is_pickled_payload(payload))
      throw InputError(name() + ": a Python regressor is read from its pickle, through load_model(path, allow_pickle=True)");
  }

  std::vector<ParamSpec> schema_;
  std::shared_ptr<PyRef> factory_;
  std::shared_ptr<PyRef> estimator_;
};

/// The parameters a saved model lists, as a schema of their own: a pickled model needs no
/// registration in this process, so its parameters are typed from their text.
std::vector<ParamSpec> schema_from_text(const std::vector<std::string>& assignments) {
  std::vector<ParamSpec> schema;
  for (const auto& a : assignments) {
    const auto eq = a.find('=');
    ParamSpec spec;
    spec.name = a.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : a.substr(eq + 1);
    spec.default_value = value;
    if (value == "true" || value == "false") {
      spec.type = ParamType::boolean;
    } else if (!value.empty() && value.find_first_not_of("-0123456789") == std::string::npos) {
      spec.type = ParamType::integer;
    } else {
      char* end = nullptr;
      std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0') {
        spec.type = ParamType::choice;
        spec.choices = {value};
      }
    }
    schema.push_back(std::move(spec));
  }
  return schema;
}

}  // namespace

PickleLoader python_pickle_loader() {
  return [](const std::string& name, const std::vector<std::string>& assignments, const std::string& bytes) {
    py::gil_scoped_acquire gil;  // held by load_model's caller already
    auto estimator = std::make_shared<PyRef>(helper("_loads")(py::bytes(bytes)));
    const auto schema = schema_from_text(assignments);
    return std::unique_ptr<Regressor>(
        std::make_unique<PyRegressor>(name, Params(schema, assignments, name), std::move(estimator)));
  };
}

void bind_regressors(py::module_& m) {
  m.def(
      "register_regressor",
      [](const std::string& name, py::object factory, const std::string& description,
         const std::vector<std::tuple<std::string, std::string, std::string>>& params) {
        std::vector<ParamSpec> schema;
        for (const auto& [key, type, default_value] : params) {
          ParamSpec spec;
          spec.name = key;
          spec.type = type == "integer" ? ParamType::integer : type == "boolean" ? ParamType::boolean : ParamType::real;
          spec.default_value = default_value;
          spec.help = "a keyword argument of the Python factory";
          schema.push_back(std::move(spec));
        }
        (void)helper("_fit");  // imports the helpers now, on this thread, not first inside a parallel rollout
        auto shared = std::make_shared<PyRef>(std::move(factory));
        RegressorInfo info{name, description, schema, "",
                           [shared, schema](std::string n, Params p) -> std::unique_ptr<Regressor> {
                             return std::make_unique<PyRegressor>(std::move(n), std::move(p), schema, shared);
                           }};
        RegressorRegistry::global().add(std::move(info), kPythonSource);
      },
      py::arg("name"), py::arg("factory"), py::arg("description"), py::arg("params"));
  m.def("regressor_names", [] { return RegressorRegistry::global().names(); });
}

}  // namespace dicestack::python
