#pragma once
// The pages' scripts and styles. Each is a file in pages/resources/, edited as the language it
// is, and compiled in as a string (pages/CMakeLists.txt): a page needs nothing beside the tool.
namespace dicestack::page::resource {

/// The script every table page shares: reads the inlined data, shows the title, header and facts
/// (as text nodes), and sortableTable() builds the table from data.rows and sorts it by the
/// column whose header is clicked (again: the other way).
extern const char* const table_js;
/// The table page's style.
extern const char* const table_css;
/// The leaderboard's columns and its extra cells (previews, per-episode results) on table_js.
extern const char* const leaderboard_js;
/// The robustness page's columns on table_js; its levels sort by severity, not by name.
extern const char* const robustness_js;
/// The episode viewer's style and script.
extern const char* const viewer_css;
extern const char* const viewer_js;

}  // namespace dicestack::page::resource
