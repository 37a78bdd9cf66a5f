// A page and its media folder written as one unit (page_files.hpp, write_page_with_media).
#include <algorithm>
#include <cstdio>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/read_file.hpp>

#include <dicestack/pages/page.hpp>

namespace dicestack::page {
namespace {

namespace fs = std::filesystem;

constexpr const char* kGenerationPrefix = "m-";
constexpr std::size_t kGenerationDigits = 16;
constexpr const char* kScratchTag = "tmp";

// The name scratch generations are made beside (temporary_sibling, dead_leftovers).
fs::path scratch_anchor(const fs::path& folder) { return folder / "generation"; }

bool is_generation_name(const std::string& name) {
  return name.size() == 2 + kGenerationDigits && name.starts_with(kGenerationPrefix) &&
         std::all_of(name.begin() + 2, name.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
}

// A digest of every file under `folder` (their relative paths and bytes, in path order): the
// same media, the same generation name, on any run.
std::string generation_name(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(folder))
    if (entry.is_regular_file()) files.push_back(fs::relative(entry.path(), folder));
  std::sort(files.begin(), files.end());
  std::uint64_t digest = fnv1a("dicestack media");
  for (const auto& f : files) {
    digest = fnv1a(f.generic_string() + '\0', digest);
    digest = fnv1a(read_file(folder / f), digest);
  }
  char hex[kGenerationDigits + 1];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(digest));
  return kGenerationPrefix + std::string(hex);
}

// The generation the page now at `page` links, if it is a page of ours linking one.
std::string linked_generation(const fs::path& page, const Ownership& owner, const std::string& folder_url) {
  std::error_code ec;
  if (!fs::is_regular_file(page, ec) || !owner.recognises(page)) return {};
  const std::string text = read_file(page);
  const std::string link = folder_url + "/" + kGenerationPrefix;
  const std::size_t at = text.find(link);
  if (at == std::string::npos) return {};
  const std::string name = text.substr(at + folder_url.size() + 1, 2 + kGenerationDigits);
  return is_generation_name(name) ? name : std::string();
}

// The "version" in a marker file (0 when it has none or cannot be read).
int marker_version(const fs::path& marker) {
  try {
    const auto j = nlohmann::json::parse(read_file(marker, 1 << 16));
    return j.contains("version") && j["version"].is_number_integer() ? j["version"].get<int>() : 0;
  } catch (const std::exception&) {
    return 0;
  }
}

// Creates the media folder with its marker, whole (a folder of ours appears or nothing does).
// First removes what runs killed while creating it left beside it.
void create_media_folder(const MediaFolder& media) {
  std::error_code ec;
  for (const auto& dead : dead_leftovers(media.folder, "tmp"))
    if (fs::is_directory(fs::symlink_status(dead, ec))) fs::remove_all(dead, ec);  // named as only our scratch is
  const fs::path tmp = temporary_sibling(media.folder, "tmp");
  try {
    fs::create_directories(tmp);
    write_marker(tmp / media.marker, media.format, kMediaGenerationsVersion);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  fs::rename(tmp, media.folder, ec);
  if (!ec) return;
  const std::error_code failed = ec;
  fs::remove_all(tmp, ec);
  // Another run made it first: theirs is as good, if it is ours. Any other failure is this one's.
  if (!fs::exists(fs::symlink_status(media.folder, ec)))
    throw InputError(media.folder.string() + ": cannot write: " + failed.message());
  check_marked_folder(media.folder, media.marker, media.format, media.what);
}

// Removes what no page links: other generations, an older layout's files and dead runs' scratch.
void prune(const MediaFolder& media, const std::set<std::string>& keep) {
  std::error_code ec;
  std::set<fs::path> dead;  // killed runs' scratch generations, and their half-written markers
  for (const auto& p : dead_leftovers(scratch_anchor(media.folder), kScratchTag)) dead.insert(p);
  for (const auto& p : dead_leftovers(media.folder / media.marker, "tmp")) dead.insert(p);
  std::vector<fs::path> gone;
  for (fs::directory_iterator it(media.folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name == media.marker || keep.contains(name)) continue;
    if (name.starts_with(".") && !dead.contains(it->path())) continue;  // a live run's scratch, or not ours
    gone.push_back(it->path());
  }
  for (const auto& p : gone) fs::remove_all(p, ec);
}

}  // namespace

void write_page_with_media(const fs::path& page, const Ownership& page_owner, const MediaFolder& media,
                           const std::function<void(const fs::path&)>& fill,
                           const std::function<std::string(const std::string& media_url)>& html) {
  check_replaceable(page, page_owner);
  check_marked_folder(media.folder, media.marker, media.format, media.what);
  const std::string folder_url = url_segment(media.folder.filename().string());
  fs::path scratch;
  try {
    if (!fs::exists(fs::symlink_status(media.folder))) create_media_folder(media);
    scratch = temporary_sibling(scratch_anchor(media.folder), kScratchTag);
    fs::create_directory(scratch);
    fill(scratch);
    const std::string generation = generation_name(scratch);
    const fs::path target = media.folder / generation;
    if (fs::exists(target)) {
      fs::remove_all(scratch);  // the same media are there already
    } else {
      fs::rename(scratch, target);
    }
    scratch.clear();
    AtomicFile f(page, page_owner);
    f.stream() << html(folder_url + "/" + generation);
    f.commit();  // the commit of the pair
    prune(media, {generation, linked_generation(page, page_owner, folder_url)});
    // A folder of the older layout (its files at the top, pruned just now) is now one of generations.
    if (marker_version(media.folder / media.marker) != kMediaGenerationsVersion)
      write_marker(media.folder / media.marker, media.format, kMediaGenerationsVersion);
  } catch (const fs::filesystem_error& e) {
    std::error_code ec;
    if (!scratch.empty()) fs::remove_all(scratch, ec);
    throw InputError(media.folder.string() + ": cannot write: " + e.code().message());
  } catch (const InputError& e) {  // a failure names the folder the user chose, not the scratch one
    std::error_code ec;
    std::string message = e.what();
    if (!scratch.empty()) {
      fs::remove_all(scratch, ec);
      for (std::size_t at; (at = message.find(scratch.string())) != std::string::npos;)
        message.replace(at, scratch.string().size(), media.folder.string());
    }
    throw InputError(message);
  } catch (...) {
    std::error_code ec;
    if (!scratch.empty()) fs::remove_all(scratch, ec);
    throw;
  }
}

}  // namespace dicestack::page
