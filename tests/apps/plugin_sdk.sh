#!/usr/bin/env bash
# The plugin SDK end to end: install dicestack into a scratch prefix, build the documented
# example plugin out of tree with find_package(dicestack), load it with --plugin and with
# DICESTACK_PLUGIN_PATH, list it, and train and evaluate it on the paper's recordings.
set -euo pipefail
build_dir="$1"
source_dir="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" > /dev/null
cmake -S "$source_dir/examples/ridge_plugin" -B "$work/plugin" -DCMAKE_PREFIX_PATH="$work/prefix" \
      -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$work/plugin" -j 2 > /dev/null
plugin="$work/plugin/libridge.so"
test -f "$plugin" || { echo "FAIL: plugin not built"; exit 1; }

exe="$work/prefix/bin/dicestack"
export DICESTACK_CACHE_DIR="$work/cache"
"$exe" regressors --plugin "$plugin" | tee "$work/list.txt" | grep -A1 "^ridge"
grep -q "^ridge  (plugin $plugin)" "$work/list.txt" || { echo "FAIL: ridge not listed as a plugin"; exit 1; }
DICESTACK_PLUGIN_PATH="$work/plugin" "$exe" regressors --json | grep -q '"name":"ridge"' \
  || { echo "FAIL: DICESTACK_PLUGIN_PATH did not load the plugin"; exit 1; }
"$exe" bench regressors --plugin "$plugin" --regressors ridge --set lambda=2 --calls 100 | tee "$work/bench.txt"
awk '$1 == "ridge" { if ($5 > 0 && $5 < 2 && $6 > 0 && $6 < 2) ok = 1 } END { exit ok ? 0 : 1 }' "$work/bench.txt" \
  || { echo "FAIL: ridge did not train and evaluate"; exit 1; }
echo "plugin_sdk: ok"
