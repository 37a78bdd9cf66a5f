#!/usr/bin/env bash
# Same seed, same result, on any number of MPI ranks: one subcommand run alone and
# under mpirun -np 2 and -np 3 (with 1 and 2 threads per rank), outputs compared byte for byte
# (timing fields removed from JSON). `failure` checks that a rank that fails or dies ends the
# whole run quickly with a clear message.
#   mpi_ranks.sh DICESTACK MPIRUN MODE     MODE: record | tracker | evaluate | perturb | dagger | dad | dart | leaderboard | optimise | reinforce | rrt | failure
set -euo pipefail
exe="$1"
mpirun="$2"
mode="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export DICESTACK_CACHE_DIR="$work/cache"
# As root in a container: Open MPI refuses root without these, and oversubscribes 2 cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
ranks() {  # ranks N CMD...: run CMD on N ranks (N = 1: alone, without mpirun)
  local n="$1"
  shift
  if [ "$n" = 1 ]; then "$exe" "$@"; else "$mpirun" --oversubscribe --bind-to none -np "$n" "$exe" "$@"; fi
}
fail() { echo "FAIL: $*"; exit 1; }
same() {  # same A B: byte-identical files or folders
  diff -r "$1" "$2" > "$work/diff.txt" || { head -20 "$work/diff.txt"; fail "$1 and $2 differ"; }
}
# JSON without its timing fields (seconds, fit_s, us_per_step, seconds_per_episode, the rates), keys sorted.
untimed() {
  python3 - "$1" <<'PY'
import json, sys
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in ("seconds", "fit_s", "us_per_step", "seconds_per_episode", "evaluations_per_second",
                                                        "steps_per_second")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
print(json.dumps(strip(json.load(open(sys.argv[1]))), sort_keys=True, indent=1))
PY
}

# A short world (4 s episodes) and a few demonstrations of the scripted expert.
"$exe" config --out "$work/world.json" > /dev/null
python3 - "$work/world.json" <<'PY'
import json, sys
w = json.load(open(sys.argv[1])); w["episode"]["max_steps"] = 120; json.dump(w, open(sys.argv[1], "w"))
PY
world=(--world "$work/world.json")
"$exe" record --expert scripted --episodes 10 --seed 7 --out "$work/demos" --threads 2 "${world[@]}" > /dev/null

case "$mode" in
  record)
    for run in "1 2" "2 1" "3 2"; do
      set -- $run
      ranks "$1" record --expert scripted --episodes 7 --seed 3 --noise 0.1 --threads "$2" --out "$work/rec-$1" "${world[@]}" > /dev/null
    done
    same "$work/rec-1" "$work/rec-2"
    same "$work/rec-1" "$work/rec-3"
    ;;
  tracker)  # the demonstrator made of recordings: its ranking and its episodes, then DART through it
    for run in "1 2" "2 1" "3 2"; do
      set -- $run
      ranks "$1" record --expert tracker --demos "$work/demos" --episodes 5 --seed 3 --noise 0.1 --threads "$2" \
        --out "$work/rec-$1" "${world[@]}" > /dev/null
      ranks "$1" train --regressor knn --learner dart --option expert=tracker --option episodes=5 \
        --option successes_only=false --option tracker_probes=2 --option tracker_robust=2 \
        --option tracker_refine=1 --option tracker_refine_probes=2 --demos "$work/demos" --seed 4 --threads "$2" \
        --out "$work/dart-$1.dsm" "${world[@]}" > /dev/null
    done
    grep -q 'expert tracker' "$work/rec-1/meta.json" || fail "the set does not name its expert"
    same "$work/rec-1" "$work/rec-2"
    same "$work/rec-1" "$work/rec-3"
    same "$work/dart-1.dsm" "$work/dart-2.dsm"
    same "$work/dart-1.dsm" "$work/dart-3.dsm"
    ;;
  evaluate)
    "$exe" train --regressor knn --demos "$work/demos" --out "$work/knn.dsm" "${world[@]}" > /dev/null
    for run in "1 2" "2 2" "3 1"; do
      set -- $run
      ranks "$1" evaluate --model "$work/knn.dsm" --episodes 7 --seed 5 --threads "$2" --json --demos "$work/demos" \
        --save-rollouts "$work/roll-$1" "${world[@]}" > "$work/eval-$1.json"
      untimed "$work/eval-$1.json" > "$work/eval-$1.txt"
    done
    grep -q '"episodes": 7' "$work/eval-1.txt" || fail "no evaluation in $(cat "$work/eval-1.json")"
    same "$work/eval-1.txt" "$work/eval-2.txt"
    same "$work/eval-1.txt" "$work/eval-3.txt"
    same "$work/roll-1" "$work/roll-2"
    same "$work/roll-1" "$work/roll-3"
    ;;
  perturb)  # perturbed worlds: the robustness table, a perturbed evaluation and recording with their draws
    "$exe" train --regressor knn --demos "$work/demos" --out "$work/knn.dsm" "${world[@]}" > /dev/null
    for run in "1 2" "2 1" "3 2"; do
      set -- $run
      ranks "$1" robustness --model "$work/knn.dsm" --episodes 3 --seed 2 --threads "$2" --format csv \
        --out "$work/rob-$1.csv" "${world[@]}" > /dev/null 2>&1
      ranks "$1" evaluate --model "$work/knn.dsm" --episodes 5 --seed 5 --threads "$2" --perturb hard \
        --save-rollouts "$work/roll-$1" "${world[@]}" > /dev/null
      ranks "$1" record --expert scripted --episodes 5 --seed 3 --threads "$2" --perturb medium \
        --out "$work/rec-$1" "${world[@]}" > /dev/null
    done
    grep -q '"perturbation"' "$work/roll-1/meta.json" || fail "the rollouts do not carry their draws"
    for n in 2 3; do
      same "$work/rob-1.csv" "$work/rob-$n.csv"
      same "$work/roll-1" "$work/roll-$n"
      same "$work/rec-1" "$work/rec-$n"
    done
    ;;
  dagger|dad|dart)
    if [ "$mode" = dagger ]; then
      opts=(--learner dagger --option iterations=2 --option rollouts=5 --option expert=scripted --option beta=0.5)
    elif [ "$mode" = dart ]; then
      opts=(--learner dart --option expert=scripted --option episodes=7 --option successes_only=false)
    else
      opts=(--learner dad --option windows=2 --option iterations=1 --option corrector_iterations=3 --option demos=3)
    fi
    for run in "1 2" "2 1" "3 2"; do
      set -- $run
      ranks "$1" train --regressor knn --demos "$work/demos" --seed 4 --threads "$2" --out "$work/$mode-$1.dsm" \
        "${opts[@]}" "${world[@]}" > /dev/null
    done
    same "$work/$mode-1.dsm" "$work/$mode-2.dsm"
    same "$work/$mode-1.dsm" "$work/$mode-3.dsm"
    [ "$mode" = dart ] && { echo "mpi_ranks $mode: ok"; exit 0; }
    same "$work/$mode-1.dsm.curve.csv" "$work/$mode-2.dsm.curve.csv"
    same "$work/$mode-1.dsm.curve.csv" "$work/$mode-3.dsm.curve.csv"
    [ "$(ls "$work/$mode-2.dsm.checkpoint" | wc -l)" -ge 2 ] || fail "no checkpoint written under mpirun"
    if [ "$mode" = dad ]; then  # on the arm in joint torques: the corrections travel with their links
      # (the default world: the tracker's targets must stack, which 4 s episodes are too short for)
      arm=(--learner dad --option starts=training --option corrector=track --option episodes=3 --option windows=1
        --option iterations=1 --option tracker_probes=1 --option tracker_robust=1 --option tracker_variants=false
        --embodiment arm --controller joint_torque)
      for n in 1 3; do
        ranks "$n" train --regressor knn --demos "$work/demos" --seed 4 --threads 1 --out "$work/arm-$n.dsm" "${arm[@]}" > /dev/null
      done
      same "$work/arm-1.dsm" "$work/arm-3.dsm"
      same "$work/arm-1.dsm.curve.csv" "$work/arm-3.dsm.curve.csv"
    fi
    if [ "$mode" = dagger ]; then  # one more round resumed on 3 ranks = three rounds alone
      three=("${opts[@]/iterations=2/iterations=3}")
      "$exe" train --regressor knn --demos "$work/demos" --seed 4 --out "$work/three.dsm" "${three[@]}" "${world[@]}" > /dev/null
      ranks 3 train --regressor knn --demos "$work/demos" --seed 4 --out "$work/$mode-2.dsm" "${three[@]}" --resume \
        "${world[@]}" > /dev/null
      same "$work/three.dsm" "$work/$mode-2.dsm"
      same "$work/three.dsm.curve.csv" "$work/$mode-2.dsm.curve.csv"
    fi
    ;;
  leaderboard)
    for run in "1 2" "2 1" "3 1"; do
      set -- $run
      ranks "$1" leaderboard --demos "$work/demos" --regressors knn,linear_svr --learners bc,dagger --option expert=scripted \
        --episodes 4 --seeds 2 --threads "$2" --format json --out "$work/lb-$1.json" "${world[@]}" > /dev/null
      untimed "$work/lb-$1.json" > "$work/lb-$1.txt"
      [ ! -e "$work/lb-$1.json.partial.json" ] || fail "the progress file was left behind"
    done
    grep -q '"learner": "dagger"' "$work/lb-1.txt" || fail "no dagger row"
    same "$work/lb-1.txt" "$work/lb-2.txt"
    same "$work/lb-1.txt" "$work/lb-3.txt"
    # The results page: every row's per-episode results and previews travel between ranks.
    for n in 1 3; do
      mkdir -p "$work/page-$n"
      ranks "$n" leaderboard --demos "$work/demos" --regressors knn --learners bc,dagger --option expert=scripted \
        --episodes 4 --seeds 2 --threads 1 --format html --out "$work/page-$n/board.html" "${world[@]}" > /dev/null
    done
    # The media sit in one generation folder, named by their digest: the same media, the same name.
    media=("$work/page-1/board_files/"m-*)
    [ "${#media[@]}" = 1 ] && [ -d "${media[0]}" ] || fail "expected one generation of media"
    ls "${media[0]}/previews/"*.gif > /dev/null || fail "no previews"
    [ "$(ls "${media[0]}/eval_info" | wc -l)" = 2 ] || fail "expected the per-episode results of 2 rows"
    same "$work/page-1/board_files" "$work/page-3/board_files"
    # Resume: a progress file with one finished row is reused under mpirun, not recomputed.
    python3 - "$work/lb-1.json" "$work/lb-r.json.partial.json" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))
meta = {k: v for k, v in t.items() if k not in ("format", "version", "rows")}
row = next(r for r in t["rows"] if r["learner"] == "bc" and r["regressor"] == "knn")
row["fit_s"] = 1234.5  # a mark: a reused row keeps it
json.dump({"format": "dicestack-leaderboard-partial", "version": 1, "meta": meta, "rows": {"bc/state/knn": row}},
          open(sys.argv[2], "w"))
PY
    ranks 3 leaderboard --demos "$work/demos" --regressors knn,linear_svr --learners bc,dagger --option expert=scripted \
      --episodes 4 --seeds 2 --threads 1 --format json --out "$work/lb-r.json" "${world[@]}" > /dev/null
    grep -q '"fit_s": 1234.5' "$work/lb-r.json" || fail "the finished row in the progress file was not reused"
    untimed "$work/lb-r.json" > "$work/lb-r.txt"
    same "$work/lb-1.txt" "$work/lb-r.txt"
    ;;
  optimise)  # CMA-ES's generations shared among the ranks
    for run in "1 2" "2 1" "3 2"; do
      set -- $run
      ranks "$1" optimise --method cmaes --steps 12 --evaluations 150 --seed 2 --threads "$2" --out "$work/opt-$1" \
        "${world[@]}" > /dev/null
      untimed "$work/opt-$1/optimise.json" | grep -v '"out":' > "$work/opt-$1.txt"  # its own folder
      rm "$work/opt-$1/optimise.json"
    done
    grep -q '"best_cost"' "$work/opt-1.txt" || fail "no optimisation result"
    same "$work/opt-1.txt" "$work/opt-2.txt"
    same "$work/opt-1.txt" "$work/opt-3.txt"
    same "$work/opt-1" "$work/opt-2"
    same "$work/opt-1" "$work/opt-3"
    ;;
  reinforce|rrt)  # REINFORCE's batches and the RRT's CMA-ES generations shared among the ranks
    if [ "$mode" = reinforce ]; then
      opts=(--iterations 4 --batch 5 --steps 20 --seed 6)
    else
      opts=(--nodes 6 --extend-steps 5 --seed 6)
    fi
    for run in "1 2" "2 1" "3 2"; do
      set -- $run
      ranks "$1" "$mode" "${opts[@]}" --threads "$2" --out "$work/$mode-$1" "${world[@]}" > /dev/null
      untimed "$work/$mode-$1/$mode.json" | grep -v '"out":' > "$work/$mode-$1.txt"  # its own folder
      rm "$work/$mode-$1/$mode.json"
    done
    same "$work/$mode-1.txt" "$work/$mode-2.txt"
    same "$work/$mode-1.txt" "$work/$mode-3.txt"
    same "$work/$mode-1" "$work/$mode-2"
    same "$work/$mode-1" "$work/$mode-3"
    ;;
  failure)
    "$exe" train --regressor knn --demos "$work/demos" --out "$work/knn.dsm" "${world[@]}" > /dev/null
    for how in throw exit; do
      start=$(date +%s)
      set +e
      DICESTACK_MPI_TEST_FAIL="1:$how" timeout 60 "$mpirun" --oversubscribe --bind-to none -np 3 "$exe" \
        evaluate --model "$work/knn.dsm" --episodes 3 "${world[@]}" > "$work/out.txt" 2> "$work/err.txt"
      status=$?
      set -e
      [ "$status" -ne 0 ] || fail "$how: a failed rank did not fail the run"
      [ "$status" -ne 124 ] || fail "$how: the run hung"
      secs=$(( $(date +%s) - start ))
      [ "$secs" -le 30 ] || fail "$how: ending took $secs s"
      cat "$work/err.txt"
      if [ "$how" = throw ]; then
        grep -q "dicestack: error: rank 1: failure injected by DICESTACK_MPI_TEST_FAIL (rank 1 of 3 on " "$work/err.txt" \
          || fail "no clear message from the failed rank"
        [ "$(grep -c '^dicestack: error' "$work/err.txt")" = 1 ] || fail "the message was printed more than once"
      fi
      echo "$how: exit status $status after $secs s"
    done
    # An error every rank meets is printed once, by the root.
    set +e
    "$mpirun" --oversubscribe --bind-to none -np 3 "$exe" train --regressor nosuch --demos "$work/demos" --out "$work/x.dsm" \
      > /dev/null 2> "$work/err.txt"
    status=$?
    set -e
    [ "$status" -ne 0 ] || fail "a bad regressor name did not fail the run"
    [ "$(grep -c '^dicestack: error: unknown regressor "nosuch"' "$work/err.txt")" = 1 ] || { cat "$work/err.txt"; fail "not printed once"; }
    ;;
  *) fail "unknown mode $mode" ;;
esac
echo "mpi_ranks $mode: ok"
