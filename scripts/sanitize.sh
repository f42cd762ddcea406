#!/bin/sh
# Builds the library, the tools and the tests with AddressSanitizer and UndefinedBehaviorSanitizer
# into build-asan and runs the whole suite there, GPU tests included (docs/robustness.md says
# which leak suppressions lavapipe needs and why). Extra arguments go to ctest.
set -eu
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DSDFCSG_SANITIZE=address,undefined ${SDFCSG_CMAKE_ARGS:-} >/dev/null
cmake --build build-asan
ctest --test-dir build-asan --output-on-failure -j2 "$@"
