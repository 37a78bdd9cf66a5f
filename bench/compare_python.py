#!/usr/bin/python3
"""dicestack's six regressors beside the Python implementations the paper used.

Runs `dicestack bench regressors --json --export DIR` (dicestack's figures, and the exact
training and test rows of its split), then fits scikit-learn's and XGBoost's models with the
same hyperparameters on the same standardised rows and measures them the same way: fit
seconds, predict one row (median over batches of 50 calls), batch rows per second, and eq. 9
train and test error. Prints one table with both side by side (or JSON with --json).

Needs Debian's python3-sklearn and python3-xgboost (`scripts/install-deps.sh --python`).
Both sides run on one thread, one after the other, on the same machine.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"  # before numpy loads its BLAS

try:
    import numpy as np
    from sklearn.multioutput import MultiOutputRegressor
    from sklearn.linear_model import SGDRegressor
    from sklearn.svm import SVR
    from sklearn.neural_network import MLPRegressor
    from sklearn.ensemble import RandomForestRegressor
    from sklearn.neighbors import KNeighborsRegressor
    from sklearn.preprocessing import StandardScaler
    import xgboost
except ImportError as e:
    sys.exit(f"compare_python: {e}; install with `scripts/install-deps.sh --python` "
             "(Debian's python3-sklearn and python3-xgboost) and run with /usr/bin/python3")


def python_models(seed):
    """The paper's Section VI-C settings, as dicestack's defaults (docs/regressors.md)."""
    return {
        "linear_svr": lambda: MultiOutputRegressor(SGDRegressor(
            loss="epsilon_insensitive", epsilon=1e-3, max_iter=2000, alpha=1e-4, eta0=0.01,
            power_t=0.25, tol=1e-3, random_state=seed)),
        "rbf_svr": lambda: MultiOutputRegressor(SVR(kernel="rbf", C=1.0, epsilon=0.1, gamma="scale")),
        "mlp": lambda: MLPRegressor(hidden_layer_sizes=(16,) * 5, activation="relu", solver="adam",
                                    batch_size=200, learning_rate_init=1e-3, alpha=1e-4,
                                    max_iter=100, random_state=seed),
        "random_forest": lambda: RandomForestRegressor(n_estimators=8, max_depth=12, min_samples_split=2,
                                                       max_features=1.0, n_jobs=1, random_state=seed),
        "gbt": lambda: xgboost.XGBRegressor(n_estimators=100, max_depth=12, learning_rate=0.3,
                                            tree_method="hist", n_jobs=1, random_state=seed),
        "knn": lambda: KNeighborsRegressor(n_neighbors=3),
    }


def eq9(y, y_hat, sigma):
    return float(np.mean(np.sum(np.abs(y - y_hat) / sigma, axis=1)))


def measure(make, x_train, y_train, x_test, y_test, calls):
    xs, ys = StandardScaler().fit(x_train), StandardScaler().fit(y_train)
    sigma = np.where(y_train.std(axis=0) > 0, y_train.std(axis=0), 1.0)
    zx, zy = xs.transform(x_train), ys.transform(y_train)
    model = make()
    t0 = time.perf_counter()
    model.fit(zx, zy)
    fit_s = time.perf_counter() - t0
    probe = xs.transform(x_test if len(x_test) else x_train)
    per_call = []
    for b in range(max(1, calls // 50)):
        t0 = time.perf_counter()
        for k in range(50):
            i = (b * 50 + k) % len(probe)
            model.predict(probe[i:i + 1])
        per_call.append((time.perf_counter() - t0) / 50)
    t0 = time.perf_counter()
    train_pred = ys.inverse_transform(model.predict(zx))
    rate = len(zx) / (time.perf_counter() - t0)
    test_error = eq9(y_test, ys.inverse_transform(model.predict(probe)), sigma) if len(x_test) else 0.0
    return {"fit_s": fit_s, "predict_row_us": 1e6 * float(np.median(per_call)),
            "batch_rows_per_s": rate, "train_error": eq9(y_train, train_pred, sigma), "test_error": test_error}


def load(path):
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dicestack", default="build/apps/dicestack", help="the dicestack executable")
    ap.add_argument("--demos", help="demonstration folder (default: dicestack's converted recordings)")
    ap.add_argument("--split", default="episodes", choices=["episodes", "rows"])
    ap.add_argument("--regressors", default="linear_svr,rbf_svr,mlp,random_forest,gbt,knn")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--calls", type=int, default=2000, help="predict_row calls timed (dicestack's too)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    names = args.regressors.split(",")
    makers = python_models(args.seed)
    unknown = [n for n in names if n not in makers]
    if unknown:
        sys.exit(f"compare_python: no Python counterpart for {', '.join(unknown)} (known: {', '.join(makers)})")

    with tempfile.TemporaryDirectory() as tmp:
        cmd = [args.dicestack, "bench", "regressors", "--json", "--split", args.split, "--regressors", args.regressors,
               "--seed", str(args.seed), "--calls", str(args.calls), "--export", tmp]
        if args.demos:
            cmd += ["--demos", args.demos]
        try:
            run = subprocess.run(cmd, capture_output=True, text=True)
        except OSError as e:
            sys.exit(f"compare_python: cannot run {args.dicestack}: {e.strerror} (build first, or pass --dicestack PATH)")
        if run.returncode != 0:
            sys.exit(f"compare_python: {' '.join(cmd)} failed ({run.returncode}): {run.stderr.strip()}")
        ours = {r["name"]: r for r in json.loads(run.stdout)}
        x_train, y_train = load(os.path.join(tmp, "train_x.csv")), load(os.path.join(tmp, "train_y.csv"))
        x_test, y_test = load(os.path.join(tmp, "test_x.csv")), load(os.path.join(tmp, "test_y.csv"))

    rows = []
    for name in names:
        theirs = measure(makers[name], x_train, y_train, x_test, y_test, args.calls)
        rows.append({"name": name, "dicestack": ours[name], "python": theirs})
        if not args.json:
            print(f"  {name} done", file=sys.stderr)
    if args.json:
        print(json.dumps({"split": args.split, "train_rows": len(x_train), "test_rows": len(x_test),
                          "sklearn": __import__("sklearn").__version__, "xgboost": xgboost.__version__,
                          "rows": rows}))
        return
    print(f"split {args.split}: {len(x_train)} training rows, {len(x_test)} test rows; "
          f"scikit-learn {__import__('sklearn').__version__}, XGBoost {xgboost.__version__}; "
          "each cell: dicestack / Python")
    print("| regressor | fit s | predict_row µs | batch rows/s | train error | test error |")
    print("|---|---:|---:|---:|---:|---:|")
    for r in rows:
        a, b = r["dicestack"], r["python"]
        print(f"| {r['name']} | {a['fit_s']:.2f} / {b['fit_s']:.2f} | {a['predict_row_us']:.2f} / "
              f"{b['predict_row_us']:.1f} | {a['batch_rows_per_s']:,.0f} / {b['batch_rows_per_s']:,.0f} | "
              f"{a['train_error']:.3f} / {b['train_error']:.3f} | {a['test_error']:.3f} / {b['test_error']:.3f} |")


if __name__ == "__main__":
    main()
