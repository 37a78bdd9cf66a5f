#include "h5.hpp"

#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>

#include <dicestack/core/error.hpp>
#include <dicestack/core/read_file.hpp>

namespace dicestack::h5 {
namespace {

// A read of more numbers than this is refused before anything is allocated (a damaged or hostile
// file can claim any shape); 10^8 float64 is 800 MB, far beyond any demonstration set.
constexpr hsize_t kMaxElements = 100'000'000;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  const std::string detail = last_error();
  throw InputError(where + ": " + what + (detail.empty() ? "" : " (HDF5: " + detail + ")"));
}

herr_t innermost(unsigned n, const H5E_error2_t* err, void* data) {
  if (n == 0 && err && err->desc) *static_cast<std::string*>(data) = err->desc;
  return 0;
}

Id checked(hid_t id, const std::string& where, const std::string& what) {
  if (id < 0) fail(where, what);
  return Id(id);
}

void check(herr_t status, const std::string& where, const std::string& what) {
  if (status < 0) fail(where, what);
}

Id open_object(hid_t loc, const std::string& name, const std::string& where) {
  if (!exists(loc, name)) {
    last_error();
    throw InputError(where + ": missing");
  }
  return checked(H5Oopen(loc, name.c_str(), H5P_DEFAULT), where, "cannot open");
}

std::string class_name(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER: return "integers";
    case H5T_FLOAT: return "floating point numbers";
    case H5T_STRING: return "strings";
    case H5T_COMPOUND: return "compound records";
    case H5T_ENUM: return "enumerated values";
    case H5T_ARRAY: return "arrays";
    case H5T_VLEN: return "variable-length sequences";
    case H5T_REFERENCE: return "references";
    case H5T_OPAQUE: return "opaque bytes";
    default: return "values of another kind";
  }
}

Id write_space(const std::vector<hsize_t>& dims) {
  return Id(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr));
}

void write_dataset(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type, const std::vector<hsize_t>& dims,
                   const void* data) {
  const Id space = write_space(dims);
  const Id ds = checked(H5Dcreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), name,
                        "cannot create dataset");
  check(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), name, "cannot write dataset");
}

void write_attr(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type, const void* data) {
  const Id space(H5Screate(H5S_SCALAR));
  const Id a = checked(H5Acreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), name,
                       "cannot create attribute");
  check(H5Awrite(a.get(), mem_type, data), name, "cannot write attribute");
}

Id bool_type() {
  Id t(H5Tenum_create(H5T_NATIVE_INT8));
  signed char v = 0;
  H5Tenum_insert(t.get(), "FALSE", &v);
  v = 1;
  H5Tenum_insert(t.get(), "TRUE", &v);
  return t;
}

// A scalar attribute, opened and checked: `where` names it in messages.
Id scalar_attr(hid_t loc, const std::string& name, const std::string& where) {
  Id a = checked(H5Aopen(loc, name.c_str(), H5P_DEFAULT), where, "cannot open attribute " + name);
  const Id space(H5Aget_space(a.get()));
  const auto points = H5Sget_simple_extent_npoints(space.get());
  if (points != 1) {
    last_error();
    throw InputError(where + ": attribute " + name + " holds " + std::to_string(points) + " values, expected one");
  }
  return a;
}

bool has_attr(hid_t loc, const std::string& name) {
  const htri_t r = H5Aexists(loc, name.c_str());
  if (r < 0) last_error();
  return r > 0;
}

}  // namespace

void Id::reset() {
  if (id_ >= 0) H5Idec_ref(id_);
  id_ = H5I_INVALID_HID;
}

void quiet() {
  static std::once_flag once;
  std::call_once(once, [] { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); });
}

std::string last_error() {
  std::string desc;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, innermost, &desc);
  H5Eclear2(H5E_DEFAULT);
  return desc;
}

MemoryFile::MemoryFile() {
  quiet();
  static std::atomic<unsigned long> counter{0};
  // The core driver keeps the file in memory; the name only has to be unique among open files.
  const std::string name = "dicestack-memory-" + std::to_string(counter++) + ".h5";
  const Id fapl(H5Pcreate(H5P_FILE_ACCESS));
  check(H5Pset_fapl_core(fapl.get(), 1 << 20, 0), name, "cannot set up an in-memory file");
  file_ = checked(H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), name, "cannot create an in-memory file");
}

std::string MemoryFile::image() {
  check(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), "in-memory file", "cannot flush");
  const ssize_t size = H5Fget_file_image(file_.get(), nullptr, 0);
  if (size < 0) fail("in-memory file", "cannot get its image");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (H5Fget_file_image(file_.get(), bytes.data(), bytes.size()) != size) fail("in-memory file", "cannot copy its image");
  return bytes;
}

bool is_hdf5(const std::filesystem::path& path) {
  quiet();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  const htri_t r = H5Fis_hdf5(path.c_str());
  last_error();
  return r > 0;
}

ReadFile::ReadFile(const std::filesystem::path& path) : name_(path.string()) {
  quiet();
  {  // the system's reason first: a missing or unreadable file, or a folder, is not "not an HDF5 file"
    std::ifstream probe = open_for_reading(path);
    probe.peek();
    check_read(probe, path);
  }
  if (!is_hdf5(path)) throw InputError(name_ + ": not an HDF5 file");
  file_ = checked(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), name_, "cannot open");
}

Id create_group(hid_t loc, const std::string& name) {
  return checked(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), name, "cannot create group");
}

void write_f64(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, const double* data) {
  write_dataset(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, data);
}

void write_i64(hid_t loc, const std::string& name, const std::vector<std::int64_t>& data) {
  write_dataset(loc, name, H5T_STD_I64LE, H5T_NATIVE_INT64, {data.size()}, data.data());
}

void write_bool(hid_t loc, const std::string& name, const std::vector<std::uint8_t>& data) {
  const Id t = bool_type();
  write_dataset(loc, name, t.get(), t.get(), {data.size()}, data.data());
}

void write_fixed_strings(hid_t loc, const std::string& name, const std::vector<std::string>& data) {
  std::size_t width = 1;
  for (const auto& s : data) width = std::max(width, s.size());
  const Id t(H5Tcopy(H5T_C_S1));
  H5Tset_size(t.get(), width);
  H5Tset_strpad(t.get(), H5T_STR_NULLPAD);
  std::string buffer(width * data.size(), '\0');
  for (std::size_t i = 0; i < data.size(); ++i) std::memcpy(buffer.data() + i * width, data[i].data(), data[i].size());
  write_dataset(loc, name, t.get(), t.get(), {data.size()}, buffer.data());
}

void attr_string(hid_t loc, const std::string& name, const std::string& value) {
  const Id t(H5Tcopy(H5T_C_S1));
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  const char* p = value.c_str();
  write_attr(loc, name, t.get(), t.get(), &p);
}

void attr_i64(hid_t loc, const std::string& name, std::int64_t value) {
  write_attr(loc, name, H5T_STD_I64LE, H5T_NATIVE_INT64, &value);
}

void attr_u64(hid_t loc, const std::string& name, std::uint64_t value) {
  write_attr(loc, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value);
}

bool exists(hid_t loc, const std::string& path) {
  std::size_t start = 0;
  while (true) {
    const auto slash = path.find('/', start);
    const std::string prefix = path.substr(0, slash);
    const htri_t r = H5Lexists(loc, prefix.c_str(), H5P_DEFAULT);
    if (r <= 0) {
      last_error();
      return false;
    }
    if (slash == std::string::npos) return true;
    if (!is_group(loc, prefix)) return false;
    start = slash + 1;
  }
}

bool is_group(hid_t loc, const std::string& name) {
  const Id obj(H5Oopen(loc, name.c_str(), H5P_DEFAULT));
  if (!obj) {
    last_error();
    return false;
  }
  return H5Iget_type(obj.get()) == H5I_GROUP;
}

Id open_group(hid_t loc, const std::string& path, const std::string& where) {
  Id obj = open_object(loc, path, where);
  if (H5Iget_type(obj.get()) != H5I_GROUP) throw InputError(where + ": is not a group");
  return obj;
}

std::vector<std::string> members(hid_t group, const std::string& where) {
  H5G_info_t info;
  check(H5Gget_info(group, &info), where, "cannot list");
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t n = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (n < 0) fail(where, "cannot list");
    std::string name(static_cast<std::size_t>(n) + 1, '\0');
    H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT);
    name.resize(static_cast<std::size_t>(n));
    names.push_back(std::move(name));
  }
  return names;
}

Array read_numbers(hid_t loc, const std::string& name, const std::string& where, bool integral) {
  const Id obj = open_object(loc, name, where);
  if (H5Iget_type(obj.get()) != H5I_DATASET) throw InputError(where + ": is a group, expected a dataset");
  const Id type(H5Dget_type(obj.get()));
  const H5T_class_t cls = H5Tget_class(type.get());
  const bool is_bool_enum = cls == H5T_ENUM && H5Tget_size(type.get()) == 1;
  const bool accepted = cls == H5T_FLOAT || (integral && (cls == H5T_INTEGER || is_bool_enum));
  if (!accepted)
    throw InputError(where + ": holds " + class_name(cls) + ", expected " +
                     (integral ? "integers, booleans or floating point numbers" : "floating point numbers"));
  const Id space(H5Dget_space(obj.get()));
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) fail(where, "cannot read its shape");
  Array out;
  out.dims.resize(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), out.dims.data(), nullptr);
  hsize_t count = 1;
  for (hsize_t d : out.dims) {
    if (d != 0 && count > kMaxElements / d) throw InputError(where + ": claims more than 10^8 values; refusing to read it");
    count *= d;
  }
  out.values.resize(static_cast<std::size_t>(count));
  if (count == 0) return out;
  if (is_bool_enum) {
    std::vector<signed char> raw(out.values.size());
    const Id mem(H5Tget_native_type(type.get(), H5T_DIR_ASCEND));
    check(H5Dread(obj.get(), mem.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, raw.data()), where, "cannot read");
    for (std::size_t i = 0; i < raw.size(); ++i) out.values[i] = raw[i];
  } else {
    check(H5Dread(obj.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.values.data()), where, "cannot read");
  }
  const std::size_t cols = out.dims.size() >= 2 ? static_cast<std::size_t>(count / out.dims[0]) : 1;
  for (std::size_t i = 0; i < out.values.size(); ++i)
    if (!std::isfinite(out.values[i]))
      throw InputError(where + ": " + (out.dims.size() >= 2 ? "row " + std::to_string(i / cols) + " column " + std::to_string(i % cols)
                                                             : "item " + std::to_string(i)) +
                       " is " + (std::isnan(out.values[i]) ? "NaN" : "infinite") + "; values must be finite");
  return out;
}

std::optional<std::string> read_attr_string(hid_t loc, const std::string& name, const std::string& where) {
  if (!has_attr(loc, name)) return std::nullopt;
  const Id a = scalar_attr(loc, name, where);
  const Id type(H5Aget_type(a.get()));
  if (H5Tget_class(type.get()) != H5T_STRING) throw InputError(where + ": attribute " + name + " must be a string");
  if (H5Tis_variable_str(type.get()) > 0) {
    const Id mem(H5Tcopy(H5T_C_S1));
    H5Tset_size(mem.get(), H5T_VARIABLE);
    H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
    char* p = nullptr;
    check(H5Aread(a.get(), mem.get(), &p), where, "cannot read attribute " + name);
    std::string s = p ? p : "";
    if (p) H5free_memory(p);
    return s;
  }
  const std::size_t size = H5Tget_size(type.get());
  if (size > (1u << 26)) throw InputError(where + ": attribute " + name + " is too long");
  std::string s(size, '\0');
  check(H5Aread(a.get(), type.get(), s.data()), where, "cannot read attribute " + name);
  while (!s.empty() && (s.back() == '\0' || s.back() == ' ')) s.pop_back();
  return s;
}

std::optional<std::int64_t> read_attr_int(hid_t loc, const std::string& name, const std::string& where) {
  if (!has_attr(loc, name)) return std::nullopt;
  const Id a = scalar_attr(loc, name, where);
  const Id type(H5Aget_type(a.get()));
  if (H5Tget_class(type.get()) != H5T_INTEGER) throw InputError(where + ": attribute " + name + " must be an integer");
  std::int64_t v = 0;
  check(H5Aread(a.get(), H5T_NATIVE_INT64, &v), where, "cannot read attribute " + name);
  return v;
}

std::optional<std::uint64_t> read_attr_u64(hid_t loc, const std::string& name, const std::string& where) {
  if (!has_attr(loc, name)) return std::nullopt;
  const Id a = scalar_attr(loc, name, where);
  const Id type(H5Aget_type(a.get()));
  if (H5Tget_class(type.get()) != H5T_INTEGER) throw InputError(where + ": attribute " + name + " must be an integer");
  if (H5Tget_sign(type.get()) == H5T_SGN_2) {
    std::int64_t v = 0;
    check(H5Aread(a.get(), H5T_NATIVE_INT64, &v), where, "cannot read attribute " + name);
    if (v < 0) throw InputError(where + ": attribute " + name + " must not be negative");
    return static_cast<std::uint64_t>(v);
  }
  std::uint64_t v = 0;
  check(H5Aread(a.get(), H5T_NATIVE_UINT64, &v), where, "cannot read attribute " + name);
  return v;
}

}  // namespace dicestack::h5
