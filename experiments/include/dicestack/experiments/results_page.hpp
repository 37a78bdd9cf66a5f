#pragma once
// Results pages: a leaderboard (or one model's evaluation) as one self-contained HTML
// page that works from file:// with no network, and its media folder beside it: each row's
// per-episode results in the shape of LeRobot's eval_info.json, and a looping GIF of one
// successful and one failed rollout. docs/results-pages.md shows one.
#include <filesystem>
#include <string>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/pages/page.hpp>

namespace dicestack {

/// The page: the header facts, the table (sortable by any column, rates with their intervals)
/// and, per row, its previews and a link to its per-episode results, all under `media` (the
/// media's URL relative to the page, escaped: url_segment; empty: a page without media). Its data is inlined as
/// JSON and every text from the run (names, paths, options) is shown as text, never as markup.
std::string results_page_html(const Leaderboard& board, const std::string& media);

/// Throws InputError unless nothing exists at `folder` or it is a media folder dicestack wrote.
void check_page_media_replaceable(const std::filesystem::path& folder);

/// `leaderboard --format html --out PAGE.html`: the page and its media folder PAGE_files/, written
/// as one unit (a run killed at any point leaves the old page with its media, or the new pair).
/// The media sit in PAGE_files/m-<digest>/: eval_info/row-NN.json per row with rollouts,
/// previews/row-NN-success.gif and -failure.gif per row with previews; PAGE_files/ holds the
/// marker file dicestack-page.json. Replaces only a page and folder of ours. Throws InputError.
void write_results_page(const Leaderboard& board, const std::filesystem::path& page);

/// Throws InputError unless nothing exists at `dir` or it is a report dicestack wrote.
void check_report_replaceable(const std::filesystem::path& dir);

/// `dicestack evaluate --report DIR`: DIR holds index.html and its media folder index_files/,
/// written whole; an existing DIR is replaced only if it is a report dicestack wrote.
void write_report_folder(const Leaderboard& board, const std::filesystem::path& dir);

}  // namespace dicestack
