// A library whose dicestack_plugin_v1 is data, not a function: loading it must not call it.
extern "C" __attribute__((visibility("default"))) const char dicestack_plugin_v1[] = "I am not code";
