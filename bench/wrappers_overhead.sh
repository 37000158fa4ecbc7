#!/usr/bin/env bash
# The cost of the train-ready pixel stack over a bare pixel step, measured side by side in one run:
# `pixelgym bench ID` bare and with `--wrap resize=64x64 --wrap grayscale --wrap frame_stack=3`
# (each wrapper alone, and the stack with grayscale first, as Gymnasium's AtariPreprocessing
# orders it: then the resize works on one channel instead of three), runs interleaved so that drift on a shared machine hits both alike.
#
# usage: bench/wrappers_overhead.sh [build-dir] [repeats] [id] [steps]
# Prints the median steps/s of each configuration and its overhead over the bare step,
# (bare / wrapped - 1): the time each step gains, as a share of the bare step's. Target for the
# whole stack: <= 10 % on CartPoleSwingup-v0 at 84x84.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
repeats=${2:-7}
id=${3:-CartPoleSwingup-v0}
steps=${4:-10000}
pixelgym="$build/examples/pixelgym"
[ -x "$pixelgym" ] || { echo "wrappers_overhead: build $pixelgym first (make build)" >&2; exit 1; }
export LP_NUM_THREADS=${LP_NUM_THREADS:-0}

configs=("" "--wrap resize=64x64" "--wrap grayscale" "--wrap frame_stack=3"
         "--wrap resize=64x64 --wrap grayscale --wrap frame_stack=3"
         "--wrap grayscale --wrap resize=64x64 --wrap frame_stack=3")
names=("bare" "resize=64x64" "grayscale" "frame_stack=3" "resize=64x64 + grayscale + frame_stack=3"
       "grayscale + resize=64x64 + frame_stack=3")
declare -A rates
for r in $(seq "$repeats"); do
  for i in "${!configs[@]}"; do
    # shellcheck disable=SC2086  # the wrap options are meant to split
    rate=$("$pixelgym" bench "$id" --steps "$steps" --seed "$r" ${configs[$i]} |
           sed -n 's/^steps_per_s=\([0-9]*\)$/\1/p')
    rates[$i]="${rates[$i]:-} $rate"
  done
done
median() { tr ' ' '\n' | sed '/^$/d' | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
bare=$(echo "${rates[0]}" | median)
echo "$id, 84x84, LP_NUM_THREADS=$LP_NUM_THREADS, one thread: medians of $repeats runs of $steps steps"
printf '  %-44s %12s %10s\n' "wrappers" "steps/s" "overhead"
for i in "${!configs[@]}"; do
  m=$(echo "${rates[$i]}" | median)
  printf '  %-44s %12s %9s%%\n' "${names[$i]}" "$m" "$(awk -v b="$bare" -v w="$m" 'BEGIN {printf "%.1f", (b / w - 1) * 100}')"
done
