#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kData = fs::path(DICESTACK_TEST_DATA);
// The bad-input corpus (tests/corpus): each demonstration case's set is in <case>/set.
const fs::path kBadSets = fs::path(DICESTACK_SOURCE_DIR) / "tests" / "corpus" / "demos";

std::string read_error(const std::string& bad) {
  return test::error_of([&] { read_demo_set(kBadSets / bad / "set"); });
}

TEST(DemoSet, ReadsAValidSet) {
  const DemoSet set = read_demo_set(kData / "good");
  ASSERT_EQ(set.episodes.size(), 2u);
  EXPECT_EQ(set.episodes[0].name, "episode_0000");
  EXPECT_EQ(set.episodes[0].size(), 4u);
  EXPECT_EQ(set.episodes[1].seed, 1u);
  EXPECT_EQ(set.episodes[0].sources[1], StepSource::expert);
  EXPECT_DOUBLE_EQ(set.episodes[1].states[0][state_index::kCupX], 5.0);
  EXPECT_DOUBLE_EQ(set.episodes[0].actions[2][1], 0.1333);
  EXPECT_EQ(set.description, "tiny test set");
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(DemoSet, TextEntryPointsReadWhatTheFileReadersRead) {
  const Episode from_file = read_episode_csv(kData / "good" / "episode_0000.csv");
  const Episode from_text = parse_episode_csv(slurp(kData / "good" / "episode_0000.csv"), "in memory", "e0");
  EXPECT_EQ(from_text.name, "e0");
  EXPECT_EQ(from_text.states, from_file.states);
  EXPECT_EQ(from_text.actions, from_file.actions);
  EXPECT_EQ(from_text.sources, from_file.sources);
  EXPECT_THAT(test::error_of([] { parse_episode_csv("t,cup_x\n", "in memory", "e"); }),
              HasSubstr("in memory:1: header has 2 columns"));

  const DemoMeta meta = parse_demo_meta(slurp(kData / "good" / "meta.json"), "m.json");
  ASSERT_EQ(meta.episodes.size(), 2u);
  EXPECT_EQ(meta.episodes[1].file, "episode_0001.csv");
  EXPECT_EQ(meta.episodes[1].seed, 1u);
  EXPECT_EQ(meta.episodes[1].steps, 3u);
  EXPECT_EQ(meta.episodes[0].origin, "hand-made");
  EXPECT_EQ(meta.description, "tiny test set");
  EXPECT_THAT(test::error_of([] { parse_demo_meta("[]", "m.json"); }), HasSubstr("m.json: must be a JSON object"));
}

TEST(DemoSet, DeeplyNestedMetaIsRefusedNotCrashed) {
  const fs::path dir = fs::temp_directory_path() / ("dicestack_deep_meta_" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "meta.json") << "{\"format\":\"dicestack-demos\",\"version\":1,\"world\":"
                                   << std::string(200000, '[') << std::string(200000, ']') << "}";
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }), HasSubstr("meta.json: JSON nested deeper than 64 levels"));
  fs::remove_all(dir);
}

TEST(DemoSet, WriteThenReadIsExact) {
  DemoSet set = read_demo_set(kData / "good");
  set.episodes[0].states[1][5] = 0.1 + 0.2;  // not exactly representable in short decimal
  set.episodes[0].outcome.stacked = true;
  set.episodes[0].origin = "unit test";
  const fs::path dir = test::scratch_path("dicestack_demo_roundtrip");
  fs::remove_all(dir);
  write_demo_set(set, dir);
  const DemoSet back = read_demo_set(dir);
  ASSERT_EQ(back.episodes.size(), set.episodes.size());
  for (std::size_t i = 0; i < set.episodes.size(); ++i) {
    EXPECT_EQ(back.episodes[i].states, set.episodes[i].states);
    EXPECT_EQ(back.episodes[i].actions, set.episodes[i].actions);
    EXPECT_EQ(back.episodes[i].sources, set.episodes[i].sources);
  }
  EXPECT_TRUE(back.episodes[0].outcome.stacked);
  EXPECT_EQ(back.episodes[0].origin, "unit test");
  // Writing again replaces the folder whole; no temporary folders are left behind.
  set.episodes.pop_back();
  write_demo_set(set, dir);
  EXPECT_EQ(read_demo_set(dir).episodes.size(), 1u);
  for (const auto& entry : fs::directory_iterator(dir.parent_path()))
    EXPECT_EQ(entry.path().filename().string().find(".dicestack_demo_roundtrip."), std::string::npos);
  fs::remove_all(dir);
}

// Format v2: the final state, the rewards and the end flags travel with an episode; a v1 set
// (tests/datasets/data/good) reads as episodes without them.
TEST(DemoSet, VersionTwoKeepsTransitionsAndVersionOneReadsWithoutThem) {
  DemoSet set = read_demo_set(kData / "good");
  EXPECT_EQ(parse_demo_meta(slurp(kData / "good" / "meta.json"), "m.json").version, 1);
  for (const auto& e : set.episodes) EXPECT_FALSE(e.has_transitions());
  Episode& e = set.episodes[0];
  State last = e.states.back();
  last[0] += 0.1 + 0.2;
  e.final_state = last;
  for (std::size_t t = 0; t < e.size(); ++t) e.rewards.push_back(-0.1 * static_cast<double>(t) - 1e-17);
  e.terminated = true;
  const fs::path dir = fs::temp_directory_path() / ("dicestack_demo_v2_" + std::to_string(getpid()));
  fs::remove_all(dir);
  write_demo_set(set, dir);
  EXPECT_EQ(parse_demo_meta(slurp(dir / "meta.json"), "m.json").version, 2);
  const DemoSet back = read_demo_set(dir);
  ASSERT_TRUE(back.episodes[0].has_transitions());
  EXPECT_EQ(*back.episodes[0].final_state, last);
  EXPECT_EQ(back.episodes[0].rewards, e.rewards);
  EXPECT_TRUE(back.episodes[0].terminated);
  EXPECT_FALSE(back.episodes[0].truncated);
  EXPECT_FALSE(back.episodes[1].has_transitions()) << "unknown stays unknown";
  EXPECT_TRUE(back.episodes[1].rewards.empty());

  // Appending to a v1 set upgrades its meta.json; its v1 files read as before.
  const fs::path old = dir.string() + "_v1";
  fs::remove_all(old);
  fs::copy(kData / "good", old);
  append_to_demo_set(old, {back.episodes[0]}, back.world, "appended");
  const DemoSet appended = read_demo_set(old);
  ASSERT_EQ(appended.episodes.size(), 3u);
  EXPECT_FALSE(appended.episodes[0].has_transitions());
  EXPECT_EQ(appended.episodes[2].rewards, e.rewards);

  // A file and meta.json that disagree are refused, naming the file.
  std::string csv = slurp(dir / "episode_0000.csv");
  const auto cut = csv.find('\n', csv.find('\n') + 1);
  const auto comma = csv.rfind(',', cut);
  std::ofstream(dir / "episode_0000.csv", std::ios::binary) << csv.substr(0, comma + 1) + csv.substr(cut);
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }),
              HasSubstr("episode_0000.csv:3: column \"reward\" is a number but line 2's is empty"));
  std::ofstream(dir / "episode_0000.csv", std::ios::binary) << csv;
  std::string meta = slurp(dir / "meta.json");
  const auto at = meta.find("\"terminated\": true");
  ASSERT_NE(at, std::string::npos);
  std::ofstream(dir / "meta.json", std::ios::binary) << meta.substr(0, at) + "\"terminated\": 1" + meta.substr(at + 18);
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }), HasSubstr("meta.json: \"terminated\" must be true or false"));
  std::ofstream(dir / "meta.json", std::ios::binary) << meta;
  const auto v1 = slurp(kData / "good" / "meta.json");
  std::ofstream(dir / "meta.json", std::ios::binary) << v1;
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }),
              HasSubstr("episode_0000.csv:1: the header is format version 2's (with reward), but meta.json says version 1"));
  fs::remove_all(dir);
  fs::remove_all(old);
}

// Format v3: an episode's perturbation (the values its world drew) travels with it; a set
// without one is still written as version 2, byte for byte.
TEST(DemoSet, VersionThreeKeepsPerturbationsAndNominalSetsStayVersionTwo) {
  DemoSet set = read_demo_set(kData / "good");
  const fs::path dir = test::scratch_path("dicestack_demo_v3");
  fs::remove_all(dir);
  write_demo_set(set, dir);
  EXPECT_EQ(parse_demo_meta(slurp(dir / "meta.json"), "m.json").version, 2);
  fs::remove_all(dir);
  set.episodes[1].perturbation = R"({"action_delay":3,"dice_mass":0.05})";
  write_demo_set(set, dir);
  EXPECT_EQ(parse_demo_meta(slurp(dir / "meta.json"), "m.json").version, 3);
  const DemoSet back = read_demo_set(dir);
  EXPECT_TRUE(back.episodes[0].perturbation.empty());
  EXPECT_EQ(back.episodes[1].perturbation, set.episodes[1].perturbation);
  std::string meta = slurp(dir / "meta.json");
  const auto at = meta.find("\"perturbation\": {");
  ASSERT_NE(at, std::string::npos);
  std::ofstream(dir / "meta.json", std::ios::binary) << meta.substr(0, at) + "\"perturbation\": 7, \"ignored\": {" +
                                                             meta.substr(at + 17);
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }), HasSubstr("\"perturbation\" of episode_0001.csv must be an object"));
  fs::remove_all(dir);
}

TEST(DemoSet, AppendAddsEpisodesAndKeepsTheOldOnes) {
  const fs::path dir = test::scratch_path("dicestack_demo_append");
  fs::remove_all(dir);
  const DemoSet good = read_demo_set(kData / "good");
  auto names = append_to_demo_set(dir, {good.episodes[0]}, good.world, "appended");
  EXPECT_EQ(names, std::vector<std::string>{"episode_0000"});
  names = append_to_demo_set(dir, {good.episodes[1], good.episodes[0]}, good.world, "appended");
  EXPECT_EQ(names, (std::vector<std::string>{"episode_0001", "episode_0002"}));
  const DemoSet back = read_demo_set(dir);
  EXPECT_EQ(back.episodes.size(), 3u);
  EXPECT_EQ(back.episodes[1].size(), good.episodes[1].size());
  fs::remove_all(dir);
}

TEST(DemoSet, StreamingWriterWritesWhatTheWholeSetWriterWrites) {
  DemoSet set = read_demo_set(kData / "good");
  set.description = "streamed";
  set.provenance = "unit test";
  const fs::path whole = test::scratch_path("dicestack_demo_whole"), streamed = test::scratch_path("dicestack_demo_streamed");
  fs::remove_all(whole);
  fs::remove_all(streamed);
  write_demo_set(set, whole);
  DemoSet header = set;
  header.episodes.clear();  // not read: the episodes come from produce
  const std::size_t n = write_demo_set_streaming(header, streamed, [&](const EpisodeSink& add) {
    for (const auto& e : set.episodes) add(e);
  });
  EXPECT_EQ(n, set.episodes.size());
  for (const auto& entry : fs::directory_iterator(whole)) {
    const auto name = entry.path().filename();
    EXPECT_EQ(slurp(entry.path()), slurp(streamed / name)) << name;
  }
  // A failure halfway (here a malformed episode after a good one) leaves the old set as it was
  // and no scratch folder.
  DemoSet bad = set;
  bad.episodes[1].actions.pop_back();
  EXPECT_THAT(test::error_of([&] {
                write_demo_set_streaming(header, streamed, [&](const EpisodeSink& add) {
                  for (const auto& e : bad.episodes) add(e);
                });
              }),
              HasSubstr("3 states, 2 actions"));
  EXPECT_EQ(read_demo_set(streamed).description, "streamed");
  EXPECT_EQ(read_demo_set(streamed).episodes.size(), 2u);
  for (const auto& entry : fs::directory_iterator(streamed.parent_path()))
    EXPECT_NE(entry.path().filename().string().rfind("." + streamed.filename().string(), 0), 0u) << entry.path();
  fs::remove_all(whole);
  fs::remove_all(streamed);
}

TEST(DemoSet, WriterRejectsMalformedEpisodes) {
  DemoSet set = read_demo_set(kData / "good");
  set.episodes[1].actions.pop_back();
  const fs::path dir = test::scratch_path("dicestack_demo_bad_write");
  fs::remove_all(dir);
  EXPECT_THAT(test::error_of([&] { write_demo_set(set, dir); }), HasSubstr("3 states, 2 actions"));
  EXPECT_FALSE(fs::exists(dir)) << "a failed write leaves nothing behind";
}

TEST(DemoSetBadInput, HeaderAndRows) {
  EXPECT_THAT(read_error("wrong_columns"), HasSubstr("episode_0001.csv:1: header has 28 columns, expected 29"));
  EXPECT_THAT(read_error("wrong_header_name"),
              HasSubstr("episode_0001.csv:1: column 15 is \"die1_vz\", expected \"die1_vy\""));
  EXPECT_THAT(read_error("row_columns"), HasSubstr("episode_0001.csv:3: row has 30 columns, expected 29"));
  EXPECT_THAT(read_error("truncated"), HasSubstr("episode_0001.csv:4: row has"));
  EXPECT_THAT(read_error("truncated"), HasSubstr("truncated"));
  EXPECT_THAT(read_error("t_gap"), HasSubstr("episode_0001.csv:3: column \"t\" is 5, expected 1"));
}

TEST(DemoSetBadInput, Values) {
  EXPECT_THAT(read_error("not_a_number"),
              HasSubstr("episode_0001.csv:3: column \"die2_vy\": \"1.2.3\" is not a number"));
  EXPECT_THAT(read_error("nan"), HasSubstr("episode_0001.csv:3: column \"cup_x\" is NaN; demonstrations must be finite"));
  EXPECT_THAT(read_error("inf"), HasSubstr("episode_0001.csv:3: column \"dw\" is infinite"));
  EXPECT_THAT(read_error("unknown_source"),
              HasSubstr("episode_0001.csv:3: column \"source\": \"robot\" is not one of human, expert, policy, correction"));
  EXPECT_THAT(read_error("action_out_of_range"),
              HasSubstr("episode_0001.csv:3: column \"dvx\" = 25 is outside [-20, 20]"));
  EXPECT_THAT(read_error("empty_episode"), HasSubstr("episode_0001.csv: no steps"));
}

TEST(DemoSetBadInput, MetaAndFiles) {
  EXPECT_THAT(read_error("missing_file"), HasSubstr("meta.json: lists episode_0009.csv, which does not exist"));
  EXPECT_THAT(read_error("extra_file"), HasSubstr("episode_0002.csv: not listed in meta.json"));
  EXPECT_THAT(read_error("newer_version"),
              HasSubstr("meta.json: format version 99 is newer than this dicestack reads (5); upgrade dicestack"));
  EXPECT_THAT(read_error("wrong_format"), HasSubstr("format \"robomimic\" is not dicestack-demos"));
  EXPECT_THAT(read_error("steps_mismatch"), HasSubstr("says episode_0000.csv has 7 steps; the file has 4"));
  EXPECT_THAT(read_error("no_meta"), HasSubstr("meta.json: missing; not a dicestack demonstration folder"));
  EXPECT_THAT(read_error("broken_meta"), HasSubstr("meta.json: not valid JSON"));
  EXPECT_THAT(read_error("bad_world"), HasSubstr("\"physics.substeps\""));
  // Numbers are never narrowed, and a listed file never leaves the folder.
  EXPECT_THAT(read_error("version_fraction"), HasSubstr("\"version\" must be an integer, got 1.9"));
  EXPECT_THAT(read_error("version_huge"), HasSubstr("\"version\" must be an integer, got 4294967297"));
  EXPECT_THAT(read_error("steps_fraction"), HasSubstr("\"steps\" must be an unsigned integer, got 3.5"));
  EXPECT_THAT(read_error("seed_negative"), HasSubstr("\"seed\" must be an unsigned integer, got -1"));
  EXPECT_THAT(read_error("file_escapes"), HasSubstr("\"file\" must name a file inside the folder, got \"../good/episode_0000.csv\""));
  EXPECT_THROW(read_demo_set(kBadSets / "nan" / "set"), InputError);
}

fs::path unique_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dicestack_demo_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(DemoSetBadInput, AFileThatCannotBeReadIsNamedWithTheSystemsReason) {
  const fs::path dir = unique_dir("unreadable");
  fs::copy(kData / "good", dir / "set");
  const fs::path episode = dir / "set" / "episode_0001.csv";
  // The episode file without read permission: the error says why, not a bare "cannot open".
  fs::permissions(episode, fs::perms::none);
  const auto denied = test::unprivileged([&] { return test::error_of([&] { read_demo_set(dir / "set"); }); });
  fs::permissions(episode, fs::perms::owner_read | fs::perms::owner_write);
  if (denied) {
    EXPECT_EQ(*denied, episode.string() + ": cannot open for reading: Permission denied");
  }
  // A folder where the episode file should be, and where meta.json should be.
  fs::remove(episode);
  fs::create_directory(episode);
  EXPECT_EQ(test::error_of([&] { read_demo_set(dir / "set"); }), episode.string() + ": read failed: Is a directory");
  EXPECT_EQ(test::error_of([&] { read_episode_csv(episode); }), episode.string() + ": read failed: Is a directory");
  fs::remove(episode);
  EXPECT_EQ(test::error_of([&] { read_episode_csv(episode); }),
            episode.string() + ": cannot open for reading: No such file or directory");
  fs::remove(dir / "set" / "meta.json");
  fs::create_directory(dir / "set" / "meta.json");
  EXPECT_EQ(test::error_of([&] { read_demo_set(dir / "set"); }), (dir / "set" / "meta.json").string() + ": read failed: Is a directory");
  fs::remove_all(dir);
  if (!denied) GTEST_SKIP() << "cannot drop root's privileges here: the unreadable file was not tried";
}

TEST(DemoSet, AUsersFolderIsRefusedAndLeftUntouched) {
  const DemoSet set = read_demo_set(kData / "good");
  const fs::path root = unique_dir("user");
  const fs::path out = root / "out";
  fs::create_directories(out / "sub");
  { std::ofstream(out / "notes.txt") << "mine"; }
  { std::ofstream(out / "sub" / "notes.txt") << "mine too"; }
  const std::string message = test::error_of([&] { write_demo_set(set, out); });
  EXPECT_THAT(message, HasSubstr(out.string() + ": exists and is not a dicestack demonstration set (it holds notes.txt"));
  EXPECT_THAT(message, HasSubstr("refusing to replace it"));
  EXPECT_THROW(write_demo_set(set, out), InputError);
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_TRUE(fs::exists(out / "sub" / "notes.txt"));
  EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator{}), 2);
  EXPECT_EQ(std::distance(fs::directory_iterator(root), fs::directory_iterator{}), 1) << "no scratch folders left";
  // A set of ours with a user's file added is not ours any more.
  write_demo_set(set, root / "set");
  { std::ofstream(root / "set" / "notes.txt") << "mine"; }
  EXPECT_THROW(write_demo_set(set, root / "set"), InputError);
  EXPECT_THROW(append_to_demo_set(out, {set.episodes[0]}, set.world, "x"), InputError);
  fs::remove_all(root);
}

TEST(DemoSet, AFileAtTheTargetIsRefused) {
  const DemoSet set = read_demo_set(kData / "good");
  const fs::path root = unique_dir("file");
  { std::ofstream(root / "model.dsm") << R"({"format": "dicestack-model"})" << "\n"; }
  EXPECT_THAT(test::error_of([&] { write_demo_set(set, root / "model.dsm"); }),
              HasSubstr((root / "model.dsm").string() + ": exists and is not a dicestack demonstration set"));
  EXPECT_TRUE(fs::is_regular_file(root / "model.dsm"));
  fs::remove_all(root);
}

TEST(DemoSet, OurOwnSetWithSidecarsAnEmptyFolderAndAMissingPathAreWritten) {
  DemoSet set = read_demo_set(kData / "good");
  const fs::path root = unique_dir("own");
  write_demo_set(set, root / "missing" / "out");
  EXPECT_EQ(read_demo_set(root / "missing" / "out").episodes.size(), 2u);
  fs::create_directories(root / "empty");
  write_demo_set(set, root / "empty");
  EXPECT_EQ(read_demo_set(root / "empty").episodes.size(), 2u);
  { std::ofstream(root / "empty" / "optimise.json") << R"({"format": "dicestack-baseline", "best_cost": 1})"; }
  EXPECT_TRUE(is_own_demo_set(root / "empty"));
  set.episodes.pop_back();
  write_demo_set(set, root / "empty");
  EXPECT_EQ(read_demo_set(root / "empty").episodes.size(), 1u);
  { std::ofstream(root / "empty" / "rrt.json") << R"({"best_cost": 1})"; }  // no marker: not ours
  std::string why;
  EXPECT_FALSE(is_own_demo_set(root / "empty", &why));
  EXPECT_EQ(why, "it holds rrt.json");
  fs::remove_all(root);
}

TEST(DemoSet, SidecarsAppearWithTheSetAndASummaryAloneIsOurs) {
  DemoSet set = read_demo_set(kData / "good");
  const fs::path root = unique_dir("sidecars");
  const std::string summary = R"({"format": "dicestack-baseline", "version": 1, "best_cost": 1})";
  write_demo_set(set, root / "out", {{"optimise.json", summary}});
  EXPECT_EQ(slurp(root / "out" / "optimise.json"), summary);
  EXPECT_EQ(read_demo_set(root / "out").episodes.size(), 2u);
  EXPECT_TRUE(is_own_demo_set(root / "out"));
  // Replaced together: the old summary goes with the old set.
  set.episodes.clear();
  write_demo_set(set, root / "out", {{"rrt.json", summary}});
  EXPECT_FALSE(fs::exists(root / "out" / "optimise.json"));
  EXPECT_TRUE(read_demo_set(root / "out").episodes.empty()) << "a set may hold no episode (rrt without a path)";
  for (const std::string bad : {"meta.json", "episode_0000.csv", "../x.json", ""})
    EXPECT_THAT(test::error_of([&] { write_demo_set(set, root / "out", {{bad, summary}}); }),
                HasSubstr("cannot be written beside a demonstration set"))
        << bad;
  // What rrt left when it found no path, before: only its summary, no meta.json.
  fs::remove_all(root / "out");
  fs::create_directories(root / "out");
  { std::ofstream(root / "out" / "rrt.json") << summary; }
  EXPECT_TRUE(is_own_demo_set(root / "out"));
  { std::ofstream(root / "out" / "notes.txt") << "mine"; }
  EXPECT_FALSE(is_own_demo_set(root / "out"));
  fs::remove_all(root);
}

TEST(DemoSet, DeadRunsScratchFoldersAreRemovedLiveOnesKept) {
  const DemoSet set = read_demo_set(kData / "good");
  const fs::path root = unique_dir("scratch");
  const fs::path dead = root / (".out.tmp-" + std::to_string(test::dead_pid()) + "-x");
  const fs::path dead_old = root / (".out.old-" + std::to_string(test::dead_pid()) + "-x");
  const fs::path live = root / (".out.tmp-" + std::to_string(getpid()) + "-x");
  const fs::path parent = root / (".out.tmp-" + std::to_string(getppid()) + "-x");
  const fs::path other = root / (".other.tmp-" + std::to_string(test::dead_pid()) + "-x");
  for (const auto& p : {dead, live, parent, other}) {
    fs::create_directories(p);
    std::ofstream(p / "episode_0000.csv") << "half";
  }
  write_demo_set(set, dead_old);  // a killed run's set, moved aside before its new one was in place
  write_demo_set(set, root / "out");
  EXPECT_FALSE(fs::exists(dead)) << "a killed run's scratch folder of this target is cleaned up";
  EXPECT_FALSE(fs::exists(dead_old));
  EXPECT_TRUE(fs::exists(live / "episode_0000.csv")) << "a running writer's scratch folder is never touched";
  EXPECT_TRUE(fs::exists(parent / "episode_0000.csv"));
  EXPECT_TRUE(fs::exists(other)) << "only leftovers of this target";
  EXPECT_EQ(read_demo_set(root / "out").episodes.size(), 2u);
  fs::remove_all(root);
}

}  // namespace
}  // namespace dicestack
