#!/usr/bin/env bash
# Fuzz the case loader: build fuzz_case (clang, libFuzzer, ASan + UBSan) in build-fuzz/ and run it
# for SECONDS (default 60) on the seed corpus tests/fuzz/corpus (the studies' cases, coarsened) and
# the corpus grown by earlier runs (build-fuzz/corpus). SEED (default 1) fixes libFuzzer's random
# seed. Exit 0 when nothing was found; otherwise non-zero, with the input that failed in
# build-fuzz/findings/ (reproduce: cd to the repository root, build-fuzz/fuzz_case FILE).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
secs=${1:-60}
seed=${SEED:-1}
case "$secs" in ''|*[!0-9]*) echo "fuzz.sh: SECONDS must be a whole number, got '$secs'" >&2; exit 1;; esac
"$root/scripts/setup.sh"
b="$root/build-fuzz"
# (At -O1 under the sanitizers clang does not vectorize the loops marked `omp simd`, and deal.II's
# flags carry options of GCC's: neither is a finding, so neither is reported.)
CC=clang CXX=clang++ cmake -S "$root" -B "$b" -DSILENTMPM_FUZZ=ON -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g -Wno-pass-failed -Wno-unknown-warning-option -Wno-ignored-optimization-argument" >/dev/null
cmake --build "$b" -j2 --target fuzz_case
mkdir -p "$b/corpus" "$b/findings"
cd "$root"  # the seeds name their meshes from the repository root
export LSAN_OPTIONS="suppressions=$root/tests/lsan.supp"  # third-party leaks
export UBSAN_OPTIONS="print_stacktrace=1"
# Memory: one allocation of 2 GB or more is a finding (-malloc_limit_mb); the process as a whole
# may grow to 6 GB (-rss_limit_mb), because gmsh's initialise/finalise cycle (one in every
# session that reads a .geo or .msh) keeps memory that grows with the number of cycles, faster
# as they add up (2 000 bare cycles: 46 -> 98 MB resident): with two cycles a session, as the
# session had then, a run reached 2 GB after 7 minutes (480 000 inputs) and a 10-minute run
# peaked at 4.5 GB. Split longer campaigns into runs of about 10 minutes; the corpus carries over.
echo "fuzz.sh: fuzzing the case loader for $secs s (seed $seed)"
set +e
"$b/fuzz_case" -max_total_time="$secs" -seed="$seed" -rss_limit_mb=6144 -malloc_limit_mb=2048 -timeout=30 \
  -dict=tests/fuzz/case.dict -artifact_prefix="$b/findings/" -print_final_stats=1 \
  "$b/corpus" tests/fuzz/corpus >"$b/fuzz.log" 2>&1
rc=$?
set -e
grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb|^#[0-9]+ +DONE' "$b/fuzz.log" || true
if [ $rc -ne 0 ]; then
  grep -E 'ERROR|fuzz_case:|SUMMARY|Test unit written' "$b/fuzz.log" | head -20 >&2
  echo "fuzz.sh: FINDING (exit $rc); full log in $b/fuzz.log" >&2
  exit 1
fi
echo "fuzz.sh: no findings"
