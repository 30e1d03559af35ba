#!/usr/bin/env bash
# The main job: install what is missing, build, run the pulse study (paper Figs. 5-7) and print
# its metrics table. Figures and metrics land in studies/pulse/out/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
"$root/studies/pulse/run" "${1:-$root/studies/pulse/out}"
