#!/bin/sh
# End-to-end checks of the sdfcsg command line: exit codes, messages, atomic outputs.
# Usage: cli_test.sh SDFCSG_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0

check() { # check NAME EXPECTED_EXIT COMMAND...
    name=$1 expected=$2
    shift 2
    "$@" >out.txt 2>err.txt
    rc=$?
    if [ "$rc" -ne "$expected" ]; then
        echo "FAIL $name: exit $rc, expected $expected"; cat out.txt err.txt
        failures=$((failures + 1))
    else
        passed=$((passed + 1))
    fi
}
expect_text() { # expect_text NAME FILE TEXT: FILE holds TEXT as a whole line
    if ! grep -qxF -- "$3" "$2"; then
        echo "FAIL $1: '$3' not found in:"; cat "$2"
        failures=$((failures + 1))
    else
        passed=$((passed + 1))
    fi
}

for c in render validate glsl convert schema bench; do
    check "$c --help" 0 "$bin" "$c" --help
    grep -q "^Usage: sdfcsg $c" out.txt || { echo "FAIL $c --help text"; failures=$((failures + 1)); }
done
check "no command" 2 "$bin"
check "unknown command" 2 "$bin" frobnicate
expect_text "unknown command message" err.txt "sdfcsg: unknown command 'frobnicate'"

check "validate bundled" 0 "$bin" validate "$src"/assets/scenes/*.json
expect_text "validate ok line" out.txt "$src/assets/scenes/house.json: ok (34 nodes)"

printf '{"version": 1, "root": {"type": "sphere", "radius": -1}}' >bad.json
check "validate bad" 1 "$bin" validate bad.json
expect_text "validate bad message" err.txt "bad.json: root.radius: expected a positive number, got -1"
check "validate missing file" 3 "$bin" validate does-not-exist.json

check "render usage" 2 "$bin" render "$src/assets/scenes/house.json"
check "render bad mode" 2 "$bin" render "$src/assets/scenes/house.json" -o x.png --mode fancy
check "render bad scene" 1 "$bin" render bad.json -o bad.png
[ ! -e bad.png ] || { echo "FAIL render bad scene left an output"; failures=$((failures + 1)); }
check "render house" 0 "$bin" render "$src/assets/scenes/house.json" -o house.png --width 96 --height 64
[ "$(head -c 8 house.png | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] ||
    { echo "FAIL house.png is not a PNG"; failures=$((failures + 1)); }
check "render to a missing directory" 3 "$bin" render "$src/assets/scenes/house.json" -o no/such/dir.png --width 8 --height 8
ls | grep -q '\.tmp-' && { echo "FAIL a temporary file was left behind"; failures=$((failures + 1)); }

check "glsl" 0 "$bin" glsl "$src/assets/scenes/csg_part.json"
grep -q "float sceneDistance(vec3 p)" out.txt || { echo "FAIL glsl has no sceneDistance"; failures=$((failures + 1)); }
grep -q "hole x" out.txt || { echo "FAIL glsl does not name the nodes"; failures=$((failures + 1)); }

check "convert legacy" 0 "$bin" convert "$src/tests/data/legacy/csg.json" -o converted.json
check "converted validates" 0 "$bin" validate converted.json
check "convert round trip" 0 "$bin" convert converted.json -o again.json
cmp -s converted.json again.json || { echo "FAIL convert is not idempotent"; failures=$((failures + 1)); }

check "schema" 0 "$bin" schema -o schema.json
cmp -s schema.json "$src/assets/scene.schema.json" || { echo "FAIL schema differs from assets/scene.schema.json"; failures=$((failures + 1)); }

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
