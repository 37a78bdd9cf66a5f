#!/usr/bin/env bash
# Builds dicestack's libFuzzer harnesses (fuzz/) with clang, ASan and UBSan in build-fuzz/, and
# runs each one for N executions over its seed corpus (fuzz/corpus/<target>/). Prints, per
# target, the executions, crashes, executions per second and seconds; exits 1 if any crashed.
#
#   scripts/fuzz.sh [TARGET...] [--runs N] [--time S] [--jobs J] [--make-seeds] [--build-only]
#
#   TARGET        episode_csv demo_meta world_config model_file payload_knn payload_linear_svr
#                 payload_rbf_svr payload_mlp payload_random_forest payload_gbt (default: all)
#   --runs N      executions per target (default 1000000; 0 = no limit, use with --time)
#   --time S      also stop a target after S seconds
#   --jobs J      build jobs (default 2)
#   --make-seeds  regenerate the generated seeds (fitted payloads and model files, the default
#                 world config, a written meta.json and episode CSV) into fuzz/corpus/
#   --build-only  configure and build, run nothing
#
# New inputs the fuzzer finds go to build-fuzz/corpus/<target>/ (never into the repository);
# a crash is saved as build-fuzz/artifacts/<target>/crash-<sha1> (or leak-, oom-, timeout-),
# with libFuzzer's whole log in build-fuzz/logs/<target>.log. Reproduce one with
#   build-fuzz/fuzz/fuzz_<target> build-fuzz/artifacts/<target>/crash-...
# Needs clang and libclang-rt-14-dev (scripts/install-deps.sh installs both).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${DICESTACK_FUZZ_BUILD:-$root/build-fuzz}
all=(episode_csv demo_meta world_config model_file payload_knn payload_linear_svr payload_rbf_svr payload_mlp
     payload_random_forest payload_gbt)
runs=1000000 seconds=0 jobs=2 make_seeds=0 build_only=0 targets=()

die() { echo "fuzz.sh: $*" >&2; exit 2; }
number() { [[ "$2" =~ ^[0-9]+$ ]] || die "$1 takes a whole number, got '$2'"; }
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) [ $# -ge 2 ] || die "--runs needs a value"; number --runs "$2"; runs=$2; shift 2 ;;
    --time) [ $# -ge 2 ] || die "--time needs a value"; number --time "$2"; seconds=$2; shift 2 ;;
    --jobs) [ $# -ge 2 ] || die "--jobs needs a value"; number --jobs "$2"; jobs=$2; shift 2 ;;
    --make-seeds) make_seeds=1; shift ;;
    --build-only) build_only=1; shift ;;
    -h|--help) sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *) [[ " ${all[*]} " == *" $1 "* ]] || die "unknown target '$1'; targets: ${all[*]}"; targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=("${all[@]}")
[ "$jobs" -ge 1 ] || die "--jobs must be at least 1"
[ "$runs" -gt 0 ] || [ "$seconds" -gt 0 ] || die "--runs 0 needs --time S"
command -v clang++ > /dev/null || die "clang++ not found; run scripts/install-deps.sh"

mkdir -p "$build"
# RelWithDebInfo without -DNDEBUG: assertions (ours and Eigen's) stay on, so a broken invariant
# is a finding too.
cmake -S "$root" -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DDICESTACK_FUZZ=ON \
  -DDICESTACK_BUILD_TESTS=OFF -DDICESTACK_BUILD_APPS=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g" > "$build/configure.log" 2>&1 \
  || { cat "$build/configure.log" >&2; die "configuring $build failed"; }
build_targets=()
for t in "${targets[@]}"; do build_targets+=("fuzz_$t"); done
[ $make_seeds -eq 0 ] || build_targets+=(dicestack_fuzz_seeds)
cmake --build "$build" -j "$jobs" --target "${build_targets[@]}"
[ $make_seeds -eq 0 ] || "$build/fuzz/dicestack_fuzz_seeds" "$root/fuzz/corpus"
[ $build_only -eq 0 ] || exit 0

mkdir -p "$build/logs"
failed=0
rows=()
for t in "${targets[@]}"; do
  work="$build/corpus/$t" artifacts="$build/artifacts/$t/" log="$build/logs/$t.log"
  mkdir -p "$work" "$artifacts"
  before=$(find "$artifacts" -maxdepth 1 -type f | wc -l)
  args=(-runs=$([ "$runs" -gt 0 ] && echo "$runs" || echo -1) -print_final_stats=1 -timeout=30 -rss_limit_mb=2048
        -artifact_prefix="$artifacts")
  [ "$seconds" -eq 0 ] || args+=(-max_total_time="$seconds")
  [ ! -f "$root/fuzz/dict/$t.dict" ] || args+=(-dict="$root/fuzz/dict/$t.dict")
  echo "fuzz.sh: $t: fuzz_$t ${args[*]} $work $root/fuzz/corpus/$t"
  start=$(date +%s%N)
  set +e
  "$build/fuzz/fuzz_$t" "${args[@]}" "$work" "$root/fuzz/corpus/$t" > "$log" 2>&1
  rc=$?
  set -e
  elapsed=$(awk -v a="$start" -v b="$(date +%s%N)" 'BEGIN { printf "%.1f", (b - a) / 1e9 }')
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  crashes=$(( $(find "$artifacts" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'oom-*' \
                 -o -name 'timeout-*' \) | wc -l) - before ))
  [ "$crashes" -ge 0 ] || crashes=0
  if [ $rc -ne 0 ] && [ "$crashes" -eq 0 ]; then crashes=1; fi
  if [ "$crashes" -gt 0 ]; then
    failed=1
    echo "fuzz.sh: $t: FINDING (exit status $rc); the end of $log:" >&2
    grep -E 'ERROR|SUMMARY|dicestack fuzz|Test unit written|what\(\)|uncaught' "$log" | head -20 >&2 || true
  fi
  rows+=("$(printf '%-22s %12s %8s %10s %9s' "$t" "${execs:-?}" "$crashes" "${rate:-?}" "$elapsed")")
done

printf '\n%-22s %12s %8s %10s %9s\n' target executions crashes exec/s seconds
printf '%s\n' "${rows[@]}"
exit $failed
