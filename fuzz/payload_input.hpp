#pragma once
// The input layout of the payload harnesses, shared with the seed maker: two bytes of
// dimensions, then the payload bytes exactly as a model file holds them.
//   byte 0, byte 1 & 0x0f : input_dim - 1  (12 bits, 1..4096)
//   byte 1 >> 4           : output_dim - 1 (1..16)
// And the settings each regressor is created with: what load_payload reads can depend on them
// (mlp's layer count), and the seeds are fitted with small ones so that they stay small.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dicestack::fuzz {

inline constexpr std::size_t kDimBytes = 2;

struct PayloadInput {
  std::size_t input_dim = 0, output_dim = 0;
  std::string_view payload;
};

/// Splits a fuzz input; false if it is shorter than the dimension bytes.
inline bool split_payload_input(const std::uint8_t* data, std::size_t size, PayloadInput& out) {
  if (size < kDimBytes) return false;
  out.input_dim = 1 + (data[0] | static_cast<std::size_t>(data[1] & 0x0f) << 8);
  out.output_dim = 1 + (data[1] >> 4);
  out.payload = {reinterpret_cast<const char*>(data) + kDimBytes, size - kDimBytes};
  return true;
}

/// The two dimension bytes for input_dim in [1, 4096] and output_dim in [1, 16].
inline std::string dim_bytes(std::size_t input_dim, std::size_t output_dim) {
  const std::size_t i = input_dim - 1, o = output_dim - 1;
  return {static_cast<char>(i & 0xff), static_cast<char>(((i >> 8) & 0x0f) | (o << 4))};
}

/// The --set assignments the harness creates `regressor` with (defaults but for mlp's size).
inline std::vector<std::string> load_settings(std::string_view regressor) {
  if (regressor == "mlp") return {"layers=2", "width=8"};
  return {};
}

/// The assignments the seed models are fitted with: load_settings plus small sizes.
inline std::vector<std::string> seed_fit_settings(std::string_view regressor) {
  std::vector<std::string> s = load_settings(regressor);
  if (regressor == "mlp") s.push_back("max_iter=5");
  if (regressor == "linear_svr") s.push_back("max_iter=5");
  if (regressor == "random_forest") s.insert(s.end(), {"trees=2", "max_depth=4", "threads=1"});
  if (regressor == "gbt") s.insert(s.end(), {"trees=3", "max_depth=3"});
  if (regressor == "rbf_svr") s.push_back("threads=1");
  return s;
}

/// The fixed, finite row every harness predicts: a few distinct values of both signs.
inline std::vector<double> fixed_row(std::size_t dim) {
  std::vector<double> row(dim);
  for (std::size_t i = 0; i < dim; ++i) row[i] = 0.5 * static_cast<double>(static_cast<int>(i % 7) - 3);
  return row;
}

}  // namespace dicestack::fuzz
