#pragma once
// Demonstrations that travel: robomimic's and Minari's HDF5 layouts, written from and read into
// dicestack's DemoSet (docs/datasets.md, "robomimic and Minari"). This library alone links HDF5,
// so the other libraries (and every regressor plugin) never load it. Debian's HDF5 is the serial
// build, which is not thread-safe: call these functions from one thread at a time.
#include <array>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <dicestack/datasets/demo_set.hpp>

namespace dicestack {

/// The Gymnasium id of dicestack's environment (the Python package registers it); robomimic's
/// env_args and Minari's dataset id name it.
inline constexpr const char* kGymEnvId = "dicestack/DiceStack-v0";
/// robomimic's EnvType.GYM_TYPE: env_args "type" for an environment made with gym.make.
inline constexpr int kRobomimicGymType = 2;
/// Marker of our robomimic files (JSON attribute "dicestack" of /data: "format") and of our Minari
/// folders (metadata.json's "dicestack" object); an export replaces only a file or folder with it.
inline constexpr const char* kRobomimicFormat = "dicestack-robomimic";
inline constexpr const char* kMinariFormat = "dicestack-minari";
inline constexpr int kInteropFormatVersion = 1;
/// The Minari release whose on-disk layout (HDF5 storage) the Minari export follows.
inline constexpr const char* kMinariVersion = "0.5.3";

/// One robomimic observation key: three numbers of the 24-number state.
struct ObservationKey {
  const char* name;                   ///< "cup_pose", "cup_vel", "die0_pose", ...
  std::array<std::size_t, 3> index;   ///< state indices, in order
};
/// cup_pose (x, y, angle), cup_vel (vx, vy, w), die<i>_pose, die<i>_vel for i = 0, 1, 2.
std::span<const ObservationKey> observation_keys();

/// Throws InputError naming (up to 10 of) the episodes without a final state, rewards and end
/// flags (Episode::has_transitions()); `where` starts the message.
void require_transitions(const std::vector<Episode>& episodes, const std::string& where);

/// Writes `set` in robomimic's layout to `file` (docs/datasets.md lists every field): actions
/// divided by the world's action limits (so within [-1, 1]), states, rewards, dones, obs and
/// next_obs, num_samples, data's total and env_args, and mask/train and mask/valid from
/// is_test_episode (episode i is valid when i % 5 == 4). Every episode needs its transitions.
/// The file is built in memory and written atomically; an existing file at `file` is replaced
/// only when it is one of our exports. Throws InputError.
void export_robomimic(const DemoSet& set, const std::filesystem::path& file);

/// Reads a robomimic file of dicestack's environment back into a set: everything our export
/// writes comes back exactly. Files without our extra attributes (e.g. written by robomimic's
/// run_trained_agent) get names episode_<i>, seed 0, source `policy` and an outcome judged on
/// their states. Refuses, naming the path inside the file: a missing group, dataset or
/// attribute, a wrong shape or dtype, NaN or infinity, actions outside [-1, 1], obs/next_obs that
/// disagree with states, an env_args of another environment. Throws InputError.
DemoSet import_robomimic(const std::filesystem::path& file);

/// Writes `set` as a Minari dataset: `dir`/data/main_data.hdf5 (episode_<i> groups with
/// observations T + 1 x 24, actions T x 3 in world units, rewards, terminations, truncations;
/// attributes id, seed, total_steps) and `dir`/data/metadata.json (Minari 0.5.3's fields).
/// `dataset_id` follows Minari's "(namespace/)name-v<version>". The folder is filled beside
/// `dir` and renamed into place; an existing `dir` is replaced only when it is missing, empty
/// or one of our exports. Throws InputError.
void export_minari(const DemoSet& set, const std::filesystem::path& dir, const std::string& dataset_id);

/// Reads a Minari dataset folder (`dir`/data/...) of dicestack's environment back into a set,
/// exactly for what our export writes; other Minari datasets with a 24-number observation and
/// a 3-number action are read with `world` (their episodes named episode_<i>, source `policy`).
/// Refuses bad files as import_robomimic does. Throws InputError.
DemoSet import_minari(const std::filesystem::path& dir, const WorldConfig& world = {});

/// A Minari dataset id for a set folder: "dicestack/<folder name, cleaned>-v0".
std::string default_minari_dataset_id(const std::filesystem::path& set_dir);

}  // namespace dicestack
