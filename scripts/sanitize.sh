#!/usr/bin/env bash
# Build the command and the tests with AddressSanitizer and UndefinedBehaviorSanitizer
# (float-cast-overflow included; every report aborts) in build-asan/ and run the tests of the
# labels given (default: unit errors physics cross). The deal.II units of the FE far field are
# built without sanitizers (they take many times longer under ASan) and linked; everything else,
# the MPM library, the case loader, the run loop, output, geometry and the coupling, is checked.
# About 40 minutes on 2 cores; not part of scripts/test.sh.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
labels=${*:-unit errors physics cross}
"$root/scripts/setup.sh"
b="$root/build-asan"
CC=clang CXX=clang++ cmake -S "$root" -B "$b" -DSILENTMPM_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" >/dev/null
targets=(silentmpm)
for l in $labels; do targets+=("smpm_tests_$l"); done
cmake --build "$b" -j2 --target "${targets[@]}"
export LSAN_OPTIONS="suppressions=$root/tests/lsan.supp:fast_unwind_on_malloc=0"  # third-party leaks
export UBSAN_OPTIONS="print_stacktrace=1"
export ASAN_OPTIONS="detect_stack_use_after_return=1"
cd "$b"
ctest --output-on-failure -j2 -L "$(echo $labels | tr ' ' '|')"
