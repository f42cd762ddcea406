#!/bin/sh
# Rewrites the checked-in files that are made from the node kind table, after a change to it
# (docs/vocabulary.md): the JSON Schema (assets/scene.schema.json), the field reference in
# docs/scene-format.md, and the recorded language-model request (tests/data/llm/
# first_request.json), whose prompt holds that reference. Run after a build (scripts/build.sh).
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
"$build/apps/sdfcsg" schema -o assets/scene.schema.json
"$build/apps/sdfcsg" schema --markdown >"$build/reference.md"
awk -v ref="$build/reference.md" '
    /^<!-- END scene-format-reference -->$/ { skip = 0 }
    !skip { print }
    /^<!-- BEGIN scene-format-reference -->$/ {
        print ""; while ((getline line < ref) > 0) print line; print ""; skip = 1
    }' docs/scene-format.md >"$build/scene-format.md"
mv "$build/scene-format.md" docs/scene-format.md
SDFCSG_UPDATE_GOLDEN=1 "$build/tests/test_generate" --gtest_filter='*RequestBodyGolden*' >/dev/null
