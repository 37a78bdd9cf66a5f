#pragma once
// Forwarding header: Standardizer lives in the foundation (<dicestack/core/standardizer.hpp>),
// so that a regressor plugin does not need datasets/. Kept for code that includes this path.
#include <dicestack/core/standardizer.hpp>
