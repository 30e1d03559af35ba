#!/usr/bin/env bash
# Install what is missing, build, and run the whole test suite (GoogleTest through CTest).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
cd "$root/build"
ctest --output-on-failure -j2
