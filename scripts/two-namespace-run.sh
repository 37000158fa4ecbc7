#!/usr/bin/env bash
# A data-parallel run across two "machines" on one host: two network namespaces joined by a veth
# pair (10.77.0.1 and 10.77.0.2), each running one rank of `pixelgym train` started as on two
# machines (MASTER_ADDR=10.77.0.1, WORLD_SIZE=2, RANK=0 or 1; no --nproc). Needs root (ip netns).
#
# usage: sudo scripts/two-namespace-run.sh [build-dir] [out-folder] [extra train options ...]
#   default: build, /tmp/pixelgym-two-hosts; the extra options go after the run's own
# Prints each rank's log, the TCP connections between the two addresses while training, and the
# run's summary.json; removes the namespaces at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=${2:-/tmp/pixelgym-two-hosts}
shift $(($# < 2 ? $# : 2))
pixelgym="$(realpath "$build/examples/pixelgym")"
[ -x "$pixelgym" ] || { echo "two-namespace-run: build $pixelgym first (make build)" >&2; exit 1; }
rm -rf "$out"
mkdir -p "$out"
cleanup() { ip netns del pg-host0 2>/dev/null || true; ip netns del pg-host1 2>/dev/null || true; }
trap cleanup EXIT
cleanup
ip netns add pg-host0
ip netns add pg-host1
ip link add pg-veth0 type veth peer name pg-veth1
ip link set pg-veth0 netns pg-host0
ip link set pg-veth1 netns pg-host1
ip -n pg-host0 addr add 10.77.0.1/24 dev pg-veth0
ip -n pg-host1 addr add 10.77.0.2/24 dev pg-veth1
for n in 0 1; do
  ip -n pg-host$n link set lo up
  ip -n pg-host$n link set pg-veth$n up
done
train=(train CartPoleBalance-v1 --set obs_mode=pixels --set width=64 --set height=64 --set msaa=4
  --set action_repeat=8 --wrap grayscale --wrap frame_stack=3
  --config examples/trainer/ppo/configs/action_repeat_8.json --num-envs 4 --torch-threads 1
  --steps 8192 --eval-episodes 2 --quiet "$@")
common=(MASTER_ADDR=10.77.0.1 MASTER_PORT=29500 WORLD_SIZE=2)
ip netns exec pg-host0 env "${common[@]}" RANK=0 LOCAL_RANK=0 \
  "$pixelgym" "${train[@]}" --out "$out/run" > "$out/rank0.log" 2>&1 &
rank0=$!
# Rank 1's --out is never written (rank 0 writes the run folder): checked below.
ip netns exec pg-host1 env "${common[@]}" RANK=1 LOCAL_RANK=0 \
  "$pixelgym" "${train[@]}" --out "$out/rank1-out" > "$out/rank1.log" 2>&1 &
rank1=$!
sleep 8
echo "== TCP connections of rank 1's namespace (10.77.0.2) while training"
ip netns exec pg-host1 ss -tn | grep -E "10\.77\.0\." | head -8 || true
status=0
wait $rank0 || status=$?
wait $rank1 || status=$?
echo "== rank 0's log"; cat "$out/rank0.log"
echo "== rank 1's log"; cat "$out/rank1.log"
echo "== rank 1's --out folder exists: $([ -e "$out/rank1-out" ] && echo yes || echo no)"
echo "== summary.json"; cat "$out/run/summary.json"
exit $status
