#!/usr/bin/env bash
# Install what is missing, build, and run the whole test suite (GoogleTest through CTest), then
# fuzz the case loader for 60 s (scripts/fuzz.sh: a clang build with ASan and UBSan).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
(cd "$root/build" && ctest --output-on-failure -j2)
"$root/scripts/fuzz.sh" 60
