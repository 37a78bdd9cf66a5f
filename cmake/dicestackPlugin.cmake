# dicestack_add_regressor_plugin(<name> <sources>...)
# Builds a regressor plugin: a MODULE library named lib<name>.so that links only the regressor
# interface (dicestack::regressor_api, with the foundation) and exports only its
# dicestack_plugin_v1 entry point. The host program brings the built-ins and the global
# registry; the plugin loads no simulator, optimiser, OpenCV or xgboost of its own.
function(dicestack_add_regressor_plugin name)
  add_library(${name} MODULE ${ARGN})
  target_link_libraries(${name} PRIVATE dicestack::regressor_api)
  target_compile_features(${name} PRIVATE cxx_std_20)
  set_target_properties(${name} PROPERTIES
    PREFIX "lib"
    CXX_EXTENSIONS OFF
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
endfunction()
