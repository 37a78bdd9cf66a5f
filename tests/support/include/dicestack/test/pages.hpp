#pragma once
// A small leaderboard, and a written file or page read back, for the learners' tests of the
// leaderboard's formats and the results pages (include only where dicestack::learners and
// nlohmann_json are linked).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/initial_state.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/leaderboard.hpp>

namespace dicestack::test {

/// The whole file at `p`, as bytes.
inline std::string read(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The JSON a page inlines between its data script's tags.
inline nlohmann::json page_data(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"page-data\">";
  const auto from = page.find(open) + open.size();
  return nlohmann::json::parse(page.substr(from, page.find("</script>", from) - from));
}

/// Two learned rows (one with previews) and the playback row, as a run would leave them.
inline Leaderboard small_board(const std::string& name = "knn") {
  Leaderboard b;
  b.header = "test board";
  b.meta_json = R"({"demos": "d", "seed": 1})";
  LeaderboardRow a{name, "bc", "state"};
  for (int i = 0; i < 3; ++i) {
    EpisodeResult e;
    e.index = i;
    e.seed = 100u + static_cast<unsigned>(i);
    e.success = e.stacked = i == 1;
    e.wall_contact = i == 2;
    e.wall_step = i == 2 ? 7 : -1;
    e.length = 20;
    a.rollouts.push_back({0, e});
  }
  a.episodes = 3, a.success = a.stacked = 1, a.walls = 1;
  const State s = paper_start_state(b.world);
  a.success_preview.push_back({0, 1, 101, std::vector<State>(4, s)});
  a.failure_preview.push_back({0, 0, 100, std::vector<State>(3, s)});
  LeaderboardRow c{"linear_svr", "bc", "state"};
  c.rollouts = a.rollouts;
  c.episodes = 3;
  LeaderboardRow playback{"(demonstrations)", "playback"};
  b.rows = {a, c, playback};
  return b;
}

}  // namespace dicestack::test
