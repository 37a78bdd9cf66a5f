#!/usr/bin/env bash
# Wall time of the quick leaderboard and of one DaD run alone and on 2 and 4 MPI ranks, with the
# speed-up and efficiency, and a check that every run wrote the same table and model (timings
# aside). docs/scaling.md has the figures and what they mean.
#   bench/mpi_scaling.sh [DICESTACK] [--runs "1x1 2x1 4x1 1x2"] [--leaderboard-args "..."] [--dad-args "..."]
# A run RxT is R ranks (1: alone, without mpirun) of T threads each; speed-up is against the
# first run, efficiency is speed-up / min(R x T, cores) (per core the run could use).
# Ranks x threads may exceed the machine's cores (Open MPI's --oversubscribe): say so when you
# report the figures. Writes into bench-mpi/ under the current folder.
set -euo pipefail
exe="${1:-build/apps/dicestack}"
shift || true
runs="1x1 2x1 4x1 1x2"
lb_args="--format json"
dad_args="--regressor knn --learner dad --option windows=3 --option iterations=1 --option corrector_iterations=20"
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --leaderboard-args) lb_args="$2"; shift 2 ;;
    --dad-args) dad_args="$2"; shift 2 ;;
    *) echo "mpi_scaling: unknown argument $1" >&2; exit 2 ;;
  esac
done
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out=bench-mpi
mkdir -p "$out"
cores=$(nproc)
run() {  # run N CMD...: "wall cpu" seconds of CMD on N ranks (cpu: user + system of every rank)
  local n="$1"
  shift
  if [ "$n" = 1 ]; then
    /usr/bin/time -f "%e %U %S" -o "$out/time.txt" "$exe" "$@" > "$out/log.txt" 2>&1
  else
    /usr/bin/time -f "%e %U %S" -o "$out/time.txt" mpirun --oversubscribe --bind-to none -np "$n" "$exe" "$@" > "$out/log.txt" 2>&1
  fi || { cat "$out/log.txt" >&2; exit 1; }
  awk '{ printf "%.1f %.1f\n", $1, $2 + $3 }' "$out/time.txt"
}
"$exe" train --regressor knn --out "$out/warm.dsm" > /dev/null  # the built-in set, made once before timing
echo "machine: $cores cores, load $(cut -d' ' -f1-3 /proc/loadavg) before the runs"
printf '%-12s %5s %7s %9s %8s %10s %8s %s\n' job ranks threads seconds speedup efficiency cpu_s note
for job in leaderboard dad; do
  base=""
  for run_spec in $runs; do
    n=${run_spec%x*}
    threads=${run_spec#*x}
    if [ "$job" = leaderboard ]; then
      rm -f "$out/lb-$run_spec.json" "$out/lb-$run_spec.json.partial.json"
      # shellcheck disable=SC2086
      read -r s cpu < <(run "$n" leaderboard $lb_args --threads "$threads" --out "$out/lb-$run_spec.json")
    else
      rm -rf "$out/dad-$run_spec.dsm.checkpoint"
      # shellcheck disable=SC2086
      read -r s cpu < <(run "$n" train $dad_args --threads "$threads" --out "$out/dad-$run_spec.dsm")
    fi
    [ -n "${s:-}" ] || { echo "mpi_scaling: run $run_spec of $job failed" >&2; exit 1; }
    [ -n "$base" ] || base="$s"
    note=""
    [ $((n * threads)) -le "$cores" ] || note="oversubscribed: $((n * threads)) threads on $cores cores"
    python3 -c "
b, s, n = $base, $s, $n
used = min(n * $threads, $cores)
print(f'{\"$job\":<12} {n:>5} {$threads:>7} {s:>9.1f} {b / s:>8.2f} {b / s / used:>10.2f} {$cpu:>8.1f} $note')"
  done
done
# The same results from every rank count (timings aside).
python3 - "$out" $runs <<'PY'
import json, sys, filecmp
out, ranks = sys.argv[1], sys.argv[2:]
def untimed(p):
    t = json.load(open(p))
    for r in t["rows"]:
        r.pop("fit_s"); r.pop("us_per_step")
    return t
first = ranks[0]
for n in ranks[1:]:
    assert untimed(f"{out}/lb-{n}.json") == untimed(f"{out}/lb-{first}.json"), f"leaderboard of run {n} differs"
    assert filecmp.cmp(f"{out}/dad-{n}.dsm", f"{out}/dad-{first}.dsm", shallow=False), f"DaD model of run {n} differs"
print("identical tables and models from runs", ", ".join(ranks), "(ranks x threads)")
# Per-row costs of the single-process run (fit time + rollouts), for the projection.
t = json.load(open(f"{out}/lb-{first}.json"))
print("rows of run", first, "(ranks x threads): fit_s, us_per_step")
for r in t["rows"]:
    print(f"  {r['learner']:<9} {r['features']:<24} {r['regressor']:<16} {r['fit_s']:>8.2f} {r['us_per_step']:>8.1f}")
PY
