#!/usr/bin/env bash
# Fresh-machine demo: installs what is missing, builds evcorner, and runs eFAST on the
# bundled Event-Camera-Dataset sample, printing the summary. Corners go to build/demo-corners.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-debian.sh
scripts/build.sh evcorner-cli
build/bin/evcorner detect data/ecd/shapes_translation/events.txt -o build/demo-corners.txt
echo "corner events written to build/demo-corners.txt; first lines:"
head -n 5 build/demo-corners.txt
