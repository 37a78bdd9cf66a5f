#pragma once
// What every page dicestack writes shares: its first line (which makes it ours to replace), JSON
// safe inside <script>, the marker files that make a page's folder ours, the sortable table page
// that the leaderboard's page and the robustness page are made of, and a page written with its
// media folder as one unit.
#include <filesystem>
#include <functional>
#include <string>

#include <dicestack/core/atomic_file.hpp>

namespace dicestack {

/// The first line of a page dicestack wrote (the ownership test of --out).
inline constexpr const char* kResultsPageMarker = "<!-- dicestack results page -->";

/// Which existing pages --out may replace: those that start with kResultsPageMarker.
Ownership results_page_ownership();

/// The media folder of the page at `page`: "<stem>_files" beside it.
std::filesystem::path page_media_folder(const std::filesystem::path& page);

}  // namespace dicestack

namespace dicestack::page {

/// `text` (JSON) with "<", ">" and "&" written as \u escapes, so that it can sit inside
/// <script> and read back the same.
std::string script_safe(const std::string& text);

/// `name` as one segment of a relative URL: every byte but letters, digits and "-._~" %-escaped
/// (a page's folder may be named "my #1 board_files").
std::string url_segment(const std::string& name);

/// True when `folder` is a real folder (not a link) holding `marker`, a JSON object with
/// "format": `format`.
bool is_marked_folder(const std::filesystem::path& folder, const char* marker, const char* format);

/// Throws InputError unless nothing exists at `folder` or is_marked_folder; names `what` we write there.
void check_marked_folder(const std::filesystem::path& folder, const char* marker, const char* format, const std::string& what);

/// A page holding one sortable table, built by its script from `data_json` (inlined, made
/// script_safe): a JSON object with "title", "header", "facts" ([[name, value], ...]) and "rows"
/// (each with a "rank", the table's order). The shared script shows the title, header and facts
/// as text and defines `data`, el(), pct(), fixed(), rate(key) and sortableTable(columns, extra);
/// `script` runs after it, defines the columns and calls sortableTable once. No network: the
/// style and scripts are inside the page. Without the marker line (the caller writes it).
std::string table_page_html(const std::string& data_json, const char* script);

/// Writes the marker file `file` ({"format": format, "version": version, ...}).
void write_marker(const std::filesystem::path& file, const char* format, int version = 1);

/// A page's media folder: where it is and the marker that makes it ours.
struct MediaFolder {
  std::filesystem::path folder;  ///< "<stem>_files" beside the page
  const char* marker;            ///< the marker file's name inside it
  const char* format;            ///< the marker's "format"
  std::string what;              ///< what it is, for messages ("results page's media folder")
};

/// The version of a media folder written by write_page_with_media: its files sit in a generation
/// folder inside it ("m-" and 16 hex digits of their digest), which the page links.
inline constexpr int kMediaGenerationsVersion = 2;

/// Writes a page and its media as one unit. `fill` writes the media into an empty folder, which
/// becomes a new generation folder inside `media.folder`; `html` gets the generation's URL
/// relative to the page and returns the page. The page's rename over `page` is the commit: a
/// run killed before it leaves the old page and the generation it links, one killed after it the
/// new pair. Then every generation no page links is removed, and the leftovers of dead runs.
/// Replaces only a page that `page_owner` recognises and a media folder with our marker
/// (InputError, before anything is written). Throws InputError naming the page or the folder.
void write_page_with_media(const std::filesystem::path& page, const Ownership& page_owner, const MediaFolder& media,
                           const std::function<void(const std::filesystem::path&)>& fill,
                           const std::function<std::string(const std::string& media_url)>& html);

}  // namespace dicestack::page
