#!/usr/bin/env bash
# Configures and builds evcorner in build/ (Release). Extra arguments go to make,
# e.g. a target name.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc)" -- "$@"
