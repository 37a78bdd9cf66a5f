#include <dicestack/core/atomic_file.hpp>

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <random>
#include <system_error>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/json_depth.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;

std::string first_line_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!in || !std::getline(in, line)) return {};
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

bool has_format(const nlohmann::json& j, const std::string& format, const std::vector<std::string>& legacy_keys) {
  if (!j.is_object()) return false;
  if (j.contains("format")) return j["format"].is_string() && j["format"].get<std::string>() == format;
  if (legacy_keys.empty()) return false;
  for (const auto& k : legacy_keys)
    if (!j.contains(k)) return false;
  return true;
}

std::string leftover_prefix(const fs::path& target, std::string_view tag) {
  return "." + target.filename().string() + "." + std::string(tag) + "-";
}

}  // namespace

Ownership Ownership::json_object(std::string what, std::string format, std::vector<std::string> legacy_keys) {
  return {std::move(what), [format = std::move(format), keys = std::move(legacy_keys)](const fs::path& p) {
            std::ifstream in(p, std::ios::binary);
            try {
              return has_format(parse_json_limited<nlohmann::json>(in, p.string()), format, keys);
            } catch (const std::exception&) {
              return false;
            }
          }};
}

Ownership Ownership::json_first_line(std::string what, std::string format) {
  return {std::move(what), [format = std::move(format)](const fs::path& p) {
            try {
              return has_format(parse_json_limited<nlohmann::json>(first_line_of(p), p.string()), format, {});
            } catch (const std::exception&) {
              return false;
            }
          }};
}

Ownership Ownership::first_line(std::string what, std::vector<std::string> lines) {
  return {std::move(what), [lines = std::move(lines)](const fs::path& p) {
            const std::string line = first_line_of(p);
            for (const auto& l : lines)
              if (line == l) return true;
            return false;
          }};
}

Ownership Ownership::unchecked(std::string what) { return {std::move(what), nullptr}; }

void check_replaceable(const fs::path& path, const Ownership& owner) {
  std::error_code ec;
  // A folder that is not there fails every write into it: say so before any work, not after.
  const fs::path parent = path.parent_path();
  if (!parent.empty() && fs::status(parent, ec).type() != fs::file_type::directory)
    throw InputError(path.string() + ": its folder " + parent.string() +
                     " does not exist (or is not a folder); create it first");
  const auto st = fs::symlink_status(path, ec);
  if (ec || st.type() == fs::file_type::not_found) return;
  if (!owner.recognises && st.type() == fs::file_type::regular) return;
  if (st.type() == fs::file_type::regular && owner.recognises(path)) return;
  const std::string kind = st.type() == fs::file_type::directory ? " (it is a folder)"
                           : st.type() == fs::file_type::regular ? ""
                                                                  : " (it is not a regular file)";
  throw InputError(path.string() + ": exists and is not a " + owner.what + kind +
                   "; refusing to replace it: choose another --out or remove it yourself");
}

bool process_is_running(long pid) {
  if (pid <= 0) return true;  // not a pid we wrote; never treat it as dead
  return !(kill(static_cast<pid_t>(pid), 0) == -1 && errno == ESRCH);
}

std::string host_tag() {
  static const std::string tag = [] {
    char name[256] = {};
    if (gethostname(name, sizeof name - 1) != 0) name[0] = '\0';
    char hex[16];
    std::snprintf(hex, sizeof hex, "h%08llx", static_cast<unsigned long long>(fnv1a(name) >> 32));
    return std::string(hex);
  }();
  return tag;
}

fs::path temporary_sibling(const fs::path& target, std::string_view tag) {
  static std::atomic<unsigned long> counter{0};
  thread_local std::mt19937_64 rng{std::random_device{}()};  // only names scratch files
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  return parent / (leftover_prefix(target, tag) + std::to_string(getpid()) + "-" + host_tag() + "-" +
                   std::to_string(counter++) + "x" + std::to_string(rng() % 1000000000));
}

void replace_folder(const fs::path& dir, const std::function<bool(const fs::path&)>& is_ours,
                    const std::function<void(const fs::path&)>& check, const std::function<void(const fs::path&)>& fill) {
  const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
  fs::create_directories(parent);
  std::error_code ec;
  for (const auto& old : dead_leftovers(dir, "old")) {
    if (!fs::exists(fs::symlink_status(dir, ec)) && is_ours(old)) fs::rename(old, dir, ec);
    else if (is_ours(old) || fs::is_empty(old, ec)) fs::remove_all(old, ec);
  }
  for (const auto& tmp : dead_leftovers(dir, "tmp"))
    if (fs::is_directory(fs::symlink_status(tmp, ec))) fs::remove_all(tmp, ec);
  check(dir);
  const fs::path tmp = temporary_sibling(dir, "tmp");
  const fs::path old = temporary_sibling(dir, "old");
  if (!fs::create_directory(tmp, ec) && ec) throw InputError(dir.string() + ": cannot write: " + ec.message());
  // A failure names what the user chose: the scratch folder's name becomes the folder's.
  auto as_users = [&](const std::string& message) {
    std::string out = message;
    const std::string scratch = tmp.string();
    for (std::size_t at; (at = out.find(scratch)) != std::string::npos;) out.replace(at, scratch.size(), dir.string());
    return out;
  };
  auto undo = [&] {  // the scratch copy goes; a folder moved aside comes back
    fs::remove_all(tmp, ec);
    if (!fs::exists(dir, ec) && fs::exists(old, ec)) fs::rename(old, dir, ec);
  };
  try {
    fill(tmp);
    if (fs::exists(fs::symlink_status(dir, ec))) fs::rename(dir, old);
    fs::rename(tmp, dir);
  } catch (const InputError& e) {
    undo();
    throw InputError(as_users(e.what()));
  } catch (const fs::filesystem_error& e) {
    undo();
    throw InputError(dir.string() + ": cannot write: " + e.code().message());
  } catch (...) {
    undo();
    throw;
  }
  fs::remove_all(old, ec);
}

std::vector<fs::path> dead_leftovers(const fs::path& target, std::string_view tag) {
  std::vector<fs::path> out;
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = leftover_prefix(target, tag);
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const char* digits = name.data() + prefix.size();
    const char* stop = name.data() + name.size();
    long pid = 0;
    const auto r = std::from_chars(digits, stop, pid);
    if (r.ec != std::errc() || r.ptr == digits || r.ptr == stop || *r.ptr != '-') continue;
    // A pid means something only on the host that wrote it (a shared folder sees several):
    // another host's leftovers are never judged. Names without a host tag predate it.
    const std::string_view rest(r.ptr + 1, static_cast<std::size_t>(stop - r.ptr - 1));
    if (rest.size() > 10 && rest[0] == 'h' && rest[9] == '-' && rest.substr(0, 9) != host_tag()) continue;
    if (!process_is_running(pid)) out.push_back(it->path());
  }
  return out;
}

AtomicFile::AtomicFile(fs::path path, const Ownership& owner, Leftovers leftovers) : path_(std::move(path)) {
  check_replaceable(path_, owner);
  if (leftovers == Leftovers::clean) {
    for (const auto& old : dead_leftovers(path_, "tmp")) {
      std::error_code ignored;
      if (fs::is_regular_file(old, ignored)) fs::remove(old, ignored);
    }
  }
  tmp_ = temporary_sibling(path_, "tmp");
  errno = 0;
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw InputError(path_.string() + ": cannot write: " + os_reason(errno));
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ignored;
    fs::remove(tmp_, ignored);
  }
}

namespace {

// Why writing to `file` fails: the stream keeps no reason, so one more byte is written to its
// end the plain way and the system's answer returned (ENOSPC, EDQUOT, EIO, EROFS), or 0.
int write_failure_reason(const fs::path& file) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd < 0) return errno;
  int reason = 0;
  if (::write(fd, "\n", 1) < 0) reason = errno;
  else if (::fsync(fd) != 0) reason = errno;
  ::close(fd);
  return reason;
}

}  // namespace

void AtomicFile::commit() {
  errno = 0;
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  const int flush_errno = ok ? 0 : errno;
  out_.close();
  if (!ok || out_.fail()) {
    const int reason = flush_errno ? flush_errno : write_failure_reason(tmp_);
    throw InputError(path_.string() + ": write failed: " + os_reason(reason));
  }
  std::error_code ec;
  fs::rename(tmp_, path_, ec);
  if (ec) throw InputError(path_.string() + ": cannot put the new file in place: " + ec.message());
  committed_ = true;
}

std::string os_reason(int error) {
  if (error == 0) return "the operating system gave no reason (a stream error)";
  return std::system_category().message(error);
}

}  // namespace dicestack
