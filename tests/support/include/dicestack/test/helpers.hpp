#pragma once
// Small helpers shared by the test suites of every folder: target dicestack_test_support
// (tests/CMakeLists.txt), which every suite links.
#include <grp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <dicestack/core/matrix.hpp>
#include <dicestack/core/env.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack::test {

inline bool bit_equal(const State& a, const State& b) { return std::memcmp(a.data(), b.data(), sizeof(State)) == 0; }

/// The default world with a short time limit, for tests that roll out or learn.
/// An episode an expert plays from env's current state, knocked once: at step `at` the world
/// runs `knock` instead of the expert's action. Whether it ended in a realistic success, every
/// action and every state.
struct KnockedEpisode {
  bool success = false;
  std::vector<Action> actions;
  std::vector<State> states;
};
template <class Expert>
KnockedEpisode knocked_episode(Expert& expert, DiceEnv& env, int at, const Action& knock) {
  KnockedEpisode e;
  e.states.push_back(env.get_state());
  while (env.t() < env.config().episode.max_steps) {
    const Action a = env.t() == at ? knock : expert.act(env);
    e.actions.push_back(a);
    const StepResult r = env.step(a);
    e.states.push_back(r.observation);
    if (r.terminated) break;
  }
  e.success = env.outcome().realistic_success();
  return e;
}

inline WorldConfig short_world(int max_steps = 60) {
  WorldConfig w;
  w.episode.max_steps = max_steps;
  return w;
}

/// `n` actions uniform in the optimisers' scale, from `seed`.
inline std::vector<Action> random_actions(const WorldConfig& c, std::uint64_t seed, int n) {
  Rng rng(seed);
  std::vector<Action> out(static_cast<std::size_t>(n));
  for (auto& a : out)
    for (std::size_t k = 0; k < kActionDim; ++k) a[k] = rng.uniform(-1.0, 1.0) * c.action.scale[k];
  return out;
}

/// An n x d matrix of values uniform in [-1, 1), from `seed`.
inline Matrix random_matrix(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  Rng rng(seed);
  Matrix m(n, d);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = rng.uniform(-1.0, 1.0);
  return m;
}

/// A path in the temporary folder named for this process, so that two test runs can share a
/// machine: temp/<name> becomes temp/<stem>-<pid><extension>.
inline std::filesystem::path scratch_path(const std::string& name) {
  const std::filesystem::path n(name);
  return std::filesystem::temp_directory_path() /
         (n.stem().string() + "-" + std::to_string(getpid()) + n.extension().string());
}

/// What a callable throws, as text; empty if it does not throw.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return {};
}

/// What `f` returns (a string) when run without the right to read others' files: here when this
/// process is not root, else in a child that drops to user and group nobody (65534) first, since
/// root reads a file whatever its mode. Nothing when the child cannot drop them (the caller skips).
template <class F>
std::optional<std::string> unprivileged(F&& f) {
  if (geteuid() != 0) return f();
  int fds[2];
  if (pipe(fds) != 0) return std::nullopt;
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    if (setgroups(0, nullptr) != 0 || setgid(65534) != 0 || setuid(65534) != 0) _exit(3);
    const std::string text = f();
    for (std::size_t at = 0; at < text.size();) {
      const ssize_t n = write(fds[1], text.data() + at, text.size() - at);
      if (n <= 0) _exit(4);
      at += static_cast<std::size_t>(n);
    }
    _exit(0);
  }
  close(fds[1]);
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  if (child < 0 || waitpid(child, &status, 0) != child || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nullopt;
  return text;
}

/// The pid of a child that has exited and been reaped: a process that no longer runs.
inline long dead_pid() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  int status = 0;
  waitpid(child, &status, 0);
  return static_cast<long>(child);
}

}  // namespace dicestack::test
