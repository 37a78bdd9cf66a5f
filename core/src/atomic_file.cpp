#include <dicestack/core/atomic_file.hpp>

#include <system_error>

#include <dicestack/core/error.hpp>

namespace dicestack {

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)) {
  tmp_ = path_;
  tmp_ += ".tmp";
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw InputError(tmp_.string() + ": cannot create file");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ignored;
    std::filesystem::remove(tmp_, ignored);
  }
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok || out_.fail()) throw InputError(tmp_.string() + ": write failed");
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) throw InputError(path_.string() + ": cannot rename " + tmp_.string() + " into place: " + ec.message());
  committed_ = true;
}

}  // namespace dicestack
