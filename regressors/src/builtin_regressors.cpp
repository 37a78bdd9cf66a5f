#include <dicestack/regressors/registry.hpp>

namespace dicestack {

// Defined next to each class (knn.cpp, ...). Called explicitly rather than from static
// initialisers, which a static link would drop (STYLE 5).
void register_gbt(RegressorRegistry&);
void register_knn(RegressorRegistry&);
void register_linear_svr(RegressorRegistry&);
void register_mlp(RegressorRegistry&);
void register_random_forest(RegressorRegistry&);
void register_rbf_svr(RegressorRegistry&);

void register_builtin_regressors(RegressorRegistry& registry) {
  register_gbt(registry);
  register_knn(registry);
  register_linear_svr(registry);
  register_mlp(registry);
  register_random_forest(registry);
  register_rbf_svr(registry);
}

// Here rather than beside the registry (dicestack::regressor_api): the global registry holds
// the built-ins, and the interface a plugin links must not pull them in.
RegressorRegistry& RegressorRegistry::global() {
  static RegressorRegistry* registry = [] {
    auto* r = new RegressorRegistry;  // never destroyed: plugin code may run during exit
    register_builtin_regressors(*r);
    return r;
  }();
  return *registry;
}

}  // namespace dicestack
