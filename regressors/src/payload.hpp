#pragma once
// Binary payload helpers shared by the regressors that store plain matrices (knn, linear_svr,
// mlp): a magic word, then for each matrix its shape and little-endian doubles.
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/matrix.hpp>

namespace dicestack::payload {

inline constexpr char kMagic[8] = {'D', 'S', 'M', 'A', 'T', 'v', '1', '\n'};

inline std::string write_matrices(const std::vector<const Matrix*>& ms) {
  std::string out(kMagic, sizeof kMagic);
  auto put = [&](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
  const std::uint64_t count = ms.size();
  put(&count, sizeof count);
  for (const Matrix* m : ms) {
    const std::uint64_t shape[2] = {static_cast<std::uint64_t>(m->rows()), static_cast<std::uint64_t>(m->cols())};
    put(shape, sizeof shape);
    put(m->data(), sizeof(double) * static_cast<std::size_t>(m->size()));
  }
  return out;
}

inline std::vector<Matrix> read_matrices(std::string_view in, std::size_t expected, const std::string& who) {
  std::size_t at = 0;
  auto take = [&](void* p, std::size_t n) {
    if (in.size() - at < n) throw InputError(who + ": model payload is truncated");
    if (n > 0) std::memcpy(p, in.data() + at, n);  // an empty matrix's data() may be null
    at += n;
  };
  char magic[sizeof kMagic];
  take(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) throw InputError(who + ": model payload is not a matrix payload");
  std::uint64_t count = 0;
  take(&count, sizeof count);
  if (count != expected)
    throw InputError(who + ": model payload holds " + std::to_string(count) + " matrices, expected " + std::to_string(expected));
  std::vector<Matrix> out;
  for (std::uint64_t i = 0; i < count; ++i) {
    std::uint64_t shape[2];
    take(shape, sizeof shape);
    if (shape[0] > (1ULL << 32) || shape[1] > (1ULL << 20)) throw InputError(who + ": model payload has an absurd shape");
    // The shape against the bytes present, before anything is allocated.
    if (shape[1] > 0 && shape[0] > (in.size() - at) / sizeof(double) / shape[1])
      throw InputError(who + ": model payload says " + std::to_string(shape[0]) + " x " + std::to_string(shape[1]) +
                       " values, more than its " + std::to_string(in.size() - at) + " remaining bytes hold");
    Matrix m(static_cast<Eigen::Index>(shape[0]), static_cast<Eigen::Index>(shape[1]));
    take(m.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
    if (!m.allFinite()) throw InputError(who + ": model payload holds NaN or infinity");
    out.push_back(std::move(m));
  }
  if (at != in.size()) throw InputError(who + ": model payload has trailing bytes");
  return out;
}

}  // namespace dicestack::payload
