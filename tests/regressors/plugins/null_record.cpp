// A library whose entry point returns a record with null fields.
#include <dicestack/regressors/registry.hpp>

extern "C" __attribute__((visibility("default"))) const DicestackPluginV1* dicestack_plugin_v1() {
  static const DicestackPluginV1 record{DICESTACK_PLUGIN_ABI_VERSION, nullptr, nullptr, nullptr};
  return &record;
}
