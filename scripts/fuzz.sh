#!/bin/sh
# Builds the libFuzzer targets (tests/fuzz) with clang, AddressSanitizer and UBSan into
# build-fuzz, then runs each for SECONDS (default 60). Exit status 1 if any target found a crash,
# a leak, a timeout or a sanitizer report; the input that did it is under build-fuzz/artifacts.
#
#   sh scripts/fuzz.sh                     # every target, 60 s each (what CI runs)
#   sh scripts/fuzz.sh 3600 parse          # one target for an hour
#   FUZZ_ARGS=-runs=1000000 sh scripts/fuzz.sh 86400 parse   # stop after a million executions
#
# Each target's corpus grows in build-fuzz/corpus/TARGET and is reused by later runs; the seeds
# (tests/fuzz/corpus, the bundled scenes, tests/data/valid and legacy) are only read. Environment:
# CXX (default clang++-14), FUZZ_BUILD_DIR (default build-fuzz), FUZZ_ARGS (more libFuzzer flags).
set -eu
cd "$(dirname "$0")/.."
seconds=${1:-60}
[ $# -gt 0 ] && shift
build=${FUZZ_BUILD_DIR:-build-fuzz}

CXX=${CXX:-clang++-14} cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DSDFCSG_FUZZ=ON -DSDFCSG_BUILD_TESTS=OFF -DSDFCSG_BUILD_APPS=OFF >/dev/null
cmake --build "$build" -j2

targets="$*"
if [ -z "$targets" ]; then
    for exe in "$build"/tests/fuzz/fuzz_*; do
        targets="$targets ${exe##*/fuzz_}"
    done
fi

status=0
for target in $targets; do
    case $target in
        # Scenes that load only: this target checks what valid scenes compile to.
        glsl) seeds="assets/scenes tests/data/valid tests/data/legacy" ;;
        # HTTP answers of language models (first byte: API and status, see fuzz_llm.cpp).
        llm) seeds="tests/fuzz/llm_corpus" ;;
        # 3MF packages, and model parts' XML to pack into them (see fuzz_3mf.cpp).
        3mf) seeds="tests/fuzz/3mf_corpus" ;;
        *) seeds="tests/fuzz/corpus assets/scenes tests/data/valid tests/data/legacy" ;;
    esac
    case $target in
        3mf) dict="tests/fuzz/3mf.dict" ;;
        *) dict="$build/tests/fuzz/scene.dict" ;;
    esac
    mkdir -p "$build/corpus/$target" "$build/artifacts/$target"
    echo "fuzz_$target: $seconds s"
    # shellcheck disable=SC2086
    if ! "$build/tests/fuzz/fuzz_$target" "$build/corpus/$target" $seeds \
        -dict="$dict" -max_total_time="$seconds" -timeout=30 \
        -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix="$build/artifacts/$target/" \
        ${FUZZ_ARGS:-} 2>"$build/fuzz_$target.log"; then
        status=1
        tail -n 60 "$build/fuzz_$target.log"
    fi
    grep -E "^stat::number_of_executed_units|^stat::average_exec_per_sec|^fuzz_" \
        "$build/fuzz_$target.log" || true
done
exit $status
