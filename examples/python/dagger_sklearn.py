"""A scikit-learn regressor trained under DAgger: register_regressor makes the estimator a
regressor of dicestack's registry, and dicestack's own DAgger (learner="dagger": the learner
drives, mixed with the expert with probability beta_i, the mpc expert labels every state the
learner visits, the labels are aggregated and the estimator refitted) trains it in C++, calling
the estimator's fit and predict with the GIL held.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/dagger_sklearn.py
    ... --iterations 1 --rollouts 1 --evaluate 1 --demos 10       # seconds
    ... --estimator forest --out forest.dsm                          # also save it (and forest.dsm.pkl)

The regressor reads the features state + step + start state ("state+clock+start_state", the map
with which DART's policies stack): the state alone does not tell a policy where it is in the
swing. dicestack standardises the inputs and labels itself, so the estimator gets them scaled.

The expert's labels cost most of the time: off its own trajectory the mpc expert re-searches its
plan every few steps (about 10 ms a label). Rollouts run on all cores; a Python estimator's
predict calls take turns on the GIL.

The point is the pieces, not the score: k-NN stacks the dice under no learner
(docs/learners.md), and this run ends near 0 % realistic success, as dicestack's own
`dicestack.train("knn", learner="dagger")` does. For a policy that stacks, see
train_evaluate_plot.py (gbt under DART).
"""
import argparse

from sklearn.ensemble import RandomForestRegressor
from sklearn.neighbors import KNeighborsRegressor

import dicestack

FEATURES = "state+clock+start_state"


def knn(n_neighbors=3):
    # A one-row predict costs about 1.6 ms (scikit-learn's per-call work and a k-d tree search
    # over 51 features): with the expert's labels, most of a rollout's time.
    return KNeighborsRegressor(n_neighbors=n_neighbors, algorithm="kd_tree")


def forest(n_estimators=20):
    # random_state is left at None: dicestack sets it from the training seed. A one-row predict
    # of 20 trees costs about 1.4 ms (joblib's dispatch).
    return RandomForestRegressor(n_estimators=n_estimators, min_samples_leaf=5)


def report(name, model, episodes, seed):
    result = dicestack.evaluate(model, episodes=episodes, seed=seed)
    print(f"{name}: {model.training['seconds']:.1f} s, train error {model.training['train_error']:.3f}, "
          f"test error {model.training.get('test_error', float('nan')):.3f}; "
          f"{episodes} rollouts: realistic success {100 * result['realistic_success_rate']:.0f} %, "
          f"stacked {100 * result['stacked_rate']:.0f} %, dice in cup {result['dice_in_cup_mean']:.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--estimator", choices=("knn", "forest"), default="knn")
    parser.add_argument("--iterations", type=int, default=3, help="DAgger rounds")
    parser.add_argument("--rollouts", type=int, default=4, help="mixture rollouts per round")
    parser.add_argument("--demos", type=int, default=40, help="built-in demonstrations to start from")
    parser.add_argument("--evaluate", type=int, default=5, help="evaluation rollouts from random starts")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", help="save the DAgger model here (and its estimator, pickled, in OUT.pkl)")
    args = parser.parse_args()

    if args.estimator == "knn":
        dicestack.register_regressor("sk_knn", knn, params={"n_neighbors": 3},
                                     description="scikit-learn's KNeighborsRegressor (kd-tree)")
    else:
        dicestack.register_regressor("sk_forest", forest, params={"n_estimators": 20},
                                     description="scikit-learn's RandomForestRegressor")
    name = "sk_" + args.estimator
    demos = dicestack.load_demos("builtin")[: args.demos]

    bc = dicestack.train(name, learner="bc", demos=demos, features=FEATURES, seed=args.seed)
    report("behaviour cloning", bc, args.evaluate, args.seed)
    options = {"iterations": args.iterations, "rollouts": args.rollouts, "expert": "mpc"}
    dagger = dicestack.train(name, learner="dagger", demos=demos, features=FEATURES, options=options, seed=args.seed,
                             out=args.out)
    report(f"DAgger, {args.iterations} x {args.rollouts} rollouts", dagger, args.evaluate, args.seed)
    if args.out:
        # Reading the pickle back runs code: only with allow_pickle=True, and only files you trust.
        loaded = dicestack.load_model(args.out, allow_pickle=True)
        print(f"wrote {args.out} and {args.out}.pkl ({loaded.regressor}, {loaded.params})")


if __name__ == "__main__":
    main()
