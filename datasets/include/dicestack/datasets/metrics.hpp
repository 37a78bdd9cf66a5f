#pragma once
// The paper's error metric (eq. 9).
#include <span>
#include <vector>

#include <dicestack/datasets/dataset.hpp>

namespace dicestack {

/// Population standard deviation (ddof 0) of each column of `labels`; a constant column gets
/// 1, as in the standardiser, so that eq. 9 stays defined.
std::vector<double> column_sigma(const Matrix& labels);

/// Mean over rows of sum_j |y_ij - yhat_ij| / sigma_j (paper eq. 9), sigma from the training
/// labels. Throws InputError if shapes differ or a sigma_j is not positive.
double scaled_l1_error(const Matrix& y, const Matrix& y_hat, std::span<const double> sigma);

}  // namespace dicestack
