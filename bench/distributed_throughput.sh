#!/usr/bin/env bash
# Data-parallel training throughput on one machine: `pixelgym train` on the demo's settings
# (CartPoleBalance-v1 from 64x64 anti-aliased grey frames, 3 stacked, action_repeat 8, the
# demo's PPO config: 8 envs x 128 steps per update in all) run as
#   1proc_1thread   one process, 1 torch thread, 8 envs
#   1proc_2threads  one process, 2 torch threads, 8 envs
#   2proc_1thread   --nproc 2, 1 torch thread each, 4 envs each (the same 8 envs per update)
# in interleaved rounds, and from the progress.csv of each: env steps per second with the
# updates included, the update's time (update_s), and for the 2-process runs the time of the
# update spent in the all-reduces (allreduce_s) and its share of the update.
#
# usage: bench/distributed_throughput.sh [build-dir] [env-steps] [rounds]
#   env-steps: each run's length (default 16384: 16 updates); rounds: default 3
# Prints one line per run, then the medians over rounds of each run's median over its updates
# after the first (which includes start-up).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
steps=${2:-16384}
rounds=${3:-3}
pixelgym="$build/examples/pixelgym"
[ -x "$pixelgym" ] || { echo "distributed_throughput: build $pixelgym first (make build)" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
demo=(train CartPoleBalance-v1 --set obs_mode=pixels --set width=64 --set height=64
  --set msaa=4 --set action_repeat=8 --wrap grayscale --wrap frame_stack=3
  --config examples/trainer/ppo/configs/action_repeat_8.json --steps "$steps" --eval-episodes 1
  --eval-every 0 --threads 1 --quiet)
for round in $(seq 1 "$rounds"); do
  "$pixelgym" "${demo[@]}" --num-envs 8 --torch-threads 1 --out "$out/1proc_1thread_$round" > /dev/null
  "$pixelgym" "${demo[@]}" --num-envs 8 --torch-threads 2 --out "$out/1proc_2threads_$round" > /dev/null
  "$pixelgym" "${demo[@]}" --num-envs 4 --torch-threads 1 --nproc 2 --out "$out/2proc_1thread_$round" > /dev/null
done
/usr/bin/python3 - "$out" "$rounds" <<'EOF'
import csv, statistics, sys
out, rounds = sys.argv[1], int(sys.argv[2])
def medians(run):
    rows = list(csv.DictReader(open(f"{out}/{run}/progress.csv")))[1:]
    if not rows:
        sys.exit("distributed_throughput: too few updates; give more env steps")
    get = lambda key: statistics.median(float(row[key]) for row in rows)
    return get("fps"), get("update_s"), get("allreduce_s"), len(rows)
results = {}
for name in ("1proc_1thread", "1proc_2threads", "2proc_1thread"):
    for r in range(1, rounds + 1):
        fps, update_s, allreduce_s, n = medians(f"{name}_{r}")
        results.setdefault(name, []).append((fps, update_s, allreduce_s))
        print(f"{name} round {r}: updates={n} env_steps_per_s={fps:.0f} update_s={update_s:.3f} "
              f"allreduce_s={allreduce_s:.4f}")
base = statistics.median(x[0] for x in results["1proc_1thread"])
for name, values in results.items():
    fps = statistics.median(x[0] for x in values)
    update_s = statistics.median(x[1] for x in values)
    allreduce_s = statistics.median(x[2] for x in values)
    line = f"{name}: env_steps_per_s={fps:.0f} ({fps / base:.2f}x 1proc_1thread) update_s={update_s:.3f}"
    if name.startswith("2proc"):
        line += f" allreduce_s={allreduce_s:.4f} ({100 * allreduce_s / update_s:.1f}% of the update)"
    print(line)
EOF
