#include "cli.hpp"

int main(int argc, char** argv) { return dicestack::cli::run(argc, argv); }
