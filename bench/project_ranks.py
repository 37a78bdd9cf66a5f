#!/usr/bin/env python3
"""Projects a leaderboard's wall time on R MPI ranks from its measured rows (docs/scaling.md).

Each row is trained and rolled out whole on one rank, so a row's cost is its fit time plus its
rollouts: fit_s + rollouts * steps * (us_per_step + sim_us) / 1e6. The rows are dealt as
dicestack deals them (longest first, each to the least loaded rank; learners/leaderboard.cpp),
and the run takes as long as the most loaded rank, plus the playback row on all ranks.

  bench/project_ranks.py TABLE [--rollouts N] [--steps T] [--sim-us U] [--ranks 1,2,4,...] [--seeds K]

TABLE is a leaderboard written with --format json, or a Markdown table (`| regressor | learner |
... | fit s | us/step |`) such as those in docs/learners.md; --section picks the n-th table of
a Markdown file (0-based).
"""
import argparse
import json


def rows_from(path, section):
    text = open(path).read()
    if path.endswith(".json"):
        return [(f"{r['learner']} {r['features']} {r['regressor']}", r["fit_s"], r["us_per_step"])
                for r in json.loads(text)["rows"] if r["learner"] != "playback"]
    tables, current = [], None
    for line in text.splitlines():
        if line.startswith("| regressor |"):
            current = {"head": [c.strip() for c in line.strip("|").split("|")], "rows": []}
            tables.append(current)
        elif current is not None and line.startswith("|") and not line.startswith("|---"):
            current["rows"].append([c.strip() for c in line.strip("|").split("|")])
        elif not line.startswith("|"):
            current = None
    t = tables[section]
    h = t["head"]
    out = []
    for r in t["rows"]:
        if r[h.index("learner")] == "playback":
            continue
        name = " ".join(r[h.index(k)] for k in ("learner", "features", "regressor") if k in h)
        out.append((name, float(r[h.index("fit s")]), float(r[h.index("us/step")])))
    return out


def deal(costs, ranks):
    """dicestack's deal_items: by decreasing cost (ties by index), each to the least loaded rank."""
    order = sorted(range(len(costs)), key=lambda i: (-costs[i], i))
    load = [0.0] * ranks
    for i in order:
        r = min(range(ranks), key=lambda k: (load[k], k))
        load[r] += costs[i]
    return max(load)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("table")
    p.add_argument("--section", type=int, default=0)
    p.add_argument("--rollouts", type=int, default=100, help="rollouts per row (paper profile: 100)")
    p.add_argument("--steps", type=float, default=300, help="mean control steps per rollout")
    p.add_argument("--sim-us", type=float, default=60, help="simulation time per control step, us (dicestack bench sim)")
    p.add_argument("--ranks", default="1,2,4,8,16,32,64")
    p.add_argument("--seeds", type=int, default=1, help="training seeds per row: each seed of a row is a job of its own")
    a = p.parse_args()
    rows = [r for r in rows_from(a.table, a.section) for _ in range(a.seeds)]
    costs = [fit + a.rollouts * a.steps * (us + a.sim_us) / 1e6 for _, fit, us in rows]
    total = sum(costs)
    biggest = max(range(len(rows)), key=lambda i: costs[i])
    print(f"{len(rows)} jobs ({a.seeds} seed(s) per row), {total:.0f} s of row time in all; largest row {rows[biggest][0]}: {costs[biggest]:.0f} s "
          f"({100 * costs[biggest] / total:.0f} %)")
    for name, c in sorted(zip([r[0] for r in rows[::a.seeds]], costs[::a.seeds]), key=lambda x: -x[1])[:5]:
        print(f"  {c:8.0f} s  {name}")
    print(f"{'ranks':>6} {'time s':>8} {'speed-up':>9} {'efficiency':>11}  bound")
    for r in [int(x) for x in a.ranks.split(",")]:
        t = deal(costs, r)
        bound = "largest row" if abs(t - costs[biggest]) < 1e-9 else "total / ranks" if t < 1.05 * total / r else "deal"
        print(f"{r:>6} {t:>8.0f} {total / t:>9.2f} {total / t / r:>11.2f}  {bound}")


if __name__ == "__main__":
    main()
