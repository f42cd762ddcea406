#!/bin/sh
# Configures and builds sdfcsg into ./build (Release with assertions checked at the API boundary).
set -eu
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release ${SDFCSG_CMAKE_ARGS:-}
cmake --build build
