// The episode CSV: one file per episode of a demonstration folder (docs/formats.md), written and
// read here; demo_set.cpp holds the folder around the files.
#include "episode_csv.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/read_file.hpp>
#include <dicestack/datasets/demo_set.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kColumnsV1 = 1 + kStateDim + kActionDim + 1;  // t, state, action, source
constexpr std::size_t kColumnsV2 = kColumnsV1 + 1;                   // and reward
constexpr std::size_t kCsvLinkColumns = 6;                              // an arm's three link angles, then their rates
constexpr std::size_t kCsvTorqueColumns = 4;                            // the torques its four joints held
constexpr std::size_t kColumnsV4 = kColumnsV2 + kCsvLinkColumns + kCsvTorqueColumns;  // and, on an arm, those
constexpr std::size_t kColumnsV4Torques = kColumnsV4 + kJointCount - kActionDim;  // the same, its actions joint torques

// A file's columns: its format version and what its actions command.
struct CsvLayout {
  int version = 2;
  ActionKind actions = ActionKind::cup;
  std::size_t source() const { return 1 + kStateDim + action_dim(actions); }  // t, state, action, then source
  std::size_t arm() const { return source() + 2; }                            // after source and reward
};

// Splits one CSV line on commas (no quoting: none of our fields contain commas).
void split_fields(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    out.push_back(line.substr(start, comma == std::string_view::npos ? comma : comma - start));
    if (comma == std::string_view::npos) return;
    start = comma + 1;
  }
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}


// Checks a CSV header row (any layout's columns, in order); sets `columns` to its column names
// and returns its layout (version 1, 2, or 4 for an arm's episode, whose actions may be torques).
CsvLayout check_csv_header(const std::vector<std::string_view>& fields, const std::string& prefix, std::vector<std::string>& columns) {
  const std::size_t width = fields.size();
  if (width != kColumnsV1 && width != kColumnsV2 && width != kColumnsV4 && width != kColumnsV4Torques)
    throw InputError(prefix + "header has " + std::to_string(width) + " columns, expected " + std::to_string(kColumnsV1) +
                     " (t, 24 state names, dvx, dvy, dw, source: format version 1), " + std::to_string(kColumnsV2) +
                     " (the same and reward: version 2), " + std::to_string(kColumnsV4) +
                     " (those, the arm's link angles and rates and its joint torques: version 4) or " +
                     std::to_string(kColumnsV4Torques) + " (the same with joint0_action to joint3_action: an arm's episode in joint torques)");
  CsvLayout layout;
  layout.version = width == kColumnsV1 ? 1 : width == kColumnsV2 ? 2 : 4;
  if (width == kColumnsV4Torques) layout.actions = ActionKind::joint_torque;
  columns = episode_csv_columns(layout.version, layout.actions);
  for (std::size_t c = 0; c < width; ++c)
    if (trim(fields[c]) != columns[c])
      throw InputError(prefix + "column " + std::to_string(c + 1) + " is \"" + std::string(trim(fields[c]).substr(0, 40)) +
                       "\", expected \"" + columns[c] + "\"");
  return layout;
}

// Column `c` of a row, a finite number.
double parse_csv_number(const std::vector<std::string_view>& fields, std::size_t c, const std::string& prefix,
                        const std::vector<std::string>& columns) {
  const std::string_view f = trim(fields[c]);
  double v = 0.0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
  if (f.empty() || r.ec != std::errc() || r.ptr != f.data() + f.size())
    throw InputError(prefix + "column \"" + columns[c] + "\": \"" + std::string(f.substr(0, 40)) +
                     (f.size() > 40 ? "...\"" : "\"") + " is not a number");
  if (!std::isfinite(v))
    throw InputError(prefix + "column \"" + columns[c] + "\" is " + (std::isnan(v) ? "NaN" : "infinite") +
                     "; demonstrations must be finite");
  return v;
}


// A version-4 row's arm columns, after the reward: the links (numbers) and the joint torques,
// numbers in every row or (unknown) empty in every row, as line 2's (`torques_empty`).
void parse_csv_arm(const std::vector<std::string_view>& fields, std::size_t first, const std::string& prefix,
                   const std::vector<std::string>& columns, bool& torques_empty, Episode& e) {
  ArmLinks& l = e.links.emplace_back();
  for (std::size_t i = 0; i < 3; ++i) {
    l.angles[i] = parse_csv_number(fields, first + i, prefix, columns);
    l.rates[i] = parse_csv_number(fields, first + 3 + i, prefix, columns);
  }
  const std::size_t torque = first + kCsvLinkColumns;
  bool empty = true;
  for (std::size_t j = 0; j < kCsvTorqueColumns; ++j) empty = empty && trim(fields[torque + j]).empty();
  if (e.states.size() == 1) torques_empty = empty;
  if (empty != torques_empty)
    throw InputError(prefix + "the joint torques are " + (empty ? "empty" : "numbers") + " but line 2's are " +
                     (torques_empty ? "empty" : "numbers") + "; an episode's joint torques are all known or all empty");
  if (empty) return;
  std::array<double, kCsvTorqueColumns>& tau = e.joint_torques.emplace_back();
  for (std::size_t j = 0; j < kCsvTorqueColumns; ++j) tau[j] = parse_csv_number(fields, torque + j, prefix, columns);
}

// The reward cell `f` of the row just appended to `e`: empty in every row (unknown, as in the
// first row, which sets `reward_empty`) or a finite number in every row.
void parse_csv_reward(std::string_view f, const std::string& prefix, bool& reward_empty, Episode& e) {
  if (e.states.size() == 1) reward_empty = f.empty();
  if (f.empty() != reward_empty)
    throw InputError(prefix + "column \"reward\" is " + (f.empty() ? "empty" : "a number") + " but line 2's is " +
                     (reward_empty ? "empty" : "a number") + "; an episode's rewards are all known or all empty");
  if (f.empty()) return;
  double v = 0.0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
  if (r.ec != std::errc() || r.ptr != f.data() + f.size())
    throw InputError(prefix + "column \"reward\": \"" + std::string(f.substr(0, 40)) + (f.size() > 40 ? "...\"" : "\"") +
                     " is not a number");
  if (!std::isfinite(v))
    throw InputError(prefix + "column \"reward\" is " + (std::isnan(v) ? "NaN" : "infinite") + "; demonstrations must be finite");
  e.rewards.push_back(v);
}

// Appends one data row (its width already checked) to `e`: the next step's state, action,
// source, from version 2 its reward and in version 4 the arm's links and joint torques.
void append_csv_row(const std::vector<std::string_view>& fields, const std::string& prefix,
                    const std::vector<std::string>& columns, const CsvLayout& layout, bool& reward_empty, bool& torques_empty,
                    Episode& e) {
  const double t = parse_csv_number(fields, 0, prefix, columns);
  const double expected_t = static_cast<double>(e.states.size());
  if (t != expected_t)
    throw InputError(prefix + "column \"t\" is " + episode_csv::number_text(t) + ", expected " + episode_csv::number_text(expected_t) +
                     " (rows are consecutive steps from 0)");
  State s;
  for (std::size_t k = 0; k < kStateDim; ++k) s[k] = parse_csv_number(fields, 1 + k, prefix, columns);
  Action a = Action::zeros(layout.actions);
  for (std::size_t k = 0; k < a.size(); ++k) a[k] = parse_csv_number(fields, 1 + kStateDim + k, prefix, columns);
  e.states.push_back(s);
  e.actions.push_back(a);
  try {
    e.sources.push_back(step_source_from(trim(fields[layout.source()])));
  } catch (const InputError& err) {
    throw InputError(prefix + "column \"source\": " + err.what());
  }
  if (layout.version >= 2) parse_csv_reward(trim(fields[layout.source() + 1]), prefix, reward_empty, e);
  if (layout.version >= 4) parse_csv_arm(fields, layout.arm(), prefix, columns, torques_empty, e);
}

std::string csv_header(int version, ActionKind actions = ActionKind::cup) {
  std::string header;
  for (const auto& c : episode_csv_columns(version, actions)) header += (header.empty() ? "" : ",") + c;
  return header;
}

}  // namespace

namespace episode_csv {

std::string number_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest text that reads back exactly
  return std::string(buf, r.ptr);
}

void write(const Episode& e, const fs::path& path, AtomicFile::Leftovers leftovers) {
  // The writers check the episode first (check_episode: one kind of action, links beside joint
  // torques), before any file is made.
  const ActionKind kind = e.actions.empty() ? ActionKind::cup : e.actions.front().kind();
  AtomicFile file(path, ownership(), leftovers);
  auto& out = file.stream();
  // An arm's episode adds its links and joint torques; any other keeps version 2's columns, byte
  // for byte.
  const bool arm = !e.links.empty();
  out << csv_header(arm ? 4 : 2, kind) << '\n';
  for (std::size_t t = 0; t < e.states.size(); ++t) {
    out << t;
    for (double v : e.states[t]) out << ',' << number_text(v);
    for (double v : e.actions[t]) out << ',' << number_text(v);
    out << ',' << to_string(e.sources[t]) << ',';
    if (e.has_transitions()) out << number_text(e.rewards[t]);  // empty cell: unknown
    if (arm) {
      for (double v : e.links[t].angles) out << ',' << number_text(v);
      for (double v : e.links[t].rates) out << ',' << number_text(v);
      for (std::size_t j = 0; j < kCsvTorqueColumns; ++j)
        out << ',' << (e.joint_torques.empty() ? std::string() : number_text(e.joint_torques[t][j]));  // empty: unknown
    }
    out << '\n';
  }
  file.commit();
}

Ownership ownership() {
  return Ownership::first_line("dicestack episode CSV",
                               {csv_header(1), csv_header(2), csv_header(4), csv_header(4, ActionKind::joint_torque)});
}

Episode parse(std::string_view text, const std::string& where, std::string name, int& version) {
  std::vector<std::string> columns;
  std::size_t width = 0;
  bool reward_empty = false, torques_empty = false;
  CsvLayout layout;
  Episode e;
  e.name = std::move(name);
  std::vector<std::string_view> fields;
  std::size_t line_no = 0, pos = 0;
  while (pos < text.size()) {
    const auto nl = text.find('\n', pos);
    const std::string_view line = text.substr(pos, (nl == std::string_view::npos ? text.size() : nl) - pos);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    ++line_no;
    const std::string prefix = where + ":" + std::to_string(line_no) + ": ";
    if (trim(line).empty()) {
      if (pos >= text.size()) break;  // trailing blank line
      throw InputError(prefix + "empty line inside the file");
    }
    split_fields(line, fields);
    if (line_no == 1) {
      layout = check_csv_header(fields, prefix, columns);
      version = layout.version;
      width = fields.size();
      continue;
    }
    if (fields.size() != width)
      throw InputError(prefix + "row has " + std::to_string(fields.size()) + " columns, expected " +
                       std::to_string(width) + (nl == std::string_view::npos ? " (truncated last line?)" : ""));
    append_csv_row(fields, prefix, columns, layout, reward_empty, torques_empty, e);
  }
  if (line_no == 0) throw InputError(where + ": empty file (expected a header row)");
  if (e.states.empty()) throw InputError(where + ": no steps (an episode needs at least one row)");
  return e;
}

}  // namespace episode_csv

std::vector<std::string> episode_csv_columns(int version, ActionKind actions) {
  std::vector<std::string> cols{"t"};
  for (auto n : state_names()) cols.emplace_back(n);
  if (actions == ActionKind::cup)
    for (auto n : action_names()) cols.emplace_back(n);
  else
    for (int j = 0; j < 4; ++j) cols.push_back("joint" + std::to_string(j) + "_action");
  cols.emplace_back("source");
  if (version >= 2) cols.emplace_back("reward");
  if (version < 4) return cols;
  for (const char* what : {"angle", "rate"})
    for (int i = 0; i < 3; ++i) cols.push_back("link" + std::to_string(i) + "_" + what);
  for (int j = 0; j < 4; ++j) cols.push_back("joint" + std::to_string(j) + "_torque");
  return cols;
}

Episode read_episode_csv(const fs::path& file) {
  return parse_episode_csv(read_file(file), file.string(), file.stem().string());
}

Episode parse_episode_csv(std::string_view text, const std::string& where, std::string name) {
  int version = 0;
  return episode_csv::parse(text, where, std::move(name), version);
}

}  // namespace dicestack
