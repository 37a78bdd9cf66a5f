#pragma once
// The regressor registry: name -> {description, parameter schema, factory}. Built-ins are
// registered on first use; plugins add theirs from shared libraries (`--plugin LIB`, or the
// DICESTACK_PLUGIN_PATH variable) after an ABI handshake. A plugin author writes one class and
// one DICESTACK_REGISTER_REGRESSOR line (docs/plugins.md).
//
// This header, regressor.hpp and params.hpp are the regressor interface, target
// dicestack::regressor_api: all a plugin links (with the foundation), so that loading a plugin
// loads no simulator, optimiser or OpenCV. The built-ins, Model and model files are
// dicestack::regressors, which also defines RegressorRegistry::global() and
// register_builtin_regressors(): a program that calls them links dicestack::regressors.
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/registry_lookup.hpp>
#include <dicestack/regressors/regressor.hpp>
#include <dicestack/version.hpp>

/// Bumped whenever the Regressor interface or the plugin struct changes layout. (Guarded so
/// that the tests can build a plugin that claims another ABI.)
#ifndef DICESTACK_PLUGIN_ABI_VERSION
#define DICESTACK_PLUGIN_ABI_VERSION 1
#endif

#define DICESTACK_STRINGIFY_(x) #x
#define DICESTACK_STRINGIFY(x) DICESTACK_STRINGIFY_(x)
#if defined(_GLIBCXX_RELEASE)
#define DICESTACK_STDLIB_TAG "libstdc++ " DICESTACK_STRINGIFY(_GLIBCXX_RELEASE)
#elif defined(_LIBCPP_VERSION)
#define DICESTACK_STDLIB_TAG "libc++ " DICESTACK_STRINGIFY(_LIBCPP_VERSION)
#else
#define DICESTACK_STDLIB_TAG "unknown standard library"
#endif

namespace dicestack {

/// Everything the registry knows about one regressor.
struct RegressorInfo {
  std::string name;
  std::string description;
  std::vector<ParamSpec> params;
  std::string source;  ///< "built-in", or the plugin's path
  std::function<std::unique_ptr<Regressor>(std::string name, Params params)> factory;
};

/// Info for a class T that inherits Regressor's constructor and has `static std::vector<ParamSpec> schema()`.
template <class T>
RegressorInfo regressor_info(std::string name, std::string description) {
  return {std::move(name), std::move(description), T::schema(), "",
          [](std::string n, Params p) -> std::unique_ptr<Regressor> { return std::make_unique<T>(std::move(n), std::move(p)); }};
}

class RegressorRegistry {
 public:
  /// The process-wide registry (the one global in dicestack), with the built-ins registered.
  /// Defined in dicestack::regressors (with the built-ins); plugins never call it.
  static RegressorRegistry& global();

  /// Adds a regressor. Throws ConfigError if the name is taken, naming both sources:
  /// `regressor "knn" registered twice (built-in, and plugin ./libknn2.so)`.
  void add(RegressorInfo info);
  /// Adds a regressor registered by `source` (named in messages, e.g. "Python
  /// (dicestack.register_regressor)"); throws as add(info) does.
  void add(RegressorInfo info, std::string source);

  /// A new, unfitted regressor with the schema's defaults overridden by "key=value"
  /// assignments. Throws ConfigError for an unknown name (listing the registered ones) or a
  /// bad parameter (naming the regressor, the parameter and the value).
  std::unique_ptr<Regressor> create(std::string_view name, const std::vector<std::string>& assignments = {}) const;

  /// Throws ConfigError listing the registered names if `name` is unknown.
  const RegressorInfo& info(std::string_view name) const;
  bool contains(std::string_view name) const { return entries_.find(name) != entries_.end(); }
  /// Registered names, sorted.
  std::vector<std::string> names() const;

  /// Loads a plugin library and lets it register. Throws PluginError if it cannot be loaded,
  /// is not a dicestack plugin, or was built for another ABI (naming both versions).
  void load_plugin(const std::filesystem::path& library);

  /// Loads every plugin named by DICESTACK_PLUGIN_PATH (':'-separated files, or folders whose
  /// *.so files are loaded in name order). Returns what was loaded.
  std::vector<std::filesystem::path> load_plugins_from_environment();

 private:
  std::map<std::string, RegressorInfo, std::less<>> entries_;
  std::vector<std::filesystem::path> loaded_;
  std::string registering_source_ = "built-in";
};

/// Registers the six built-ins; called once by RegressorRegistry::global(). Defined in
/// dicestack::regressors (builtin_regressors.cpp).
void register_builtin_regressors(RegressorRegistry& registry);

}  // namespace dicestack

extern "C" {
/// What a plugin library exports, through `dicestack_plugin_v1()`.
struct DicestackPluginV1 {
  int abi_version;                ///< DICESTACK_PLUGIN_ABI_VERSION the plugin was built with
  const char* dicestack_version;  ///< DICESTACK_VERSION the plugin was built against
  const char* stdlib;             ///< DICESTACK_STDLIB_TAG: C++ types cross the boundary
  void (*register_regressors)(dicestack::RegressorRegistry* registry);
};
}

/// The one line a plugin author writes, after the class: exports the plugin entry point that
/// registers `Class` under `name` (the CLI spelling) with a one-line `description`.
#define DICESTACK_REGISTER_REGRESSOR(Class, name, description)                                     \
  extern "C" __attribute__((visibility("default"))) const DicestackPluginV1* dicestack_plugin_v1() { \
    static const DicestackPluginV1 plugin{                                                         \
        DICESTACK_PLUGIN_ABI_VERSION, DICESTACK_VERSION, DICESTACK_STDLIB_TAG,                     \
        [](dicestack::RegressorRegistry* registry) {                                               \
          registry->add(dicestack::regressor_info<Class>(name, description));                     \
        }};                                                                                        \
    return &plugin;                                                                                \
  }
