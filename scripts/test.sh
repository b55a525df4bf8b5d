#!/usr/bin/env bash
# Fresh-machine test run: installs what is missing, builds everything, runs all tests.
# Tests on the real recordings run when ../shared/data exists beside the checkout.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-debian.sh
scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)"
if [ "${CI:-}" = "true" ]; then
  scripts/fuzz.sh 20
fi
