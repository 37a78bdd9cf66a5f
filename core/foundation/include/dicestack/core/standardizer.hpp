#pragma once
// Per-column standardisation fitted on training rows and saved with every model.
#include <span>
#include <string>
#include <vector>

#include <dicestack/core/matrix.hpp>

namespace dicestack {

/// z = (x - mean) / sigma per column; mean and population sigma (ddof 0) of the rows it was
/// fitted on. A constant column gets sigma 1 (and a warning), so it maps to zero.
struct Standardizer {
  std::vector<double> mean;
  std::vector<double> sigma;

  /// Fits on `rows`; each constant column adds a line to `warnings` (if given).
  /// Throws InputError if `rows` is empty or holds a non-finite value.
  static Standardizer fit(const Matrix& rows, std::vector<std::string>* warnings = nullptr,
                          const std::vector<std::string>* column_names = nullptr);

  std::size_t dims() const { return mean.size(); }
  /// Standardises every row. Throws InputError on a column-count mismatch.
  Matrix apply(const Matrix& rows) const;
  /// Standardises one row into `out` (same size), without allocating.
  void apply_row(std::span<const double> in, std::span<double> out) const;
  /// Maps standardised values back.
  void invert_row(std::span<const double> in, std::span<double> out) const;
};

}  // namespace dicestack
