// kill -9 at several points of every writer: each writer of the `dicestack` tool is run
// over an output an earlier run made, and killed 0.05 s and 0.2 s after it starts, when its first
// scratch file or folder appears, and just before each commit to that output (the test-only
// library stop_at_commit.cpp stops the process there, so the kill does not race the rename).
// After every kill the old output must be byte-identical; then the writer is run whole, and no
// scratch file or folder may be left anywhere in the case's folder.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <dicestack/test/helpers.hpp>

extern char** environ;

namespace dicestack {
namespace {
namespace kill9 {  // apart from test_cli.cpp's and test_corpus.cpp's helpers (one unity source)

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Writer {
  std::string name;
  std::vector<std::string> setup;    // runs that make the writer's inputs
  std::string first;                 // the earlier run: makes the old output
  std::string again;                 // the run that is killed at each point, then run whole
  std::vector<std::string> outputs;  // what must stay old together (under the case's folder)
  bool may_grow = false;             // a checkpoint or a page: new entries (an iteration, media) may appear beside the old ones
};

void PrintTo(const Writer& w, std::ostream* os) { *os << w.name; }

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) text.replace(at, from.size(), to);
  return text;
}

std::string expand(const std::string& args, const fs::path& root) {
  return replace_all(replace_all(args, "{root}", root.string()),
                     "{demos}", std::string(DICESTACK_SOURCE_DIR) + "/tests/datasets/data/good");
}

// ".<name>.tmp-..." or ".<name>.old-...": what temporary_sibling names.
bool is_scratch(const std::string& name) {
  return name.size() > 1 && name[0] == '.' && (name.find(".tmp-", 1) != std::string::npos || name.find(".old-", 1) != std::string::npos);
}

std::vector<std::string> scratch_under(const fs::path& root) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (is_scratch(e.path().filename().string())) out.push_back(fs::relative(e.path(), root).string());
  return out;
}

// What the case's folder holds besides the outputs.
std::vector<std::string> names_beside(const fs::path& root, const std::vector<std::string>& outputs) {
  std::vector<std::string> out;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    const std::string rel = fs::relative(it->path(), root).string();
    if (std::find(outputs.begin(), outputs.end(), rel) != outputs.end()) {
      it.disable_recursion_pending();
      continue;
    }
    out.push_back(rel);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Every file (bytes) and folder of the outputs, by path relative to the case's folder.
std::map<std::string, std::string> contents(const fs::path& root, const std::vector<std::string>& outputs) {
  std::map<std::string, std::string> out;
  for (const auto& o : outputs) {
    const fs::path p = root / o;
    if (fs::is_regular_file(p)) {
      out[o] = bytes_of(p);
    } else if (fs::is_directory(p)) {
      out[o + "/"] = "<folder>";
      for (const auto& e : fs::recursive_directory_iterator(p))
        out[fs::relative(e.path(), root).string()] = e.is_directory() ? "<folder>" : bytes_of(e.path());
    } else {
      out[o] = "<missing>";
    }
  }
  return out;
}

// A run of dicestack (a child process): its argument words and environment are made before fork, so the child
// only redirects its output to `log` and execs.
class Child {
 public:
  Child(const std::string& args, const fs::path& log, const std::string& outputs, int stop_at_commit) {
    std::istringstream words(args);
    args_.push_back(DICESTACK_EXE);
    for (std::string w; words >> w;) args_.push_back(w);
    for (char** e = environ; *e; ++e) {
      const std::string_view v(*e);
      if (v.rfind("LD_PRELOAD=", 0) != 0 && v.rfind("ASAN_OPTIONS=", 0) != 0 && v.rfind("DICESTACK_TEST_", 0) != 0) env_.emplace_back(v);
    }
    env_.push_back(std::string("LD_PRELOAD=") + DICESTACK_STOP_AT_COMMIT);
    // An instrumented dicestack (scripts/sanitize.sh) accepts the preloaded library.
    const char* asan = std::getenv("ASAN_OPTIONS");
    env_.push_back(std::string("ASAN_OPTIONS=") + (asan ? std::string(asan) + ":" : "") + "verify_asan_link_order=0");
    env_.push_back("DICESTACK_TEST_OUTPUTS=" + outputs);
    env_.push_back("DICESTACK_TEST_STOP_AT_COMMIT=" + std::to_string(stop_at_commit));
    std::vector<char*> argv, envp;
    for (auto& a : args_) argv.push_back(a.data());
    for (auto& e : env_) envp.push_back(e.data());
    argv.push_back(nullptr);
    envp.push_back(nullptr);
    const std::string log_path = log.string();
    pid_ = fork();
    if (pid_ == 0) {
      const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
      }
      execve(argv[0], argv.data(), envp.data());
      _exit(127);
    }
  }
  ~Child() {
    if (pid_ > 0 && !reaped_) kill_now();
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Whether it has stopped (at a commit) or ended, polled without waiting.
  bool stopped_or_ended() {
    if (stopped_ || reaped_) return true;
    int raw = 0;
    const pid_t r = waitpid(pid_, &raw, WNOHANG | WUNTRACED);
    if (r != pid_) return false;
    if (WIFSTOPPED(raw)) {
      stopped_ = true;
    } else {
      reaped_ = true;
      status_ = raw;
    }
    return true;
  }
  /// Waits up to `seconds` for it to stop or end.
  bool wait(double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (!stopped_or_ended()) {
      if (Clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
  }
  /// SIGKILL, then reap. False if it had already ended by itself.
  bool kill_now() {
    if (reaped_) return false;
    ::kill(pid_, SIGKILL);
    waitpid(pid_, &status_, 0);
    reaped_ = true;
    return WIFSIGNALED(status_) && WTERMSIG(status_) == SIGKILL;
  }
  bool stopped() const { return stopped_; }
  bool ended_by_itself() const { return reaped_ && !stopped_ && !(WIFSIGNALED(status_) && WTERMSIG(status_) == SIGKILL); }
  int exit_status() const { return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1; }

 private:
  std::vector<std::string> args_, env_;
  pid_t pid_ = -1;
  int status_ = 0;
  bool stopped_ = false, reaped_ = false;
};

class KillNine : public ::testing::TestWithParam<Writer> {
 protected:
  void SetUp() override {
    const Writer& w = GetParam();
    root_ = test::scratch_path("dicestack_kill_" + w.name);
    log_ = test::scratch_path("dicestack_kill_" + w.name + ".log");
    fs::remove_all(root_);
    fs::remove(log_);
    fs::create_directories(root_);
    for (const auto& o : w.outputs) outputs_ += (outputs_.empty() ? "" : ":") + (root_ / o).string();
  }
  void TearDown() override {
    if (!HasFailure()) {
      fs::remove_all(root_);
      fs::remove(log_);
    }
  }

  // Runs `args` whole (no stop) and returns its exit status.
  int run_whole(const std::string& args) {
    Child r(expand(args, root_), log_, outputs_, 0);
    if (!r.wait(120)) return -1;
    r.kill_now();  // reaps
    return r.exit_status();
  }

  std::string log_tail() const {
    const std::string text = bytes_of(log_);
    return text.size() > 3000 ? text.substr(text.size() - 3000) : text;
  }

  // The old output after a kill: byte-identical (or, for a checkpoint, every old entry identical
  // and new entries beside them). Names what differs, not the bytes.
  void expect_old_output(const std::map<std::string, std::string>& old, const std::string& point) {
    const auto now = contents(root_, GetParam().outputs);
    std::vector<std::string> changed;
    for (const auto& [path, bytes] : old) {
      const auto it = now.find(path);
      if (it == now.end()) changed.push_back(path + " (gone)");
      else if (it->second != bytes) changed.push_back(path + " (changed)");
    }
    if (!GetParam().may_grow)
      for (const auto& [path, bytes] : now)
        if (!old.contains(path)) changed.push_back(path + " (new)");
    EXPECT_THAT(changed, ::testing::IsEmpty()) << "killed " << point << ": the old output is not intact\n" << log_tail();
  }

  fs::path root_, log_;
  std::string outputs_;
};

TEST_P(KillNine, TheOldOutputSurvivesAndTheNextRunLeavesNoScratch) {
  const Writer& w = GetParam();
  for (const auto& s : w.setup) ASSERT_EQ(run_whole(s), 0) << s << "\n" << log_tail();
  ASSERT_EQ(run_whole(w.first), 0) << w.first << "\n" << log_tail();
  const auto old = contents(root_, w.outputs);
  const auto beside = names_beside(root_, w.outputs);
  for (const auto& [path, bytes] : old) ASSERT_NE(bytes, "<missing>") << path;
  const std::string again = expand(w.again, root_);

  // 0.05 s and 0.2 s after the start. The run stops at its first commit if it gets there first.
  for (const double seconds : {0.05, 0.2}) {
    Child r(again, log_, outputs_, 1);
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end && !r.stopped_or_ended()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    EXPECT_TRUE(r.kill_now()) << "ended by itself before the kill at " << seconds << " s\n" << log_tail();
    expect_old_output(old, "at " + std::to_string(seconds) + " s");
  }

  // When the first scratch file or folder appears (inotify on the case's folder and the outputs).
  {
    const int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    ASSERT_GE(fd, 0);
    inotify_add_watch(fd, root_.c_str(), IN_CREATE | IN_MOVED_TO);
    for (const auto& o : w.outputs)
      if (fs::is_directory(root_ / o)) inotify_add_watch(fd, (root_ / o).c_str(), IN_CREATE | IN_MOVED_TO);
    Child r(again, log_, outputs_, 1);
    bool seen = false;
    const auto end = Clock::now() + std::chrono::seconds(120);
    alignas(inotify_event) char buffer[8192];
    while (!seen && Clock::now() < end && !r.stopped_or_ended()) {
      pollfd p{fd, POLLIN, 0};
      if (poll(&p, 1, 2) <= 0) continue;
      for (ssize_t n = read(fd, buffer, sizeof buffer), at = 0; n > 0 && at < n;) {
        const auto* e = reinterpret_cast<const inotify_event*>(buffer + at);
        if (e->len > 0 && is_scratch(e->name)) seen = true;
        at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
      }
    }
    EXPECT_TRUE(r.kill_now()) << "ended by itself before a scratch appeared\n" << log_tail();
    close(fd);
    EXPECT_TRUE(seen) << "no scratch file or folder appeared before the run stopped at its first commit";
    expect_old_output(old, "when its scratch appeared");
  }

  // Just before each commit to the outputs, until a run has no commit left: that run is whole.
  int commits = 0;
  for (int k = 1; k <= 8; ++k) {
    Child r(again, log_, outputs_, k);
    ASSERT_TRUE(r.wait(120)) << "no stop or end within 120 s\n" << log_tail();
    if (!r.stopped()) {
      ASSERT_EQ(r.exit_status(), 0) << "the whole run failed\n" << log_tail();
      break;
    }
    commits = k;
    EXPECT_TRUE(r.kill_now());
    expect_old_output(old, "before commit " + std::to_string(k));
  }
  RecordProperty("commits", commits);
  EXPECT_GE(commits, 1) << "the run never committed to " << outputs_;
  EXPECT_LT(commits, 8) << "still committing after 8 kills";

  // The whole run replaced the output and cleaned every killed run's scratch.
  EXPECT_NE(contents(root_, w.outputs), old) << "the whole run did not replace the output";
  EXPECT_THAT(scratch_under(root_), ::testing::IsEmpty()) << "left after the next run";
  if (!w.may_grow) {
    EXPECT_EQ(names_beside(root_, w.outputs), beside) << "beside the outputs, the folder holds what it held before";
  }
}

const std::string kTrainKnn = "train --demos {demos} --regressor knn --split none ";
const std::string kDagger =
    "train --demos {demos} --regressor knn --split none --learner dagger --option rollouts=1 --option expert=scripted "
    "--checkpoint {root}/ck --out {root}/dagger.dsm ";
const std::vector<std::string> kTwoSets = {"record --expert scripted --episodes 1 --seed 1 --out {root}/demos1",
                                           "record --expert scripted --episodes 2 --seed 2 --out {root}/demos2"};
const std::string kPolicy = kTrainKnn + "--out {root}/policy.dsm";

INSTANTIATE_TEST_SUITE_P(
    EveryWriter, KillNine,
    ::testing::Values(
        Writer{"record", {},
               "record --expert scripted --episodes 1 --seed 1 --out {root}/set",
               "record --expert scripted --episodes 3 --seed 2 --threads 1 --out {root}/set", {"set"}},
        Writer{"train_out", {}, kTrainKnn + "--out {root}/m.dsm", kTrainKnn + "--set k=2 --out {root}/m.dsm", {"m.dsm"}},
        Writer{"train_checkpoint", {}, kDagger + "--option iterations=1", kDagger + "--option iterations=2 --resume", {"ck"}, true},
        Writer{"leaderboard_out", {},
               "leaderboard --demos {demos} --regressors knn --learners bc --episodes 1 --seed 1 --format json --out {root}/lb.json",
               "leaderboard --demos {demos} --regressors knn,linear_svr --learners bc --episodes 1 --seed 2 --format json "
               "--out {root}/lb.json",
               {"lb.json"}},
        // A page and its media folder: the old page with the media it links, or the new pair. A
        // new generation of media may appear beside the old one before the page's commit.
        Writer{"leaderboard_html", {},
               "leaderboard --demos {demos} --regressors knn --learners bc --episodes 1 --seed 1 --format html "
               "--out {root}/lb.html",
               "leaderboard --demos {demos} --regressors knn --learners bc --episodes 2 --seed 2 --format html "
               "--out {root}/lb.html",
               {"lb.html", "lb_files"}, true},
        Writer{"dataset_view", kTwoSets, "dataset view {root}/demos1 --out {root}/view.html",
               "dataset view {root}/demos2 --out {root}/view.html", {"view.html", "view_files"}, true},
        Writer{"export_minari", kTwoSets, "dataset export {root}/demos1 --format minari --out {root}/minari",
               "dataset export {root}/demos2 --format minari --out {root}/minari", {"minari"}},
        Writer{"export_robomimic", kTwoSets, "dataset export {root}/demos1 --format robomimic --out {root}/set.hdf5",
               "dataset export {root}/demos2 --format robomimic --out {root}/set.hdf5", {"set.hdf5"}},
        Writer{"optimise_out", {}, "optimise --method cmaes --steps 5 --evaluations 20 --seed 1 --out {root}/opt",
               "optimise --method cmaes --steps 5 --evaluations 20 --seed 2 --out {root}/opt", {"opt"}},
        Writer{"reinforce_out", {}, "reinforce --iterations 1 --batch 2 --steps 4 --seed 1 --out {root}/rf",
               "reinforce --iterations 1 --batch 2 --steps 4 --seed 2 --out {root}/rf", {"rf"}},
        Writer{"rrt_out", {}, "rrt --nodes 3 --extend-steps 2 --extend-iterations 2 --seed 1 --out {root}/rrt",
               "rrt --nodes 3 --extend-steps 2 --extend-iterations 2 --seed 2 --out {root}/rrt", {"rrt"}},
        Writer{"evaluate_save_rollouts", {kPolicy},
               "evaluate --model {root}/policy.dsm --episodes 1 --seed 1 --save-rollouts {root}/rollouts",
               "evaluate --model {root}/policy.dsm --episodes 2 --seed 2 --save-rollouts {root}/rollouts", {"rollouts"}},
        Writer{"evaluate_report", {kPolicy}, "evaluate --model {root}/policy.dsm --episodes 1 --seed 1 --report {root}/report",
               "evaluate --model {root}/policy.dsm --episodes 2 --seed 2 --report {root}/report", {"report"}}),
    [](const ::testing::TestParamInfo<Writer>& p) { return p.param.name; });

}  // namespace kill9
}  // namespace
}  // namespace dicestack
