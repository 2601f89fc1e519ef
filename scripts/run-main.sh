#!/usr/bin/env bash
# Quick-start command 1: install what is missing, build (Release) and run the main job.
# The main job today is the offline MFT preferable-space tool (mft-space) on the default robot;
# it becomes the multi-process demo stack once the services land.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
mkdir -p out
exec build/release/bin/mft-space all --out out/mft-space "$@"
