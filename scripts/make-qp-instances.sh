#!/usr/bin/env bash
# Regenerates the QP instance set tests/data/qp (docs/reference/qp-instances.md): the WBC's own QPs, dumped by
# mft-closedloop --dump-qp from closed-loop runs (stand, step, walk, pushes, both controllers), a window of
# consecutive ticks per run. Deterministic: the closed loop runs on the simulator's clock and the same inputs give
# the same files, byte for byte.
# Usage: scripts/make-qp-instances.sh [OUT_DIR]   (default tests/data/qp; needs build/release/bin/mft-closedloop)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-tests/data/qp}
closedloop=${MFT_CLOSEDLOOP:-build/release/bin/mft-closedloop}
if [ ! -x "$closedloop" ]; then
  echo "make-qp-instances: $closedloop not found; build it first: bash scripts/build.sh release mft-closedloop" >&2
  exit 2
fi
mkdir -p "$out"
rm -f "$out"/*.txt

# run NAME FROM_S COUNT ARGS...: dump COUNT consecutive ticks from sim time FROM_S of one mft-closedloop run.
run() {
  local name=$1 from=$2 count=$3
  shift 3
  "$closedloop" "$@" --dump-qp "$out" --dump-name "$name" --dump-from "$from" --dump-count "$count" \
    --duration "$(python3 -c "print($from + $count / 1000 + 0.01)")" >/dev/null
  echo "$name: $count instances from t = $from s"
}

# Windows picked where the runs exercise the constraints (docs/reference/qp-instances.md lists what is active where).
run stand_mft 1.500 10 --stand --height 0.40                                    # double support, nothing active
run step_mft 0.990 20 --height 0.44                                              # first lift-off, MFT rows
run walk_mft 1.670 25 --speed 0.3                                                # a touchdown while walking
run push_mft 3.415 50 --height 0.42 --push 8 --push-at 3                         # friction, MFT rows, torque
run push_sa 3.340 45 --height 0.42 --push 12 --push-at 3 --controller sa         # passive rows, qdd box, f_z >= 0
echo "$(ls "$out"/*.txt | wc -l) files, $(du -sh "$out" | cut -f1) in $out"
