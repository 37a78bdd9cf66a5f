#!/usr/bin/env python3
"""knn at any width: predict_row of knn's two exact searches side by side, on dart's
49-input map and on the 24 state numbers, timed on held-out states and on a policy's own
rollouts (which stray far from every training row). Prints the median over RUNS runs of
`dicestack bench regressors` (each itself the median of batches of 50 calls).

    /usr/bin/python3 bench/knn_width.py [--dicestack build/apps/dicestack] [--episodes 530] [--runs 5]

The set: `record --expert mpc --noise 0.1 --no-replan --successes-only` (what dart records);
the training rows are 80 % of it (49,000 at 430 episodes, 60,000 at 530). The rollouts: a knn policy fitted on that set under
dart's map, `evaluate --episodes 20 --save-rollouts`.
"""
import argparse
import json
import statistics
import subprocess
import tempfile
from pathlib import Path

DART_MAP = "state+clock+start_state"


def run(cmd):
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dicestack", default="build/apps/dicestack")
    ap.add_argument("--episodes", type=int, default=530)
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    ds = args.dicestack
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        run([ds, "record", "--expert", "mpc", "--episodes", str(args.episodes), "--noise", "0.1", "--no-replan",
             "--successes-only", "--seed", "0", "--out", str(work / "set")])
        run([ds, "train", "--regressor", "knn", "--learner", "bc", "--split", "none", "--demos", str(work / "set"),
             "--features", DART_MAP, "--out", str(work / "knn.dsm")])
        run([ds, "evaluate", "--model", str(work / "knn.dsm"), "--episodes", "20", "--seed", "0",
             "--save-rollouts", str(work / "rollouts")])
        cases = [(DART_MAP, "held-out states", []), (DART_MAP, "the policy's rollouts", ["--queries", str(work / "rollouts")]),
                 ("state", "held-out states", []), ("state", "the policy's rollouts", ["--queries", str(work / "rollouts")])]
        rows = {}
        for _ in range(args.runs):
            for features, where, extra in cases:
                for search in ("cluster_tree", "kdtree"):  # side by side in each run
                    out = json.loads(run([ds, "bench", "regressors", "--demos", str(work / "set"), "--features", features,
                                          "--regressors", "knn", "--set", "search=" + search, "--json"] + extra))[0]
                    rows.setdefault((features, where, search), []).append(out)
        first = rows[(DART_MAP, "held-out states", "cluster_tree")][0]
        print(f"knn predict_row, median of {args.runs} runs (us per call); {first['train_rows']} training rows "
              f"(80 % of {args.episodes} noisy mpc episodes' successes); fit seconds")
        print("| features | timed on (rows) | cluster_tree | kdtree | speed-up | fit s (cluster_tree / kdtree) | same errors |")
        print("|---|---|---:|---:|---:|---|---|")
        for features, where, _ in cases:
            a, b = rows[(features, where, "cluster_tree")], rows[(features, where, "kdtree")]
            ua = statistics.median(r["predict_row_us"] for r in a)
            ub = statistics.median(r["predict_row_us"] for r in b)
            fa = statistics.median(r["fit_s"] for r in a)
            fb = statistics.median(r["fit_s"] for r in b)
            same = all(r.get(key) == a[0].get(key) for r in a + b for key in ("train_error", "test_error"))
            print(f"| {features} | {where} ({a[0]['timed_rows']}) | {ua:.1f} | {ub:.1f} | {ub / ua:.1f}x | {fa:.2f} / {fb:.2f} | {same} |")


if __name__ == "__main__":
    main()
