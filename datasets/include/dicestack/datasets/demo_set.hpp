#pragma once
// The on-disk demonstration format: a folder with one CSV per episode (header naming every
// column: t, the 24 state names, dvx, dvy, dw, source) and a versioned meta.json (format,
// units, world config, provenance, per-episode outcomes). Opens in any spreadsheet or pandas.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/episode.hpp>

namespace dicestack {

inline constexpr const char* kDemoFormat = "dicestack-demos";
/// Version 2 adds each episode's final state, terminated and truncated (meta.json) and the
/// reward of each step (a `reward` column); version 3 each episode's perturbation (the values
/// its perturbed world drew), written only by sets that hold one, so that nominal sets stay
/// byte for byte version 2; version 4 an arm's readings (its links and joint torques at each
/// step, columns of their own, and its final links), written only by sets that hold an arm's
/// episode; version 5 an arm's perturbation drawn in joint torques too (the bias and noise a
/// policy in joint torques met), written only by sets that hold such a perturbation. Older
/// folders stay readable (docs/formats.md).
inline constexpr int kDemoFormatVersion = 5;
/// Format marker of the JSON summaries the baselines (optimise, reinforce, rrt) write into a set.
inline constexpr const char* kBaselineFormat = "dicestack-baseline";

/// A folder of episodes and what meta.json says about them.
struct DemoSet {
  WorldConfig world;        ///< the world the episodes were recorded in
  std::string description;  ///< one line for people
  std::string provenance;   ///< how the set was made (command, source files, seeds)
  std::vector<Episode> episodes;  ///< in file-name order
};

/// The header row of an episode CSV of format `version` (1: t, 24 state names, dvx, dvy, dw,
/// source; 2 and 3: those and reward; 4, an arm's episode: those, link0_angle to link2_angle,
/// link0_rate to link2_rate and joint0_torque to joint3_torque). An arm's episode whose actions
/// are joint torques has joint0_action to joint3_action (N m) where dvx, dvy, dw stand.
std::vector<std::string> episode_csv_columns(int version = kDemoFormatVersion, ActionKind actions = ActionKind::cup);

/// Reads a whole set, checking everything: meta.json's format and version, that its episode
/// list matches the CSV files exactly, every header, row and value (finite numbers, known
/// sources, consecutive t). Throws InputError with "path:line:" and the column at fault;
/// never returns a partial set.
DemoSet read_demo_set(const std::filesystem::path& dir);

/// Reads one episode CSV (name = the file stem). Throws InputError as read_demo_set does.
Episode read_episode_csv(const std::filesystem::path& file);

/// What read_episode_csv does with a file's text, for callers that hold the text (the fuzzer,
/// tests): `where` starts every message ("where:line: ..."), `name` becomes Episode::name. Checks
/// the header (either version's), every row and value; a version-2 file's reward cells are all
/// numbers (into Episode::rewards) or all empty (unknown). Seed, outcome, origin, final state and
/// the end flags stay empty (meta.json has them). Throws InputError.
Episode parse_episode_csv(std::string_view text, const std::string& where, std::string name);

/// One entry of meta.json's "episodes" list.
struct DemoMetaEntry {
  std::string file;      ///< a file name inside the set's folder (no separators, not "." or "..")
  std::uint64_t seed = 0;
  std::size_t steps = 0;  ///< rows the file must have
  std::string origin;
  Outcome outcome;
  std::optional<State> final_state;  ///< version 2's "final_state" (null or absent: unknown)
  bool terminated = false;           ///< version 2's "terminated"
  bool truncated = false;            ///< version 2's "truncated"
  std::string perturbation;          ///< version 3's "perturbation" (a JSON object), or empty
  bool arm = false;                  ///< version 4: the entry has "final_links" (an arm's episode)
  std::optional<ArmLinks> final_links;  ///< version 4's "final_links" (null: unknown)
};

/// What a set's meta.json says, checked on its own (no episode file is opened).
struct DemoMeta {
  int version = kDemoFormatVersion;  ///< the file's format version (1 to 5)
  WorldConfig world;
  std::string description;
  std::string provenance;
  std::vector<DemoMetaEntry> episodes;  ///< in the file's order; each file named once
};

/// Parses meta.json's text as read_demo_set does: format and version, the world config, and
/// every episode entry (file name, seed, steps, outcome; integers never narrowed). `where` (the
/// path) starts every message. Throws InputError, or ConfigError for a bad "world".
DemoMeta parse_demo_meta(std::string_view text, const std::filesystem::path& where);

/// True when `dir` is a demonstration set dicestack wrote, so one of our writers may replace or
/// remove it: meta.json parses with "format": "dicestack-demos" and every entry is meta.json, an
/// episode CSV it lists, a sidecar JSON with "format": "dicestack-baseline", or one of our
/// scratch files; or (what rrt wrote when it found no path, before) it has no meta.json and holds
/// only such sidecars. Otherwise false, with the reason in `why` ("it holds notes.txt").
bool is_own_demo_set(const std::filesystem::path& dir, std::string* why = nullptr);

/// Throws InputError unless `dir` is missing, an empty folder, or is_own_demo_set: "DIR: exists and
/// is not a dicestack demonstration set (it holds notes.txt); refusing to replace it: ...".
void check_demo_set_replaceable(const std::filesystem::path& dir);

/// Writes a set into `dir` (created, or replaced whole if check_demo_set_replaceable allows it):
/// files go to a temporary folder (".<name>.tmp-<pid>-<unique>") renamed into place, so a failure
/// never leaves half a set. Dead runs' scratch folders of `dir` are removed first (a live run's
/// never). Throws InputError.
void write_demo_set(const DemoSet& set, const std::filesystem::path& dir);

/// write_demo_set with sidecar files (file name -> bytes: a baseline's summary JSON with
/// kBaselineFormat, which is_own_demo_set accepts beside a set) written into the temporary folder
/// too, so the set and its sidecars replace `dir` together: a kill never leaves a new set beside
/// an old summary, or none. A name must be a plain file name, not meta.json nor a .csv. Throws InputError.
void write_demo_set(const DemoSet& set, const std::filesystem::path& dir, const std::map<std::string, std::string>& sidecars);

/// Receives the episodes of write_demo_set_streaming, in order.
using EpisodeSink = std::function<void(const Episode&)>;

/// write_demo_set for a set too large to hold (record): `produce(add)` calls add(episode) for
/// each episode in order; each is checked and written into the scratch folder as it comes, and
/// meta.json last, from `header` (world, description, provenance; its episodes are not read).
/// The folder replaces `dir` only when produce returns; a throw from produce or add leaves `dir`
/// as it was. Holds one meta.json entry per episode, not its steps. Returns the number written.
std::size_t write_demo_set_streaming(const DemoSet& header, const std::filesystem::path& dir,
                                     const std::function<void(const EpisodeSink&)>& produce);

/// What write_demo_set_streaming holds per episode, at most (its meta.json entry): for memory
/// checks before a long recording.
inline constexpr double kEpisodeEntryBytes = 8192.0;

/// Appends episodes to the set in `dir` (created if missing or empty; any other folder without a
/// meta.json is refused with InputError) and rewrites its meta.json
/// atomically; new episodes get the next free names. Returns the names given.
std::vector<std::string> append_to_demo_set(const std::filesystem::path& dir, std::vector<Episode> episodes,
                                            const WorldConfig& world, const std::string& description);

}  // namespace dicestack
