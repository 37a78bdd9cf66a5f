#!/usr/bin/env bash
# A regressor plugin links only the regressor interface and the foundation: loading
# it must not load the simulator, the optimisers, OpenCV or xgboost. Fails if `ldd` of any
# library given lists Box2D, pagmo, NLopt, OpenCV or xgboost, or cannot resolve a dependency.
# Used by CTest on the in-tree example plugin and by plugin_sdk.sh on the out-of-tree one.
set -euo pipefail
forbidden='lib(box2d|pagmo|nlopt|opencv_[a-z]+|xgboost)\.so'
status=0
for lib in "$@"; do
  if [[ ! -f "$lib" ]]; then
    echo "FAIL: $lib: no such file"; status=1; continue
  fi
  deps="$(ldd "$lib")"
  if grep -q 'not found' <<<"$deps"; then
    echo "FAIL: $lib: a dependency is not found:"; grep 'not found' <<<"$deps"; status=1
  fi
  if ! grep -q 'libdicestack_regressor_api\.so' <<<"$deps"; then
    echo "FAIL: $lib: does not load libdicestack_regressor_api (is it a dicestack plugin?)"; status=1
  fi
  if grep -Eq "$forbidden" <<<"$deps"; then
    echo "FAIL: $lib loads libraries a regressor plugin must not:"; grep -E "$forbidden" <<<"$deps"; status=1
  else
    echo "ok: $lib loads no Box2D, pagmo, NLopt, OpenCV or xgboost"
  fi
done
exit "$status"
