#pragma once
// Writing and reading plain numbers as bytes, for snapshots that leave the process (pickles).
// Values are stored in the machine's own byte order: a record is read back by the same build
// on the same kind of machine, and its header's byte-order mark refuses any other.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/types.hpp>

namespace dicestack::detail {

class ByteWriter {
 public:
  template <class T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T>);
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    out_.append(raw, sizeof(T));
  }
  void put_bytes(std::string_view bytes) {
    put<std::uint64_t>(bytes.size());
    out_.append(bytes);
  }
  /// Appends the FNV-1a checksum of everything written so far and returns the record.
  std::string finish() {
    put<std::uint64_t>(fnv1a(out_));
    return std::move(out_);
  }

 private:
  std::string out_;
};

/// Reads what ByteWriter wrote; every failure is an InputError naming `what`.
class ByteReader {
 public:
  /// Checks the trailing checksum first, so that no field of a damaged record is trusted.
  ByteReader(std::string_view bytes, std::string what) : what_(std::move(what)) {
    if (bytes.size() < sizeof(std::uint64_t)) fail("too short (" + std::to_string(bytes.size()) + " bytes)");
    const std::string_view body = bytes.substr(0, bytes.size() - sizeof(std::uint64_t));
    std::uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + body.size(), sizeof stored);
    if (stored != fnv1a(body)) fail("checksum mismatch (damaged or edited)");
    in_ = body;
  }
  template <class T>
  T get() {
    static_assert(std::is_arithmetic_v<T>);
    if (in_.size() < sizeof(T)) fail("truncated");
    T value;
    std::memcpy(&value, in_.data(), sizeof(T));
    in_.remove_prefix(sizeof(T));
    return value;
  }
  /// A finite floating-point value.
  template <class T>
  T get_finite(std::string_view field) {
    const T value = get<T>();
    if (!std::isfinite(value)) fail(std::string(field) + " is not finite");
    return value;
  }
  /// An integer in [lo, hi].
  template <class T>
  T get_in(T lo, T hi, std::string_view field) {
    const T value = get<T>();
    if (value < lo || value > hi)
      fail(std::string(field) + " is " + std::to_string(value) + ", outside [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
    return value;
  }
  std::string_view get_bytes() {
    const auto n = get<std::uint64_t>();
    if (n > in_.size()) fail("truncated");
    const std::string_view out = in_.substr(0, static_cast<std::size_t>(n));
    in_.remove_prefix(static_cast<std::size_t>(n));
    return out;
  }
  /// Throws unless every byte was read.
  void expect_end() const {
    if (!in_.empty()) fail(std::to_string(in_.size()) + " unexpected bytes at the end");
  }
  [[noreturn]] void fail(const std::string& why) const { throw InputError(what_ + ": " + why); }

 private:
  std::string what_;
  std::string_view in_;
};

}  // namespace dicestack::detail
