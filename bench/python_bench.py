"""Steps per second from Python beside the C++ simulator (the targets: DiceStackEnv.step from
Python >= 50 % of C++ on one thread; DiceStackVectorEnv >= 90 % of C++ on 2 threads).

    PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py [--exe build/apps/dicestack]

Each repeat measures, one after the other so that the machine's load falls on all three alike:
  - `dicestack bench sim --json --repeats 1` (the binary): control steps per second of DiceEnv in
    C++, 1 thread and --threads threads (episodes of --steps steps with random actions);
  - DiceStackEnv.step from a Python loop: the same episode length and action range, a reset
    (random start) every --steps steps, the reset not timed;
  - DiceStackVectorEnv(--envs environments, --threads threads).step: environment steps per
    second (envs x calls), on a world whose time limit is --steps (its next-step autoresets
    count as steps, as a vector env's user sees them).
It prints the medians of --repeats repeats and the ratios to C++, and the load average before
and after (the figures move with what else the machine runs). Run by hand; not part of CTest.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
try:
    import dicestack
except ImportError:  # from a source tree with the default build folder
    sys.path.insert(0, os.path.join(HERE, "..", "build", "python"))
    import dicestack


def cpp_steps_per_second(exe, args):
    out = subprocess.run([exe, "bench", "sim", "--json", "--repeats", "1", "--threads", str(args.threads),
                          "--episodes", str(args.episodes), "--steps", str(args.steps)],
                         check=True, capture_output=True, text=True).stdout
    j = json.loads(out)
    return j["episodes_per_second"] * args.steps, j["episodes_per_second_threads"] * args.steps, j["threads"]


def python_env_steps_per_second(args, actions):
    world = dicestack.default_world()
    world["episode"]["max_steps"] = args.steps + 1  # episodes end by our resets, as in bench sim
    env = dicestack.DiceStackEnv(world=world)
    seconds = 0.0
    for e in range(args.episodes):
        env.reset(seed=e)
        step = env.step
        episode = actions[e % len(actions)]
        t0 = time.perf_counter()
        for a in episode:
            step(a)
        seconds += time.perf_counter() - t0
    env.close()
    return args.episodes * args.steps / seconds


def vector_env_steps_per_second(args, batches):
    world = dicestack.default_world()
    world["episode"]["max_steps"] = args.steps
    venv = dicestack.DiceStackVectorEnv(args.envs, world=world, threads=args.threads)
    venv.reset(seed=0)
    calls = max(1, args.episodes * args.steps // args.envs)
    step = venv.step
    t0 = time.perf_counter()
    for i in range(calls):
        step(batches[i % len(batches)])
    seconds = time.perf_counter() - t0
    venv.close()
    return calls * args.envs / seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--exe", default=os.path.join(HERE, "..", "build", "apps", "dicestack"))
    parser.add_argument("--episodes", type=int, default=200, help="episodes per measurement (bench sim's default)")
    parser.add_argument("--steps", type=int, default=100, help="control steps per episode (bench sim's default)")
    parser.add_argument("--envs", type=int, default=16, help="environments in the vector env")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()

    scale = np.asarray(dicestack.default_world()["action"]["scale"], dtype=np.float64)
    rng = np.random.default_rng(1)
    actions = [rng.uniform(-1.0, 1.0, size=(args.steps, 3)) * scale for _ in range(16)]
    batches = [np.ascontiguousarray(b) for b in rng.uniform(-1.0, 1.0, size=(256, args.envs, 3)) * scale]

    load_before = os.getloadavg()
    cpp1, cppn, py1, pyv = [], [], [], []
    threads = args.threads
    for _ in range(args.repeats):
        one, many, threads = cpp_steps_per_second(args.exe, args)
        cpp1.append(one)
        cppn.append(many)
        py1.append(python_env_steps_per_second(args, actions))
        pyv.append(vector_env_steps_per_second(args, batches))
    load_after = os.getloadavg()
    m = {k: statistics.median(v) for k, v in (("cpp_1_thread", cpp1), ("cpp_threads", cppn), ("python_env", py1),
                                              ("python_vector_env", pyv))}
    result = {
        "steps_per_second": m,
        "python_env_over_cpp_1_thread": m["python_env"] / m["cpp_1_thread"],
        "vector_env_over_cpp_threads": m["python_vector_env"] / m["cpp_threads"],
        "threads": threads,
        "envs": args.envs,
        "episodes": args.episodes,
        "steps": args.steps,
        "repeats": args.repeats,
        "load_average_before": load_before,
        "load_average_after": load_after,
        "cpu_count": os.cpu_count(),
        "dicestack_version": dicestack.__version__,
    }
    if args.json:
        print(json.dumps(result))
        return
    print(f"python_bench: {args.episodes} episodes x {args.steps} steps per measurement, random actions; "
          f"medians of {args.repeats} repeats; {os.cpu_count()} cores, load average "
          f"{load_before[0]:.2f} before, {load_after[0]:.2f} after")
    print(f"  C++ DiceEnv (bench sim), 1 thread      : {m['cpp_1_thread']:10.0f} steps/s")
    print(f"  Python DiceStackEnv.step               : {m['python_env']:10.0f} steps/s  "
          f"({100 * result['python_env_over_cpp_1_thread']:.0f} % of C++; aim >= 50 %)")
    print(f"  C++ DiceEnv (bench sim), {threads} threads     : {m['cpp_threads']:10.0f} steps/s")
    print(f"  Python DiceStackVectorEnv({args.envs}), {threads} threads: {m['python_vector_env']:10.0f} steps/s  "
          f"({100 * result['vector_env_over_cpp_threads']:.0f} % of C++; aim >= 90 %)")


if __name__ == "__main__":
    main()
