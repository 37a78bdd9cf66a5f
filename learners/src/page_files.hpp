#pragma once
// What the results pages and the episode viewer share: JSON safe inside <script>, and the
// marker files that make a page's folder ours to replace.
#include <filesystem>
#include <string>

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

/// Writes the marker file `file` ({"format": format, "version": 1, ...}).
void write_marker(const std::filesystem::path& file, const char* format);

}  // namespace dicestack::page
