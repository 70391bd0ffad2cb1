#!/usr/bin/env bash
# The checked build CI runs after the README's test command: clang-14 with AddressSanitizer,
# UndefinedBehaviorSanitizer and libFuzzer's coverage in build-asan/, the whole test suite
# under it, then every fuzz target for FUZZ_SECONDS (default 60) from its seed corpus.
# Installs clang-14 and its runtimes (Debian's clang-14, libclang-rt-14-dev) if missing.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
start=$(date +%s)

bash scripts/install_missing.sh clang-14 libclang-rt-14-dev

# Line tables only: sanitizer reports name file and line, and the build stays fast.
CXX=clang++-14 cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS=-gline-tables-only \
  "-DWAVETRACE_SANITIZE=address;undefined" -DWAVETRACE_FUZZ=ON >/dev/null
cmake --build build-asan -j"$(nproc)"
built=$(date +%s)
ctest --test-dir build-asan --output-on-failure -j"$(nproc)"
tested=$(date +%s)
fuzz/run_fuzzers.sh build-asan "${FUZZ_SECONDS:-60}s"
echo "sanitize: build $((built - start)) s, tests $((tested - built)) s, fuzzing $(($(date +%s) - tested)) s"
