#!/usr/bin/env bash
# Quick-start command 2: install what is missing, build (Release) and run the whole test suite through CTest.
# Extra arguments go to ctest, e.g. scripts/run-tests.sh -L model
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
cd build/release
ctest --output-on-failure --timeout 900 "$@"
