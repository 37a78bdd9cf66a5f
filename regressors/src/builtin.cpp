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

}  // namespace dicestack
