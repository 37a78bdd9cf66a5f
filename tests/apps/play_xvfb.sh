#!/usr/bin/env bash
# Plays `dicestack play` headless under Xvfb, driven by xdotool key-down/key-up: holds the
# right arrow, takes a screenshot (p), quits (Escape), then checks the recorded episode (valid
# set, cup moved right, vertical motion stopped) and the screenshot (a 900 x 700 PNG).
set -euo pipefail
exe="$1"
work="$(mktemp -d)"
display=":$((90 + RANDOM % 100))"
xvfb_pid=""
play_pid=""
cleanup() {
  for pid in $play_pid $xvfb_pid; do kill "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

Xvfb "$display" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
xvfb_pid=$!
export DISPLAY="$display" SDL_VIDEODRIVER=x11
for _ in $(seq 50); do xdotool getdisplaygeometry >/dev/null 2>&1 && break; sleep 0.1; done

"$exe" play --record "$work/rec" --start paper --seed 3 --screenshot-dir "$work" --max-seconds 20 > "$work/out.txt" 2>&1 &
play_pid=$!
wid="$(xdotool search --sync --name '^dicestack$' | head -1)"
xdotool windowfocus --sync "$wid"
sleep 0.5
xdotool keydown Right
sleep 0.3
xdotool keyup Right
sleep 0.5
xdotool key p
sleep 0.5
xdotool key Escape
play_status=0
wait "$play_pid" || play_status=$?
play_pid=""
cat "$work/out.txt"
[ "$play_status" -eq 0 ] || { echo "FAIL: dicestack play exited with status $play_status"; exit 1; }

"$exe" dataset validate "$work/rec"
csv="$work/rec/episode_0000.csv"
# Columns: 2 cup_x, 3 cup_y; the cup must have moved right by more than 0.5 m, and its height
# must stay within 0.2 m (released up/down keys stop vertical motion).
awk -F, 'NR == 2 { x0 = $2; y0 = $3 } NR > 1 { if ($2 > xmax) xmax = $2; dy = $3 - y0; if (dy < 0) dy = -dy; if (dy > dymax) dymax = dy }
         END { printf "cup x %.3f -> max %.3f, max |dy| %.3f over %d rows\n", x0, xmax, dymax, NR - 1;
               if (xmax - x0 < 0.5) { print "FAIL: cup did not move right"; exit 1 }
               if (dymax > 0.2) { print "FAIL: cup drifted vertically"; exit 1 } }' "$csv"

# Format v2: quit mid-episode, the recording keeps its final state and is a truncation; every
# row has a reward.
grep -q '"truncated": true' "$work/rec/meta.json" || { echo "FAIL: the recording is not marked truncated"; exit 1; }
if grep -q '"final_state": null' "$work/rec/meta.json"; then echo "FAIL: the recording has no final state"; exit 1; fi
awk -F, 'NR > 1 && $30 == "" { print "FAIL: row " NR " has no reward"; exit 1 }' "$csv"

png="$work/dicestack_0.png"
test -s "$png" || { echo "FAIL: no screenshot"; exit 1; }
# PNG header: width and height are big-endian 32-bit integers at bytes 16-23.
size="$(od -An -tu1 -j16 -N8 "$png" | awk '{ printf "%dx%d", $1*16777216+$2*65536+$3*256+$4, $5*16777216+$6*65536+$7*256+$8 }')"
echo "screenshot $size"
test "$size" = "900x700" || { echo "FAIL: screenshot is $size, expected 900x700"; exit 1; }
echo "play_xvfb: ok"
