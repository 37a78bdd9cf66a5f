#pragma once
// The one wrapper around the HDF5 C API (STYLE 9): handles close themselves, HDF5's own error
// printing is off, and every failure becomes an InputError naming the file and the path inside
// it. Private to interop/.
#include <hdf5.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace dicestack::h5 {

/// An owned HDF5 identifier of any kind, closed with H5Idec_ref.
class Id {
 public:
  Id() = default;
  explicit Id(hid_t id) : id_(id) {}
  ~Id() { reset(); }
  Id(Id&& o) noexcept : id_(o.id_) { o.id_ = H5I_INVALID_HID; }
  Id& operator=(Id&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  hid_t get() const { return id_; }
  explicit operator bool() const { return id_ >= 0; }
  void reset();

 private:
  hid_t id_ = H5I_INVALID_HID;
};

/// Turns off HDF5's printing of its error stack (once per process).
void quiet();

/// The innermost message on HDF5's error stack ("" if none), and clears the stack.
std::string last_error();

/// A file being written in memory (HDF5's core driver, no backing store); image() gives its bytes.
class MemoryFile {
 public:
  MemoryFile();
  hid_t root() const { return file_.get(); }
  /// Flushes and returns the whole file as bytes.
  std::string image();

 private:
  Id file_;
};

/// A file opened read-only. Throws InputError "FILE: cannot open for reading: <reason>",
/// "FILE: read failed: Is a directory", "FILE: not an HDF5 file" or "FILE: cannot open" (HDF5's).
class ReadFile {
 public:
  explicit ReadFile(const std::filesystem::path& path);
  hid_t root() const { return file_.get(); }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  Id file_;
};

/// True when `path` exists and is an HDF5 file (never throws).
bool is_hdf5(const std::filesystem::path& path);

// ---- writing (errors: InputError "<what>: cannot write <path>") --------------------------------
Id create_group(hid_t loc, const std::string& name);
/// A dataset of float64 with `dims` (1 or 2 dimensions), row-major `data`.
void write_f64(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, const double* data);
void write_i64(hid_t loc, const std::string& name, const std::vector<std::int64_t>& data);
/// A 1-d dataset of h5py's bool (an int8 enum FALSE = 0, TRUE = 1; numpy reads np.bool_).
void write_bool(hid_t loc, const std::string& name, const std::vector<std::uint8_t>& data);
/// A 1-d dataset of fixed-length ASCII strings (numpy dtype 'S<n>', as robomimic's masks are).
void write_fixed_strings(hid_t loc, const std::string& name, const std::vector<std::string>& data);
void attr_string(hid_t loc, const std::string& name, const std::string& value);  ///< variable-length UTF-8
void attr_i64(hid_t loc, const std::string& name, std::int64_t value);
void attr_u64(hid_t loc, const std::string& name, std::uint64_t value);

// ---- reading: `where` is "FILE: path/inside" for messages ---------------------------------------
/// Whether `path` (relative to `loc`, "a/b") names a link, checked one component at a time.
bool exists(hid_t loc, const std::string& path);
/// Opens a group; throws "<where>: missing" or "<where>: is not a group".
Id open_group(hid_t loc, const std::string& path, const std::string& where);
/// Names of a group's members in HDF5's name order.
std::vector<std::string> members(hid_t group, const std::string& where);
bool is_group(hid_t loc, const std::string& name);

/// A numeric dataset read as double: its dims and values (row-major). `integral` chooses which
/// HDF5 class is accepted (float, or integer/h5py bool for flags); anything else (strings,
/// compounds) is refused as a wrong dtype. Every value must be finite. Throws InputError naming
/// `where` ("... has 2 dimensions, expected 1", "... holds strings, expected floating point").
struct Array {
  std::vector<hsize_t> dims;
  std::vector<double> values;
};
Array read_numbers(hid_t loc, const std::string& name, const std::string& where, bool integral = false);

std::optional<std::string> read_attr_string(hid_t loc, const std::string& name, const std::string& where);
std::optional<std::int64_t> read_attr_int(hid_t loc, const std::string& name, const std::string& where);
std::optional<std::uint64_t> read_attr_u64(hid_t loc, const std::string& name, const std::string& where);

}  // namespace dicestack::h5
