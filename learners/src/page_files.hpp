#pragma once
// What the results pages and the episode viewer share: JSON safe inside <script>, the marker
// files that make a page's folder ours to replace, and the sortable table page that the
// leaderboard's page and the robustness page are made of.
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

/// A page holding one sortable table, built by its script from `data_json` (inlined, made
/// script_safe): a JSON object with "title", "header", "facts" ([[name, value], ...]) and "rows"
/// (each with a "rank", the table's order). The shared script shows the title, header and facts
/// as text and defines `data`, el(), pct(), fixed(), rate(key) and sortableTable(columns, extra);
/// `script` runs after it, defines the columns and calls sortableTable once. No network: the
/// style and scripts are inside the page. Without the marker line (the caller writes it).
std::string table_page_html(const std::string& data_json, const char* script);

/// Writes the marker file `file` ({"format": format, "version": 1, ...}).
void write_marker(const std::filesystem::path& file, const char* format);

}  // namespace dicestack::page
