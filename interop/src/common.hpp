#pragma once
// What the robomimic and Minari readers and writers share (private to interop/).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/judge.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include "h5.hpp"

namespace dicestack::interop {

/// A dataset of exactly rows x cols numbers (cols 0: one dimension of rows); `integral` as
/// h5::read_numbers takes it. Throws InputError "WHERE: shape (3, 2), expected (4, 3)".
h5::Array read_shaped(hid_t loc, const std::string& name, const std::string& where, std::size_t rows, std::size_t cols,
                      bool integral = false);
/// A dataset of T >= 1 rows of `cols` floating-point numbers.
h5::Array read_rows(hid_t loc, const std::string& name, const std::string& where, std::size_t cols);

/// Per-step sources as runs: "expert:120,correction:3".
std::string sources_text(const std::vector<StepSource>& sources);
/// Reads sources_text's form back; throws InputError naming `where` unless it gives `steps` sources.
std::vector<StepSource> sources_from_text(const std::string& text, std::size_t steps, const std::string& where);

/// The outcome fields meta.json keeps (steps, dice_in_cup, stacked, wall_contact).
nlohmann::json outcome_json(const Outcome& outcome);
Outcome outcome_from_json(const nlohmann::json& j, const std::string& where);

/// The attributes both exports write on an episode's group (dicestack_name, the seed under
/// `seed_attr`, dicestack_origin, dicestack_sources, dicestack_outcome) into `e`, whose states
/// and final state are already read. Files of other tools lack them: episode_<index>, seed 0,
/// `default_origin`, every step "policy", and the judge over the states (as meta.json is read).
void read_episode_record(hid_t group, const std::string& where, std::size_t index, const char* seed_attr,
                         const std::string& default_origin, const WorldConfig& world, Episode& e);

/// check_episode, its message prefixed with `where` (the episode's path in the file).
void check_read_episode(const Episode& e, const std::string& where);

/// Parses JSON text from a file attribute, naming `where` if it is not JSON.
nlohmann::json parse_json_text(const std::string& text, const std::string& where);

/// The "dicestack" object both exports carry: marker, version, the writer's version, description, provenance.
nlohmann::json set_record(const DemoSet& set, const char* format);

/// Throws InputError naming `where` and the first episode whose actions are joint torques: the
/// exports carry the cup's actions (their action space is the cup's).
void require_cup_actions(const std::vector<Episode>& episodes, const std::string& where);
/// True when the episodes are an arm's: each has its links and its final links (the T + 1th
/// observation both exports carry); false when none has links. Throws InputError naming `where`
/// and the episodes otherwise.
bool arm_episodes(const std::vector<Episode>& episodes, const std::string& where);
/// An arm episode's link angles (or rates) at t = 0..T, the last its final links: 3 per row.
std::vector<double> link_rows(const Episode& e, bool rates);
/// The inverse of link_rows: T + 1 rows of angles and of rates into e.links and e.final_links.
void links_from_rows(const h5::Array& angles, const h5::Array& rates, Episode& e);


}  // namespace dicestack::interop
