// A shared library without dicestack's entry point.
extern "C" __attribute__((visibility("default"))) int not_a_dicestack_plugin() { return 42; }
