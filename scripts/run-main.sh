#!/usr/bin/env bash
# Quick-start command 1: install what is missing, build (Release) and run the main job: the whole
# multi-process stack (mft-sim, mft-estimator, mft-planner, mft-wbc on DDS, lockstep) playing the `demo`
# scenario through the supervisor, with a printed summary. Logs and summaries go to runs/.
# Extra arguments go to the supervisor, e.g. --mode realtime, --json, --domain 5.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
exec python3 services/mft-supervisor run config/scenarios/demo.yaml --bin-dir build/release/bin "$@"
