#!/usr/bin/env bash
# Renderer frames per second beside ../shared/peers/floor, measured in the same run.
#
# usage: bench/render_vs_floor.sh [build-dir] [repeats]
# For each size (64, 84, 128, 256), scene (cartpole, arm), shadows (off, on) and llvmpipe thread
# setting (LP_NUM_THREADS=0, and unset: llvmpipe's default of one thread per core), prints the
# median frames per second of `repeats` runs and the ratio to the floor program's median at the
# same size and thread setting. pixelgym's library sets LP_NUM_THREADS=0 when it is unset, so the
# "unset" rows run pixelgym with LP_NUM_THREADS=$(nproc), llvmpipe's own default.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
repeats=${2:-3}
floor_src=../shared/peers/floor/floor.c
[ -f "$floor_src" ] || { echo "render_vs_floor: $floor_src not found" >&2; exit 1; }
mkdir -p "$build/peers"
cc -O2 -o "$build/peers/floor" "$floor_src" -lOSMesa -lm
bench="$build/bench/render_bench"
[ -x "$bench" ] || { echo "render_vs_floor: build $bench first (make build)" >&2; exit 1; }

median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
fps() { sed -n 's/.*frames_per_s=\([0-9.]*\).*/\1/p'; }
frames_for() { case $1 in 64|84) echo 4000;; 128) echo 2500;; *) echo 800;; esac; }

printf '%-8s %-8s %-9s %-8s %12s %12s %7s\n' threads size scene shadows pixelgym floor ratio
for threads in 0 unset; do
  for size in 64 84 128 256; do
    n=$(frames_for "$size")
    if [ "$threads" = 0 ]; then env_floor="LP_NUM_THREADS=0"; env_ours="LP_NUM_THREADS=0"
    else env_floor="-u LP_NUM_THREADS"; env_ours="LP_NUM_THREADS=$(nproc)"; fi
    floor_fps=$(for r in $(seq "$repeats"); do env $env_floor "$build/peers/floor" "$size" "$size" "$n" | fps; done | median)
    for scene in cartpole arm; do
      for shadows in off on; do
        arg=$([ "$shadows" = on ] && echo shadows || true)
        ours=$(for r in $(seq "$repeats"); do env $env_ours "$bench" "$scene" "$size" "$size" "$n" $arg | fps; done | median)
        ratio=$(awk -v a="$ours" -v b="$floor_fps" 'BEGIN {printf "%.2f", a / b}')
        printf '%-8s %-8s %-9s %-8s %12s %12s %7s\n' "$threads" "${size}x${size}" "$scene" "$shadows" "$ours" "$floor_fps" "$ratio"
      done
    done
  done
done
