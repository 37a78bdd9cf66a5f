"""DAgger written in Python around a scikit-learn regressor, with dicestack's mpc expert as the
teacher: the learner drives (mixed with the expert with probability beta_i = p^i), the expert
labels every state the learner visits, the labels are aggregated and the regressor refitted.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/dagger_sklearn.py
    ... --iterations 1 --rollouts 1 --evaluate 1 --demos 10       # seconds

The expert's labels cost most of the time: off its own trajectory the mpc expert re-searches its
plan every few steps (about 10 ms a label).

The point is the pieces (DiceStackEnv, expert(), load_demos()), not the score: k-NN stacks the
dice under no learner (docs/learners.md), and this run ends at 0 % realistic success as dicestack's
own `dicestack.train("knn", learner="dagger")` does. For a policy that stacks, see
train_evaluate_plot.py (gbt under DART).
"""
import argparse

import numpy as np
from sklearn.neighbors import KNeighborsRegressor
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

import dicestack


def features(obs, t, start):
    """The regressor's input: the state, the step index and the start state (dicestack's
    "state+clock+start_state" map, with which DART's policies stack): the state alone does not
    tell a policy where it is in the swing."""
    return np.concatenate([obs, [t], start])


def episode_rows(states):
    return np.array([features(s, t, states[0]) for t, s in enumerate(states)])


def fit(x, y):
    # kd_tree: a one-row query takes 0.2 ms; scikit-learn 1.2's brute-force path, 30 ms.
    return make_pipeline(StandardScaler(), KNeighborsRegressor(n_neighbors=3, algorithm="kd_tree")).fit(x, y)


def dagger_rollout(env, expert, regressor, beta, seed, rng):
    """One episode where the learner acts (the expert with probability beta); every visited
    state is labelled by the expert."""
    obs, _ = env.reset(seed=seed)
    start, rows, labels = obs, [], []
    while True:
        label = expert(env)
        rows.append(features(obs, env.t, start))
        labels.append(label)
        action = label if rng.random() < beta else regressor.predict(rows[-1][None, :])[0]
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            return rows, labels


def success_rate(env, regressor, seeds):
    successes = 0
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        start = obs
        while True:
            action = regressor.predict(features(obs, env.t, start)[None, :])[0]
            obs, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                successes += info["realistic_success"]
                break
    return successes / len(seeds)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=3)
    parser.add_argument("--rollouts", type=int, default=4, help="learner rollouts per iteration")
    parser.add_argument("--p", type=float, default=0.5, help="beta_i = p^i")
    parser.add_argument("--demos", type=int, default=40, help="built-in demonstrations to start from")
    parser.add_argument("--evaluate", type=int, default=5, help="evaluation starts per iteration")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    demos = dicestack.load_demos("builtin")[: args.demos]
    x = np.concatenate([episode_rows(e.states) for e in demos])
    y = np.concatenate([e.actions for e in demos])
    regressor = fit(x, y)
    env, expert = dicestack.DiceStackEnv(), dicestack.expert("mpc")
    rng = np.random.default_rng(args.seed)
    evaluation_seeds = [10_000 + args.seed + i for i in range(args.evaluate)]
    print(f"behaviour cloning on {len(x)} rows: realistic success "
          f"{100 * success_rate(env, regressor, evaluation_seeds):.0f} %")
    for i in range(1, args.iterations + 1):
        beta = args.p**i
        for r in range(args.rollouts):
            rows, labels = dagger_rollout(env, expert, regressor, beta, args.seed + 1000 * i + r, rng)
            x = np.concatenate([x, rows])
            y = np.concatenate([y, labels])
        regressor = fit(x, y)
        rate = success_rate(env, regressor, evaluation_seeds)
        print(f"DAgger iteration {i} (beta {beta:.3f}): {len(x)} rows, realistic success {100 * rate:.0f} %")


if __name__ == "__main__":
    main()
