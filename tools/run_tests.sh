#!/usr/bin/env bash
# The test command: installs dependencies, builds, runs the recipe fuzzer for a bounded
# time and the GoogleTest suite with ctest. Every test runs once: under AddressSanitizer and
# UndefinedBehaviorSanitizer (build-asan/, clang), less the few that measure learning or
# kill runs many times over (slow there, and no code path the others miss); those run in
# the Release build users run (build/), with the Python tools' tests.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
phase() { echo "run_tests: $1 ($((SECONDS - start)) s in)"; }
RELEASE_ONLY='^(Jaco\.PpoImprovesThePickReturn|PpoLearning\..*|Trpo\.Improves.*|Sac\.Improves.*|KillSoak\..*|TsneTool|PlotTool)$'
bash tools/install_deps.sh
phase "dependencies present"
bash tools/build.sh
phase "Release build done"
(cd build && ctest --output-on-failure -j 2 --timeout 600 -R "$RELEASE_ONLY")
phase "Release-only tests passed"
# The recipe fuzzer (libFuzzer with ASan and UBSan, tests/fuzz/), a bounded run from the
# seed corpus: any crash, sanitizer report or exception other than segue::Error fails.
cmake -S tests/fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build build-fuzz
corpus=$(mktemp -d)
cp tests/fuzz/corpus/* "$corpus"/
# On a finding, the report and the input (build-fuzz/crash-*, leak-*, ...) are printed.
if build-fuzz/fuzz_recipe -max_total_time="${SEGUE_FUZZ_SECONDS:-60}" -timeout=10 -rss_limit_mb=2048 \
  -print_final_stats=1 -artifact_prefix=build-fuzz/ "$corpus" >build-fuzz/fuzz.log 2>&1; then
  tail -3 build-fuzz/fuzz.log
else
  status=$?
  grep -v -E '^#[0-9]+ |^\s+NEW_FUNC' build-fuzz/fuzz.log | tail -60
  echo "the recipe fuzzer failed (exit $status); its input, base64:"
  base64 build-fuzz/{crash,leak,timeout,oom,slow-unit}-* 2>/dev/null || true
  exit "$status"
fi
rm -rf "$corpus"
phase "recipe fuzzer done"
# LeakSanitizer is off: LibTorch and MuJoCo keep process-lifetime allocations. clang parses
# LibTorch's headers about three times faster than g++, which is most of this build.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release -DSEGUE_SANITIZE=ON -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build build-asan -j "$(nproc)"
phase "sanitizer build done"
(cd build-asan && ASAN_OPTIONS=detect_leaks=0 ctest --output-on-failure -j 2 --timeout 900 -E "$RELEASE_ONLY")
phase "sanitizer suite passed"
