#pragma once
// The dense matrix the learning side of dicestack exchanges: datasets, standardisers and every
// regressor (built-in or plugin) read and write it.
#include <Eigen/Core>

namespace dicestack {

/// Row-major so that one row is a contiguous span (predict_row's input).
using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace dicestack
