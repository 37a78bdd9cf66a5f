// The bad-input corpus (tests/corpus/<kind>/<case>/case.json, made by make_corpus.py): every case
// is copied into a scratch folder and run through the command line; each must exit non-zero
// without a crash, say what is wrong naming the file (and line or field), never echo a long
// value, and leave the folder exactly as it was: nothing half-written, nothing removed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kCorpus = fs::path(DICESTACK_SOURCE_DIR) / "tests" / "corpus";

struct Case {
  std::string name;  // <kind>/<case>
  fs::path dir;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (const auto& kind : fs::directory_iterator(kCorpus))
    if (kind.is_directory())
      for (const auto& c : fs::directory_iterator(kind.path()))
        if (fs::exists(c.path() / "case.json"))
          out.push_back({kind.path().filename().string() + "/" + c.path().filename().string(), c.path()});
  std::sort(out.begin(), out.end(), [](const Case& a, const Case& b) { return a.name < b.name; });
  return out;
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) text.replace(at, from.size(), to);
  return text;
}

// {case}, {source} and {plugin:TARGET} replaced by this run's paths.
std::string expand(std::string text, const fs::path& work) {
  text = replace_all(text, "{case}", work.string());
  text = replace_all(text, "{source}", DICESTACK_SOURCE_DIR);
  const std::map<std::string, std::string> plugins{{"test_not_a_plugin", DICESTACK_NOT_A_PLUGIN},
                                                   {"test_data_entry", DICESTACK_DATA_ENTRY},
                                                   {"test_null_record", DICESTACK_NULL_RECORD},
                                                   {"test_plugin_abi99", DICESTACK_ABI99_PLUGIN},
                                                   {"test_plugin_duplicate", DICESTACK_DUPLICATE_PLUGIN}};
  for (const auto& [target, path] : plugins) text = replace_all(text, "{plugin:" + target + "}", path);
  return text;
}

// Every entry under `root` with its size and content: what a run must leave unchanged.
std::map<std::string, std::string> tree(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    const std::string rel = fs::relative(e.path(), root).string();
    if (e.is_directory()) {
      out[rel] = "<dir>";
    } else {
      std::ifstream in(e.path(), std::ios::binary);
      std::ostringstream content;
      content << in.rdbuf();
      out[rel] = content.str();
    }
  }
  return out;
}

std::string shell_quote(const std::string& s) { return "'" + replace_all(s, "'", "'\\''") + "'"; }

class Corpus : public ::testing::TestWithParam<Case> {};

TEST_P(Corpus, IsRefusedNamingTheFileAndChangesNothing) {
  const Case& c = GetParam();
  const nlohmann::json spec = nlohmann::json::parse(std::ifstream(c.dir / "case.json"));
  const fs::path work = fs::temp_directory_path() / ("dicestack_corpus_" + std::to_string(getpid()) + "_" +
                                                     replace_all(c.name, "/", "_"));
  fs::remove_all(work);
  fs::copy(c.dir, work, fs::copy_options::recursive);
  fs::remove(work / "case.json");
  const auto before = tree(work);

  std::string command = "cd " + shell_quote(work.string()) + " && ";
  if (spec.contains("env"))
    for (const auto& [key, value] : spec["env"].items()) command += key + "=" + shell_quote(expand(value, work)) + " ";
  command += std::string(DICESTACK_EXE) + " " + expand(spec.at("run"), work) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, pipe)) > 0;) output.append(buf, n);
  const int raw = pclose(pipe);
  const int status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);

  SCOPED_TRACE(c.name + ": " + spec.value("why", "") + "\n" + output.substr(0, 2000));
  EXPECT_GE(status, 1) << "accepted";
  EXPECT_LT(status, 128) << "crashed (the shell reports a signal as 128 + N)";
  EXPECT_THAT(output, ::testing::Not(HasSubstr("internal error")));
  EXPECT_THAT(output, ::testing::Not(HasSubstr("terminate called")));
  EXPECT_LT(output.size(), 4000u) << "a message never echoes an unbounded value";
  for (const auto& expect : spec.at("expect")) EXPECT_THAT(output, HasSubstr(expect.get<std::string>()));
  if (spec.value("names_file", true)) {
    EXPECT_THAT(output, HasSubstr(work.string() + "/")) << "the message names the file";
  }
  EXPECT_EQ(tree(work), before) << "the run changed, added or removed something in the case's folder";
  fs::remove_all(work);
}

INSTANTIATE_TEST_SUITE_P(BadInputs, Corpus, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& p) { return replace_all(p.param.name, "/", "_"); });

TEST(CorpusSize, HoldsAtLeastOneHundredKinds) { EXPECT_GE(all_cases().size(), 100u); }

}  // namespace
}  // namespace dicestack
