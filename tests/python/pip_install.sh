#!/usr/bin/env bash
# `pip install .` as README shows it, into a fresh venv, from this build tree (setup.py's
# DICESTACK_BUILD_DIR: no second C++ build); then, from another folder and with no PYTHONPATH:
# `import dicestack` finds the venv's package, the `dicestack` command runs a leaderboard, and
# gymnasium.make("dicestack/DiceStack-v0") works when gymnasium is installed.
#   pip_install.sh SOURCE_DIR BUILD_DIR PYTHON
set -euo pipefail
src="$1" build="$2" python="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
unset PYTHONPATH DICESTACK_EXE
"$python" -m venv --system-site-packages "$work/v"
# pip builds in the source tree; its setuptools scratch goes to build-pip/ (ignored by git).
(cd "$src" && DICESTACK_BUILD_DIR="$build" "$work/v/bin/pip" install --no-build-isolation --no-index --quiet .) \
  > "$work/pip.log" 2>&1 || { cat "$work/pip.log"; fail "pip install failed"; }
mkdir "$work/elsewhere" && cd "$work/elsewhere"
where=$("$work/v/bin/python" -c "import dicestack; print(dicestack.__file__)")
case "$where" in "$work/v/"*) ;; *) fail "import dicestack found $where, not the venv's package" ;; esac
"$work/v/bin/python" -c "
import dicestack
env = dicestack.DiceStackEnv()
obs, info = env.reset(seed=3)
assert obs.shape == (24,), obs.shape
print('python ok:', dicestack.regressor_names()[:3])
"
[ -x "$work/v/bin/dicestack" ] || fail "no dicestack command in the venv"
"$work/v/bin/dicestack" --version | grep -q "^dicestack " || fail "dicestack --version"
"$work/v/bin/dicestack" leaderboard --learners bc --regressors linear_svr --episodes 1 --threads 1 --out board.md > leaderboard.log 2>&1 \
  || { cat leaderboard.log; fail "the venv's dicestack leaderboard failed"; }
grep -q "| linear_svr | bc |" board.md || fail "no linear_svr row in the leaderboard"
if "$work/v/bin/python" -c "import gymnasium" 2>/dev/null; then
  "$work/v/bin/python" -c "import gymnasium; e = gymnasium.make('dicestack/DiceStack-v0'); e.reset(seed=0); print('gymnasium ok')"
else
  echo "gymnasium is not installed: gymnasium.make not checked"
fi
# The CMake package is installed too: find_package(dicestack) from the venv's prefix.
[ -f "$work/v/lib/cmake/dicestack/dicestackConfig.cmake" ] || fail "no CMake package in the venv"
echo "pip install: ok"
