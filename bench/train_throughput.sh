#!/usr/bin/env bash
# Training throughput of `pixelgym train` on the demo's settings (`make demo`: CartPoleBalance-v1
# from 64x64 anti-aliased grey frames, 3 stacked, action_repeat 8, the demo's PPO config),
# updates included, and where each update's time goes: stepping the envs (env_s), the policy's
# forward passes while collecting (act_s) and the epochs of the update (update_s), from the run's
# progress.csv.
#
# usage: [FRAMES=rgb] bench/train_throughput.sh [build-dir] [env-steps] [extra train options ...]
#   env-steps: how long to train (default 20480: 20 updates of 8 envs x 128 steps)
#   extra options go to `pixelgym train` after the demo's, e.g. --threads 1
#   FRAMES=rgb: colour frames instead of grey (no --wrap grayscale), as the demo was before
# Prints the medians over the updates after the first (which includes start-up):
#   env_steps_per_s=   env steps per second of wall time, updates included
#   env_s= act_s= update_s= seconds per update, and each one's share of the update's time
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
steps=${2:-20480}
shift $(($# < 2 ? $# : 2))
pixelgym="$build/examples/pixelgym"
[ -x "$pixelgym" ] || { echo "train_throughput: build $pixelgym first (make build)" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
grey=(--wrap grayscale)
[ "${FRAMES:-grey}" = rgb ] && grey=()
"$pixelgym" train CartPoleBalance-v1 --set obs_mode=pixels --set width=64 --set height=64 \
  --set msaa=4 --set action_repeat=8 "${grey[@]}" --wrap frame_stack=3 \
  --config examples/trainer/ppo/configs/action_repeat_8.json --steps "$steps" --eval-episodes 1 --quiet \
  --out "$out/run" "$@" > "$out/log.txt"
/usr/bin/python3 - "$out/run/progress.csv" <<'EOF'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))[1:]  # the first update includes start-up
if not rows:
    sys.exit("train_throughput: too few updates; give more env steps")
def median(key):
    return statistics.median(float(row[key]) for row in rows)
env_s, act_s, update_s, fps = median("env_s"), median("act_s"), median("update_s"), median("fps")
total = env_s + act_s + update_s
print(f"updates={len(rows)} (after the first) env_steps_per_s={fps:.0f}")
for name, value in (("env_s", env_s), ("act_s", act_s), ("update_s", update_s)):
    print(f"{name}={value:.3f} ({100 * value / total:.1f}%)")
EOF
