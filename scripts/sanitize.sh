#!/usr/bin/env bash
# Builds dicestack with GCC's AddressSanitizer and UndefinedBehaviorSanitizer in build-sanitize/
# and runs the whole CTest suite there: the GoogleTest suites, the CLI and corpus tests, the
# plugin SDK test, the headless player and the pytest suites. Any sanitizer report fails the test
# that produced it; the script exits 1 if a test failed.
#
#   scripts/sanitize.sh [--jobs J] [--build-only] [-- CTEST_ARGS...]
#
#   --jobs J      build and test jobs (default 2)
#   --build-only  configure and build, run nothing
#   CTEST_ARGS    passed to ctest, e.g. -- -R Cmaes
#
# A unity build (a few sources of a target compiled as one file: about half the build time);
# DICESTACK_UNITY_BUILD=OFF builds file by file, for incremental rebuilds while fixing a finding.
# Leak checking is on; scripts/lsan.supp suppresses only leaks allocated inside other projects'
# libraries (today one: libdbus's, under SDL_Init), and the headless player draws with SDL's
# software renderer here (tests/CMakeLists.txt says why). The pytest suites run with the ASan
# runtime preloaded into Debian's interpreter and leak checking off for them
# (python/CMakeLists.txt). Our code is built with -O1 -g1 (line tables: full stack traces with
# inlined frames, at less cost than -g) and assertions on; Debian's libraries stay
# uninstrumented. The README's "Sanitizers" section has the details.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${DICESTACK_SANITIZE_BUILD:-$root/build-sanitize}
jobs=2 build_only=0 ctest_args=()

die() { echo "sanitize.sh: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --jobs) [ $# -ge 2 ] || die "--jobs needs a value"; [[ "$2" =~ ^[1-9][0-9]*$ ]] || die "--jobs takes a positive whole number, got '$2'"
            jobs=$2; shift 2 ;;
    --build-only) build_only=1; shift ;;
    --) shift; ctest_args=("$@"); break ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d'  | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown option '$1' (see --help)" ;;
  esac
done

# Findings fail: ASan aborts, UBSan halts (the code is also built with -fno-sanitize-recover),
# both with a stack trace. Options already in the environment are appended, so they win (e.g.
# ASAN_OPTIONS=detect_stack_use_after_return=1, which makes the suite several times slower).
# Set before the build too: gtest_discover_tests runs the test programs.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:check_initialization_order=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:abort_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

python_args=()
if [ -x /usr/bin/python3 ]; then python_args=(-DPython3_EXECUTABLE=/usr/bin/python3); fi

start=$(date +%s)
mkdir -p "$build"
cmake -S "$root" -B "$build" -DDICESTACK_SANITIZE=ON -DCMAKE_UNITY_BUILD="${DICESTACK_UNITY_BUILD:-ON}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" "${python_args[@]}" \
  > "$build/configure.log" 2>&1 || { cat "$build/configure.log" >&2; die "configuring $build failed"; }
grep -E 'dicestack:|Python tests are skipped|example tests are skipped|headless play test is skipped' \
  "$build/configure.log" || true
cmake --build "$build" -j "$jobs"
built=$(date +%s)
echo "sanitize.sh: built in $((built - start)) s"
[ $build_only -eq 0 ] || exit 0

set +e
ctest --test-dir "$build" --output-on-failure -j "$jobs" "${ctest_args[@]}"
rc=$?
set -e
end=$(date +%s)
echo "sanitize.sh: build $((built - start)) s, tests $((end - built)) s, total $((end - start)) s"
[ $rc -eq 0 ] || { echo "sanitize.sh: tests failed under ASan+UBSan (see above)" >&2; exit 1; }
echo "sanitize.sh: all tests clean under ASan+UBSan"
