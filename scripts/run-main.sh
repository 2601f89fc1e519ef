#!/usr/bin/env bash
# Quick-start command 1: install what is missing, build (Release) and run the main job: the whole
# multi-process stack (mft-sim, mft-estimator, mft-planner, mft-wbc on DDS, lockstep) playing the `demo`
# scenario through the supervisor, with a printed summary. Logs and summaries go to runs/; every topic is
# recorded to the MRPT rawlog runs/demo-<date>-<time>.rawlog (the summary's "recording" line; see
# docs/guide/recording.md for mft-replay and mft-export).
# Extra arguments go to the supervisor, e.g. --mode realtime, --json, --domain 5.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
exec python3 services/mft-supervisor run config/scenarios/demo.yaml --bin-dir build/release/bin \
  --record "runs/demo-$(date +%Y%m%d-%H%M%S).rawlog" "$@"
