#!/usr/bin/env bash
# Pixel steps per second (physics + render + observation, one thread, 84x84) beside the
# MuJoCo + OSMesa reference in ../shared/peers/mujoco_osmesa, measured in the same run.
#
# usage: bench/envs_vs_mujoco.sh [build-dir] [repeats]
# Prints medians of `repeats` runs for LP_NUM_THREADS=0 and for llvmpipe's default threads, and
# the ratios issue 5 sets targets on:
#   CartPoleSwingup-v0, shadows off  /  MuJoCo -lite (no shadows)          target >= 4
#   CartPoleSwingup-v0, shadows on   /  MuJoCo with dm_control's visuals    target >= 40
#   ArmReach-v0 (7-DOF mesh arm)     /  CartPoleSwingup-v0 (shadows on)      target >= 0.25
# and then, with LP_NUM_THREADS=0, every registered env: pixel steps per second with its default
# kwargs (84x84, shadows on; GridWorld with obs_mode=pixels), beside its physics-only rate
# (obs_mode=state; GridWorld's index observation), and its pixel rate over the MuJoCo cart-pole's
# with dm_control's visuals (which has shadows too) in the same run: a scale, not a like-for-like.
# Installs libmujoco-dev with apt-get when it is missing (the peer needs it; pixelgym does not).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
repeats=${2:-3}
peer=../shared/peers/mujoco_osmesa
[ -f "$peer/bench.c" ] || { echo "envs_vs_mujoco: $peer/bench.c not found" >&2; exit 1; }
if ! dpkg-query -W -f='${Status}' libmujoco-dev 2>/dev/null | grep -q "install ok installed"; then
  echo "envs_vs_mujoco: installing libmujoco-dev for the reference program"
  sudo_cmd=(); [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libmujoco-dev >/dev/null ||
    { echo "envs_vs_mujoco: cannot install libmujoco-dev" >&2; exit 1; }
fi
mkdir -p "$build/peers"
cc -O2 -o "$build/peers/mujoco_bench" "$peer/bench.c" $(pkg-config --cflags osmesa) -lmujoco $(pkg-config --libs osmesa) -lm
pixelgym="$build/examples/pixelgym"
[ -x "$pixelgym" ] || { echo "envs_vs_mujoco: build $pixelgym first (make build)" >&2; exit 1; }

median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
rate() { sed -n 's/.*steps_per_s=\([0-9.]*\).*/\1/p' | tail -1; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }

for threads in 0 unset; do
  if [ "$threads" = 0 ]; then env_peer="LP_NUM_THREADS=0"; env_ours="LP_NUM_THREADS=0"
  else env_peer="-u LP_NUM_THREADS"; env_ours="LP_NUM_THREADS=$(nproc)"; fi
  run() { for r in $(seq "$repeats"); do env $env_ours "$pixelgym" bench "$@" | rate; done | median; }
  mj_full=$(for r in $(seq "$repeats"); do env $env_peer "$build/peers/mujoco_bench" "$peer/cartpole.xml" -n 400 -w 84 -h 84 2>/dev/null | rate; done | median)
  mj_lite=$(for r in $(seq "$repeats"); do env $env_peer "$build/peers/mujoco_bench" "$peer/cartpole.xml" -n 3000 -w 84 -h 84 -lite 2>/dev/null | rate; done | median)
  cart_off=$(run CartPoleSwingup-v0 --steps 3000 --set shadows=false)
  cart_on=$(run CartPoleSwingup-v0 --steps 3000)
  arm_on=$(run ArmReach-v0 --steps 1000)
  echo "LP_NUM_THREADS=$threads (medians of $repeats, steps/s at 84x84, one env, one thread)"
  printf '  %-40s %10s\n' "MuJoCo + OSMesa, dm_control visuals" "$mj_full" "MuJoCo + OSMesa, -lite" "$mj_lite" \
    "CartPoleSwingup-v0, shadows off" "$cart_off" "CartPoleSwingup-v0, shadows on" "$cart_on" "ArmReach-v0, shadows on" "$arm_on"
  echo "  cart-pole shadows off / MuJoCo lite = $(ratio "$cart_off" "$mj_lite")  (target >= 4)"
  echo "  cart-pole shadows on / MuJoCo full  = $(ratio "$cart_on" "$mj_full")  (target >= 40)"
  echo "  arm / cart-pole (shadows on)        = $(ratio "$arm_on" "$cart_on")  (target >= 0.25)"
done

echo "every env, LP_NUM_THREADS=0 (medians of $repeats, steps/s, one env, one thread)"
printf '  %-28s %10s %10s %14s\n' "id" "pixels" "no pixels" "pixels / MJ"
mj_full=$(for r in $(seq "$repeats"); do LP_NUM_THREADS=0 "$build/peers/mujoco_bench" "$peer/cartpole.xml" -n 400 -w 84 -h 84 2>/dev/null | rate; done | median)
for id in $("$pixelgym" list | awk '{print $1}'); do
  if [ "$id" = GridWorld-v0 ]; then pixels=(--set obs_mode=pixels); plain=();
  else pixels=(); plain=(--set obs_mode=state); fi
  with=$(for r in $(seq "$repeats"); do LP_NUM_THREADS=0 "$pixelgym" bench "$id" --steps 1500 "${pixels[@]}" | rate; done | median)
  without=$(for r in $(seq "$repeats"); do LP_NUM_THREADS=0 "$pixelgym" bench "$id" --steps 5000 "${plain[@]}" | rate; done | median)
  printf '  %-28s %10s %10s %14s\n' "$id" "$with" "$without" "$(ratio "$with" "$mj_full")"
done
echo "  (MJ: MuJoCo + OSMesa cart-pole with dm_control's visuals, measured again here: $mj_full)"
