#!/bin/sh
# Checks that every tracked C++ file (*.cpp, *.h) is formatted as .clang-format says, with the
# clang-format of Debian 12 (version 14; another version may format a few lines differently).
# Names each file that is not, with the lines that differ, and fails; `clang-format -i
# FILE` formats one. Environment: CLANG_FORMAT (default clang-format).
set -eu
cd "$(dirname "$0")/.."
git ls-files -z '*.cpp' '*.h' | xargs -0 "${CLANG_FORMAT:-clang-format}" --dry-run --Werror
