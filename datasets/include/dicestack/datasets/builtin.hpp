#pragma once
// Forwarding header: data_dir, cache_dir and human_demo_set are declared in data_paths.hpp.
// Kept for code that includes this path.
#include <dicestack/datasets/data_paths.hpp>
