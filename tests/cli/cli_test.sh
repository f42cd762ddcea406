#!/bin/sh
# End-to-end checks of the sdfcsg command line: exit codes, messages, atomic outputs.
# Usage: cli_test.sh SDFCSG_BINARY SOURCE_DIR WORK_DIR CASE, where CASE names one of the case_
# functions below; it runs in WORK_DIR/CASE, so cases may run in parallel. tests/CMakeLists.txt
# registers each case as a test of its own, cli.CASE. Exits 77 (skipped) when a case cannot run.
set -u
bin=$1 src=$2 work=$3 test_case=$4
failures=0 passed=0
# The stop deadline: a second, longer under the sanitizers (cmake/Sanitizers.cmake says why).
deadline=$((1000 * ${SDFCSG_TEST_DEADLINE_SCALE:-1}))
mesh_a="$src/assets/scenes/mesh_a.json"
box=-1.1,-1.1,-1.1,1.1,1.1,1.1

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

case_help() {
    for c in render mesh validate glsl convert schema bench; do
        check "$c --help" 0 "$bin" "$c" --help
        grep -q "^Usage: sdfcsg $c" out.txt || { echo "FAIL $c --help text"; failures=$((failures + 1)); }
    done
    check "no command" 2 "$bin"
    check "unknown command" 2 "$bin" frobnicate
    expect_text "unknown command message" err.txt "sdfcsg: unknown command 'frobnicate'"
}

case_validate() {
    check "validate bundled" 0 "$bin" validate "$src"/assets/scenes/*.json
    expect_text "validate ok line" out.txt "$src/assets/scenes/house.json: ok (34 nodes)"
    printf '{"version": 1, "root": {"type": "sphere", "radius": 1}}' >one.json
    check "validate one node" 0 "$bin" validate one.json
    expect_text "validate counts in the singular" out.txt "one.json: ok (1 node)"
    # A valid scene whose offset acts on a field that is not a distance, too thin against its
    # child to bake: a note, exit 0.
    printf '{"version": 1, "root": {"type": "offset", "distance": 0.3, "children": [%s]}}' \
        '{"type": "twist", "angle": 90, "children": [{"type": "box", "size": [1, 2, 1]}]}' >twisted.json
    check "validate notes" 0 "$bin" validate twisted.json
    expect_text "validate note" out.txt "twisted.json: root: note: offset over a field that is not a distance (twist at root.children[0] divides its field by up to 2.65): the surface lies about 0.3 from the child's (divided by the field's gradient, to first order; \"accuracy\": \"exact\" bakes the child's distance; 0.3 to 0.794 without)"
    expect_text "validate shading note" out.txt "twisted.json: root: note: ambient occlusion and soft shadows over a field that is not a distance (twist at root.children[0] divides its field by up to 2.65): the shading can be darker where its values lie below the distance (down to 1/2.65 of it); --no-ao and --no-shadows leave them out"

    # A mesh whose file has a hole (a box less one triangle) and a flipped triangle: validate,
    # render and mesh each note it once.
    printf 'v %s\n' "-1 -1 -1" "1 -1 -1" "-1 1 -1" "1 1 -1" "-1 -1 1" "1 -1 1" "-1 1 1" "1 1 1" >holed.obj
    printf 'f %s\n' "1 7 3" "2 8 4" "2 8 6" "1 2 6" "1 6 5" "3 7 8" "3 8 4" "1 3 4" "1 4 2" "5 6 8" "5 8 7" >>holed.obj
    printf '{"version": 1, "root": {"type": "mesh", "file": "holed.obj", "resolution": 16}}' >holed.json
    holed_note='holed.json: root: note: mesh "holed.obj" is not closed and consistently oriented: 3 open edges, 3 edges between triangles wound opposite ways (flipped triangles); its inside comes from the generalised winding number, which fills holes and outvotes flipped triangles'
    check "validate holed mesh" 0 "$bin" validate holed.json
    expect_text "validate holed mesh note" out.txt "$holed_note"
    check "render holed mesh" 0 "$bin" render holed.json -o holed.png --width 32 --height 24
    expect_text "render holed mesh note" err.txt "$holed_note"
    check "mesh holed mesh" 0 "$bin" mesh holed.json -o holed.ply --resolution 16
    expect_text "mesh holed mesh note" err.txt "$holed_note"
    [ "$(grep -c 'note:' err.txt)" -eq 1 ] || { echo "FAIL mesh holed mesh: one note"; cat err.txt; failures=$((failures + 1)); }

    printf '{"version": 1, "root": {"type": "sphere", "radius": -1}}' >bad.json
    check "validate bad" 1 "$bin" validate bad.json
    expect_text "validate bad message" err.txt "bad.json: root.radius: expected a positive number, got -1"
    check "validate missing file" 3 "$bin" validate does-not-exist.json
}

case_render() {
    printf '{"version": 1, "root": {"type": "sphere", "radius": -1}}' >bad.json
    check "render usage" 2 "$bin" render "$src/assets/scenes/house.json"
    check "render bad mode" 2 "$bin" render "$src/assets/scenes/house.json" -o x.png --mode fancy
    check "render bad scene" 1 "$bin" render bad.json -o bad.png
    [ ! -e bad.png ] || { echo "FAIL render bad scene left an output"; failures=$((failures + 1)); }
    check "render house" 0 "$bin" render "$src/assets/scenes/house.json" -o house.png --width 96 --height 64
    [ "$(head -c 8 house.png | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] ||
        { echo "FAIL house.png is not a PNG"; failures=$((failures + 1)); }
    check "render to a missing directory" 3 "$bin" render "$src/assets/scenes/house.json" -o no/such/dir.png --width 8 --height 8
    ls | grep -q '\.tmp-' && { echo "FAIL a temporary file was left behind"; failures=$((failures + 1)); }
}

# Meshes: every format, with counts that agree with --stats; exit codes; no temporaries.
case_mesh() {
    # glTF would cut the mesh along mesh_a's colour borders (below), the others do not.
    for f in ply obj stl glb; do
        check "mesh $f" 0 "$bin" mesh "$mesh_a" -o "part.$f" --resolution 24 --bounds $box --stats \
            --color-regions off
        expect_text "mesh $f closed" out.txt "surface:   inside the bounds (the mesh is closed)"
        grep '^mesh:' out.txt >"counts.$f.txt"
    done
    for f in obj stl glb; do
        cmp -s counts.ply.txt "counts.$f.txt" || { echo "FAIL mesh counts differ between ply and $f"; failures=$((failures + 1)); }
    done
    vertices=$(sed 's/^mesh: *\([0-9]*\) vertices.*/\1/' counts.ply.txt)
    triangles=$(sed 's/.*, \([0-9]*\) triangles$/\1/' counts.ply.txt)
    [ "${triangles:-0}" -gt 100 ] || { echo "FAIL mesh --stats reports no triangles"; failures=$((failures + 1)); }
    [ "$(head -n 1 part.ply)" = "ply" ] && grep -aqx "element vertex $vertices" part.ply &&
        grep -aqx "element face $triangles" part.ply ||
        { echo "FAIL part.ply header does not match the stats"; failures=$((failures + 1)); }
    [ "$(grep -c '^v ' part.obj)" -eq "$vertices" ] && [ "$(grep -c '^vn ' part.obj)" -eq "$vertices" ] &&
        [ "$(grep -c '^f ' part.obj)" -eq "$triangles" ] ||
        { echo "FAIL part.obj counts do not match the stats"; failures=$((failures + 1)); }
    [ "$(wc -c < part.stl)" -eq $((84 + 50 * triangles)) ] ||
        { echo "FAIL part.stl size does not match the stats"; failures=$((failures + 1)); }
    [ "$(head -c 4 part.glb)" = "glTF" ] && [ "$(wc -c < part.glb)" -eq "$(od -An -tu4 -j8 -N4 part.glb | tr -d ' ')" ] ||
        { echo "FAIL part.glb header"; failures=$((failures + 1)); }
    check "mesh cut by the bounds" 0 "$bin" mesh "$mesh_a" -o cut.stl --resolution 16 --bounds 0,0,0,1,1,1 --stats
    expect_text "mesh cut stats" out.txt "surface:   cut by the bounds (the mesh is open there)"
    check "mesh nothing in the bounds" 0 "$bin" mesh "$mesh_a" -o empty.glb --resolution 8 --bounds 5,5,5,6,6,6
    [ "$(head -c 4 empty.glb)" = "glTF" ] || { echo "FAIL empty.glb is not a GLB"; failures=$((failures + 1)); }
    check "mesh voxel size" 0 "$bin" mesh "$mesh_a" -o voxel.ply --voxel-size 0.1
    check "mesh usage" 2 "$bin" mesh "$mesh_a"
    check "mesh bad extension" 2 "$bin" mesh "$mesh_a" -o part.txt
    expect_text "mesh bad extension message" err.txt "sdfcsg mesh: the output must end in .ply, .obj, .stl, .glb or .3mf (or give --format), got 'part.txt'"
    # 3MF, read back by Python's own ZIP and XML readers against the PLY of the same mesh.
    # One scene unit is a centimetre unless --unit says otherwise.
    check "mesh 3mf" 0 "$bin" mesh "$mesh_a" -o part.3mf --resolution 24 --bounds $box
    check "mesh 3mf in mm" 0 "$bin" mesh "$mesh_a" -o part-mm.3mf --resolution 24 --bounds $box --unit mm
    # The 3MF is cut along its colour borders (--color-regions is on for it), the PLY only when
    # asked; without the cut the 3MF carries the PLY's vertex colours.
    check "mesh ply with colour regions" 0 "$bin" mesh "$mesh_a" -o regions.ply --resolution 24 \
        --bounds $box --color-regions on --stats
    regions=$(sed -n 's/^mesh: *\([0-9]*\) vertices, \([0-9]*\) triangles$/\1 vertices, \2 triangles/p' out.txt)
    [ "$regions" != "$vertices vertices, $triangles triangles" ] ||
        { echo "FAIL --color-regions on cut nothing: $regions"; failures=$((failures + 1)); }
    check "mesh 3mf without colour regions" 0 "$bin" mesh "$mesh_a" -o vertex.3mf --resolution 24 \
        --bounds $box --color-regions off
    check "mesh bad colour regions" 2 "$bin" mesh "$mesh_a" -o bad.3mf --color-regions yes
    expect_text "mesh bad colour regions message" err.txt "sdfcsg mesh: --color-regions expects on or off, got 'yes'"
    if command -v python3 >/dev/null 2>&1; then
        python3 "$src/tests/cli/read_3mf.py" part.3mf regions.ply centimeter >out.txt 2>&1 &&
            grep -q "^3mf: $regions, 2 colours per triangle" out.txt ||
            { echo "FAIL part.3mf:"; cat out.txt; failures=$((failures + 1)); }
        python3 "$src/tests/cli/read_3mf.py" part-mm.3mf regions.ply millimeter >out.txt 2>&1 ||
            { echo "FAIL part-mm.3mf:"; cat out.txt; failures=$((failures + 1)); }
        python3 "$src/tests/cli/read_3mf.py" vertex.3mf part.ply centimeter >out.txt 2>&1 &&
            grep -q "^3mf: $vertices vertices, $triangles triangles, 2 colours per corner" out.txt ||
            { echo "FAIL vertex.3mf:"; cat out.txt; failures=$((failures + 1)); }
        # A scene of one colour: its vertices' colours, as a colour group.
        "$bin" mesh "$src/assets/scenes/chess_pawn.json" -o pawn.ply --resolution 24 >/dev/null 2>&1 &&
            "$bin" mesh "$src/assets/scenes/chess_pawn.json" -o pawn.3mf --resolution 24 >/dev/null 2>&1 &&
            python3 "$src/tests/cli/read_3mf.py" pawn.3mf pawn.ply centimeter >out.txt 2>&1 &&
            grep -q "^3mf: .* 1 colours per corner" out.txt ||
            { echo "FAIL pawn.3mf:"; cat out.txt; failures=$((failures + 1)); }
    else
        echo "skipped reading part.3mf back: python3 not found"
    fi
    check "mesh unit for another format" 2 "$bin" mesh "$mesh_a" -o bad.ply --unit cm
    expect_text "mesh unit for another format message" err.txt "sdfcsg mesh: --unit applies to .3mf output only"
    check "mesh bad unit" 2 "$bin" mesh "$mesh_a" -o bad.3mf --unit furlong
    expect_text "mesh bad unit message" err.txt "sdfcsg mesh: --unit expects mm, cm, m or inch"
}

# Simplification: far fewer triangles, still closed, the file as --stats says; bad values.
case_mesh_simplify() {
    check "mesh simplify" 0 "$bin" mesh "$mesh_a" -o simple.ply --resolution 48 --bounds $box \
        --simplify 0.005 --stats
    expect_text "mesh simplify closed" out.txt "surface:   inside the bounds (the mesh is closed)"
    before=$(sed -n 's/^simplify: *\([0-9]*\) -> [0-9]* triangles.*/\1/p' out.txt)
    after=$(sed -n 's/^simplify: *[0-9]* -> \([0-9]*\) triangles.*/\1/p' out.txt)
    [ "${after:-0}" -gt 100 ] && [ $((${after:-0} * 3)) -lt "${before:-0}" ] &&
        grep -aqx "element face $after" simple.ply ||
        { echo "FAIL mesh --simplify: $before -> $after triangles"; failures=$((failures + 1)); }
    check "mesh target triangles" 0 "$bin" mesh "$mesh_a" -o target.obj --resolution 48 --bounds $box \
        --target-triangles 3000 --stats
    after=$(sed -n 's/^simplify: *[0-9]* -> \([0-9]*\) triangles.*/\1/p' out.txt)
    [ "${after:-0}" -gt 2000 ] && [ "${after:-0}" -le 3000 ] &&
        [ "$(grep -c '^f ' target.obj)" -eq "$after" ] ||
        { echo "FAIL mesh --target-triangles 3000: $after triangles"; failures=$((failures + 1)); }
    for v in x 0 -1 nan inf; do
        check "mesh bad simplify $v" 2 "$bin" mesh "$mesh_a" -o bad.ply --simplify "$v"
        expect_text "mesh bad simplify $v message" err.txt "sdfcsg mesh: --simplify expects a distance greater than 0, got '$v'"
    done
    for v in x 0 -5 2.5 99999999999999999999999; do
        check "mesh bad target triangles $v" 2 "$bin" mesh "$mesh_a" -o bad.ply --target-triangles "$v"
        expect_text "mesh bad target triangles $v message" err.txt "sdfcsg mesh: --target-triangles expects a positive integer, got '$v'"
    done
    mkdir -p benchscenes && cp "$mesh_a" benchscenes/
    check "bench mesh simplify" 0 "$bin" bench --mesh --scenes benchscenes --resolutions 24 --runs 1 \
        --simplify 0.1 --error
    grep -q '^scene .* triangles  *before .* simplify .* max err' out.txt ||
        { echo "FAIL bench --mesh --simplify columns:"; cat out.txt; failures=$((failures + 1)); }
    check "bench bad simplify" 2 "$bin" bench --mesh --simplify 0
    # An invalid scene exits as render and mesh do (1), not as a Vulkan failure.
    mkdir -p badbench && printf '{"version": 1, "root": {"type": "sphere", "radius": -1}}' >badbench/bad.json
    check "bench invalid scene" 1 "$bin" bench --scenes badbench --frames 1
    check "bench mesh invalid scene" 1 "$bin" bench --mesh --scenes badbench --resolutions 8 --runs 1
}

case_mesh_errors() {
    printf '{"version": 1, "root": {"type": "sphere", "radius": -1}}' >bad.json
    check "mesh bad bounds" 2 "$bin" mesh "$mesh_a" -o bad.ply --bounds 1,1,1,0,0,0
    check "mesh short bounds" 2 "$bin" mesh "$mesh_a" -o bad.ply --bounds 0,0,0,1,1
    check "mesh resolution and voxel size" 2 "$bin" mesh "$mesh_a" -o bad.ply --resolution 8 --voxel-size 0.1
    check "mesh bad resolution" 2 "$bin" mesh "$mesh_a" -o bad.ply --resolution 0
    check "mesh missing scene" 3 "$bin" mesh does-not-exist.json -o bad.ply
    check "mesh bad scene" 1 "$bin" mesh bad.json -o bad.ply
    check "mesh too large for memory" 1 "$bin" mesh "$mesh_a" -o bad.ply --resolution 100000
    check "mesh to a missing directory" 3 "$bin" mesh "$mesh_a" -o no/such/dir.ply --resolution 8
    [ ! -e bad.ply ] || { echo "FAIL a failed mesh left an output"; failures=$((failures + 1)); }
    ls | grep -q '\.tmp-' && { echo "FAIL mesh left a temporary file behind"; failures=$((failures + 1)); }
}

case_glsl() {
    check "glsl" 0 "$bin" glsl "$src/assets/scenes/csg_part.json"
    grep -q "float sceneDistance(vec3 p)" out.txt || { echo "FAIL glsl has no sceneDistance"; failures=$((failures + 1)); }
    grep -q "hole x" out.txt || { echo "FAIL glsl does not name the nodes"; failures=$((failures + 1)); }
    grep -q "Needs(" out.txt || { echo "FAIL glsl has no bounds tests"; failures=$((failures + 1)); }
    check "glsl without bounds tests" 0 "$bin" glsl "$src/assets/scenes/csg_part.json" --no-bounds-tests
    grep -q "Needs(" out.txt && { echo "FAIL glsl --no-bounds-tests has bounds tests"; failures=$((failures + 1)); }
    grep -q "hole x" out.txt || { echo "FAIL glsl --no-bounds-tests does not name the nodes"; failures=$((failures + 1)); }
}

case_convert() {
    check "convert legacy" 0 "$bin" convert "$src/tests/data/legacy/csg.json" -o converted.json
    check "converted validates" 0 "$bin" validate converted.json
    check "convert round trip" 0 "$bin" convert converted.json -o again.json
    cmp -s converted.json again.json || { echo "FAIL convert is not idempotent"; failures=$((failures + 1)); }
    # To .py, a program of the Python module (python/tests/test_program.py runs them).
    check "convert to Python" 0 "$bin" convert converted.json -o converted.py
    expect_text "converted program saves beside it" converted.py '    s.save(scene, sys.argv[1] if len(sys.argv) > 1 else "converted.json")'
}

case_schema() {
    check "schema" 0 "$bin" schema -o schema.json
    cmp -s schema.json "$src/assets/scene.schema.json" || { echo "FAIL schema differs from assets/scene.schema.json"; failures=$((failures + 1)); }
}

# Scenes from a language model, without a network: the prompt, the request, and a recorded
# conversation (a scene that loads after one repair round) replayed.
case_generate() {
    for c in generate edit eval-prompts; do
        check "$c --help" 0 "$bin" "$c" --help
        grep -q "^Usage: sdfcsg $c" out.txt || { echo "FAIL $c --help text"; failures=$((failures + 1)); }
    done
    recording="$src/tests/data/llm/snowman.recording.json"
    export no_proxy=127.0.0.1,localhost
    llm="--base-url http://127.0.0.1:9/v1 --model test-model"
    check "generate --print-prompt" 0 "$bin" generate "a red sphere" --print-prompt
    expect_text "generate prompt request" out.txt "Request: a red sphere"
    check "generate --dry-run" 0 env SDFCSG_LLM_API_KEY=sk-cli-secret "$bin" generate "a red sphere" $llm --dry-run
    expect_text "generate --dry-run url" out.txt "POST http://127.0.0.1:9/v1/chat/completions"
    grep -q "sk-cli-secret" out.txt err.txt && { echo "FAIL --dry-run printed the API key"; failures=$((failures + 1)); }
    check "generate usage" 2 "$bin" generate -o x.json
    check "generate record and replay" 2 "$bin" generate "x" -o x.json --record a --replay b
    check "generate bad base URL" 2 "$bin" generate "x" -o x.json --base-url localhost:9 --model m
    check "generate without a key" 2 env -u SDFCSG_LLM_API_KEY -u OPENAI_API_KEY -u SDFCSG_LLM_BASE_URL \
        -u OPENAI_BASE_URL https_proxy=http://127.0.0.1:9 "$bin" generate "x" -o x.json
    expect_text "generate without a key message" err.txt "<llm>: no API key for api.openai.com: set SDFCSG_LLM_API_KEY or OPENAI_API_KEY, or point SDFCSG_LLM_BASE_URL (or --base-url) at a server that needs no key"
    check "generate with a key in the base URL" 5 "$bin" generate "x" -o x.json --model m --timeout 5 \
        --base-url "http://me:url-secret-1234@127.0.0.1:9/v1?key=query-secret-5678"
    grep -q "secret" out.txt err.txt && { echo "FAIL a key in the base URL was printed"; cat err.txt; failures=$((failures + 1)); }
    grep -q '^http://\[redacted\]@127.0.0.1:9/v1/chat/completions?key=\[redacted\]: ' err.txt ||
        { echo "FAIL the redacted base URL"; cat err.txt; failures=$((failures + 1)); }
    check "generate unreachable" 5 "$bin" generate "x" -o x.json $llm --timeout 5
    [ ! -e x.json ] || { echo "FAIL a failed generate left an output"; failures=$((failures + 1)); }
    check "generate replay" 0 "$bin" generate "A snowman" -o snow.json $llm --replay "$recording" --render snow.png
    grep -q "^snow.json: 8 nodes, valid after 1 repair round (json_schema, 2 requests, 8000 + 600 tokens" err.txt ||
        { echo "FAIL generate summary"; cat err.txt; failures=$((failures + 1)); }
    check "generated scene validates" 0 "$bin" validate snow.json
    [ "$(head -c 8 snow.png | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] ||
        { echo "FAIL snow.png is not a PNG"; failures=$((failures + 1)); }
    check "generate replay without repairs" 1 "$bin" generate "A snowman" -o bad-snow.json $llm --replay "$recording" --max-repairs 0
    expect_text "generate problems" err.txt "answer: root.children[1].radius: expected a positive number, got -0.6"
    [ ! -e bad-snow.json ] || { echo "FAIL an invalid answer was written"; failures=$((failures + 1)); }
    check "edit replay" 0 "$bin" edit snow.json "make the hat red" -o edited.json $llm --replay "$recording"
    check "generate --emit python" 0 "$bin" generate "A snowman" -o snow.py --emit python $llm --replay "$recording"
    expect_text "generated program" snow.py "import sdfcsg as s"
    check "generate --emit bad" 2 "$bin" generate "A snowman" -o snow.py --emit yaml $llm --replay "$recording"
    expect_text "generate --emit bad message" err.txt "sdfcsg generate: --emit expects json or python"
    printf '# one prompt\n\nA snowman\n' >prompts.txt
    check "eval-prompts replay" 0 "$bin" eval-prompts prompts.txt --out eval $llm --replay "$recording"
    expect_text "eval first try" eval/report.txt "first-try validity: 0 of 1 (0%)"
    expect_text "eval after repair" eval/report.txt "validity after repair: 1 of 1 (100%)"
    [ -s eval/01.json ] && [ -s eval/01.png ] && [ -s eval/contact-sheet.png ] ||
        { echo "FAIL eval-prompts outputs"; ls eval; failures=$((failures + 1)); }
    expect_text "eval contact sheet" eval/report.txt "contact sheet: the prompts' renders in order, 1 tile a row, each numbered in its top-left corner; red: no scene"
    # A prompt without a scene shows the problems, not only the line that introduces them; a prompt
    # that repeats an example's request is named.
    printf 'A snowman\nA spur gear: 12 teeth by polar_repeat, a hub\n' >prompts.txt
    check "eval-prompts replay without repairs" 0 "$bin" eval-prompts prompts.txt --out eval-bad $llm --replay "$recording" --max-repairs 0
    expect_text "eval problems" eval-bad/report.txt "           answer: root.children[1].radius: expected a positive number, got -0.6"
    expect_text "eval repeated example" eval-bad/report.txt "note: prompt 2 nearly repeats the request of an example in the system prompt (\"A spur gear: 12 teeth by polar_repeat, a hub, and 6 lightening holes by a second polar_repeat.\"), so its first-try validity is inflated"
}

# Ctrl-C and SIGTERM: long work stops at its next progress check, and work that cannot be
# cancelled (a kernel build inside the driver) is ended by a watchdog; either way the command
# exits 130 within a second of the signal and leaves neither the output nor a temporary behind.
# Each job takes half a minute or more uninterrupted, so the signal always comes in the middle.
# interrupt NAME SIGNAL OUTPUT COMMAND...: sends SIGNAL two seconds after the start, or, where
# $held names a file, once that file appears (the stand-in language model holds a request).
interrupt() {
    name=$1 signal=$2 output=$3
    shift 3
    # A background job of a script starts with SIGINT ignored: restore the default first.
    env --default-signal=INT "$@" >out.txt 2>err.txt &
    pid=$!
    if [ -n "${held:-}" ]; then
        tries=0
        while [ ! -e "$held" ] && [ $tries -lt 600 ]; do sleep 0.1; tries=$((tries + 1)); done
    else
        sleep 2
    fi
    start=$(date +%s%N)
    kill -"$signal" "$pid"
    wait "$pid"
    rc=$?
    ms=$((($(date +%s%N) - start) / 1000000))
    if [ "$rc" -ne 130 ] || [ "$ms" -gt "$deadline" ] || [ -e "$output" ] || ls | grep -q '\.tmp-'; then
        echo "FAIL $name: exit $rc after $ms ms, expected 130 within $deadline ms and no output"
        ls; cat err.txt
        failures=$((failures + 1))
    else
        passed=$((passed + 1))
    fi
}

case_interrupt() {
    interrupt "mesh interrupted" INT big.ply "$bin" mesh "$src/assets/scenes/house.json" -o big.ply \
        --resolution 2048
    interrupt "render interrupted" TERM big.png "$bin" render "$src/assets/scenes/house.json" \
        -o big.png --width 4096 --height 4096 --aa 2
}

# Where -o leads: a symbolic link writes its target (the link stays), a FIFO, a character device
# and - are written into, a folder is refused; a missing or unwritable folder is refused before
# any work (here, before the scene is even read).
case_outputs() {
    small="--width 32 --height 24"
    echo text >target.txt && ln -s target.txt link.png
    check "render through a link" 0 "$bin" render "$mesh_a" -o link.png $small
    [ -L link.png ] && [ "$(head -c 4 target.txt | od -An -c | tr -d ' ')" = "211PNG" ] ||
        { echo "FAIL the link was replaced, or its target not written"; ls -l; failures=$((failures + 1)); }
    ln -s missing/deeper.png dangling.png
    check "render through a dangling link" 3 "$bin" render "$mesh_a" -o dangling.png $small
    expect_text "dangling link message" err.txt "dangling.png: the folder missing does not exist"
    "$bin" render "$mesh_a" -o - $small >stdout.png 2>err.txt
    [ "$(head -c 4 stdout.png | od -An -c | tr -d ' ')" = "211PNG" ] && [ ! -e ./- ] ||
        { echo "FAIL render -o - wrote no PNG to standard output"; failures=$((failures + 1)); }
    "$bin" mesh "$mesh_a" -o - --format stl --resolution 16 >stdout.stl 2>err.txt
    [ "$(wc -c <stdout.stl)" -gt 84 ] || { echo "FAIL mesh -o - --format stl"; failures=$((failures + 1)); }
    mkfifo pipe.png
    head -c 4 pipe.png >fifo-start.txt &
    reader=$!
    check "render into a FIFO" 0 "$bin" render "$mesh_a" -o pipe.png $small
    wait $reader
    [ -p pipe.png ] && [ "$(od -An -c fifo-start.txt | tr -d ' ')" = "211PNG" ] ||
        { echo "FAIL the FIFO was replaced or not written"; failures=$((failures + 1)); }
    if mknod null c 1 3 2>/dev/null; then # a private /dev/null, where the user may make one
        check "render into a device" 0 "$bin" render "$mesh_a" -o null $small
        [ -c null ] || { echo "FAIL the device was replaced"; failures=$((failures + 1)); }
    fi
    mkdir folder.png
    check "render onto a folder" 3 "$bin" render "$mesh_a" -o folder.png $small
    expect_text "folder message" err.txt "folder.png: is a folder, not a file to write"
    check "mesh into a missing folder" 3 "$bin" mesh no-such-scene.json -o no/such/dir.ply
    expect_text "missing folder message, before the scene" err.txt "no/such/dir.ply: the folder no/such does not exist"
    check "render a JPEG name" 2 "$bin" render "$mesh_a" -o x.jpg
    expect_text "JPEG name message" err.txt "sdfcsg render: render writes PNG images; the output must end in .png, got 'x.jpg'"
    ls | grep -q '\.tmp-' && { echo "FAIL a temporary file was left behind"; failures=$((failures + 1)); }
    # A temporary that a killed process left beside the target goes with the next write to it.
    sh -c 'exit 0' &
    dead=$!
    wait $dead
    touch "part.ply.tmp-$dead-0"
    check "mesh over a stale temporary" 0 "$bin" mesh "$mesh_a" -o part.ply --resolution 12
    [ ! -e "part.ply.tmp-$dead-0" ] || { echo "FAIL the stale temporary is still there"; failures=$((failures + 1)); }
}

# Ctrl-C at moments around the end of a large mesh's write: wherever it lands, the exit is 130
# within a second and the message is true (no file and "nothing was written", or the whole file
# and "wrote big.ply in full"); a run that finished first exits 0 with the whole file.
case_interrupt_write() {
    scene="$src/assets/scenes/house.json"
    start=$(date +%s%N)
    check "mesh to compare with" 0 "$bin" mesh "$scene" -o whole.ply --resolution 400
    total=$((($(date +%s%N) - start) / 1000000))
    for before in 600 350 200 100 40; do
        rm -f big.ply
        env --default-signal=INT "$bin" mesh "$scene" -o big.ply --resolution 400 >out.txt 2>err.txt &
        pid=$!
        wait_ms=$((total > before ? total - before : 0))
        sleep "$((wait_ms / 1000)).$(printf %03d $((wait_ms % 1000)))"
        sent=$(date +%s%N)
        kill -INT "$pid" 2>/dev/null
        wait "$pid"
        rc=$?
        ms=$((($(date +%s%N) - sent) / 1000000))
        echo "interrupted $before ms before the end: exit $rc after $ms ms: $(cat err.txt)"
        if [ "$rc" -eq 0 ] && cmp -s big.ply whole.ply; then
            passed=$((passed + 1))
        elif [ "$rc" -ne 130 ] || [ "$ms" -gt "$deadline" ]; then
            echo "FAIL interrupt $before ms before the end: exit $rc after $ms ms"; cat err.txt
            failures=$((failures + 1))
        elif [ -e big.ply ]; then
            cmp -s big.ply whole.ply && grep -qxF "sdfcsg: interrupted; wrote big.ply in full" err.txt &&
                passed=$((passed + 1)) ||
                { echo "FAIL interrupt $before ms before the end: a file, and"; cat err.txt; failures=$((failures + 1)); }
        else
            grep -qxF "sdfcsg: interrupted; nothing was written" err.txt && passed=$((passed + 1)) ||
                { echo "FAIL interrupt $before ms before the end: no file, and"; cat err.txt; failures=$((failures + 1)); }
        fi
    done
}

# --report checks the written mesh; --report-json writes the same as JSON (atomically).
case_mesh_report() {
    printf '{"version": 1, "root": {"type": "torus", "major_radius": 1, "minor_radius": 0.3}}' >torus.json
    check "mesh report" 0 "$bin" mesh torus.json -o torus.ply --resolution 32 --report \
        --report-json torus-report.json
    # The tube is 0.6 across; with one unit a centimetre, walls under 0.08 are thin.
    for line in "closed:             yes (0 boundary edges)" "watertight:         yes" \
        "shells:             1" "genus:              1" \
        "thin walls:         area 0 (0.0% of the surface) thinner than 0.08"; do
        expect_text "mesh report line" out.txt "$line"
    done
    grep -q '^thinnest wall:      0\.59[0-9]* at ' out.txt ||
        { echo "FAIL mesh --report thinnest wall:"; cat out.txt; failures=$((failures + 1)); }
    grep -q '"watertight": true, "shells": 1, "euler": 0, "genus": 1,' torus-report.json ||
        { echo "FAIL mesh --report-json:"; cat torus-report.json; failures=$((failures + 1)); }
    # With the mesh on standard output, the report goes to standard error.
    check "mesh report to stderr" 0 "$bin" mesh torus.json -o - --format ply --resolution 16 --report
    expect_text "mesh report on stderr" err.txt "genus:              1"
    check "mesh report min wall" 0 "$bin" mesh torus.json -o torus.ply --resolution 32 --report \
        --min-wall 0.7
    grep -q '^thin walls:         area [0-9.]* (100\.0% of the surface) thinner than 0\.7$' out.txt ||
        { echo "FAIL mesh --report --min-wall 0.7:"; cat out.txt; failures=$((failures + 1)); }
    for v in 0 -1 x nan; do
        check "mesh bad min wall $v" 2 "$bin" mesh torus.json -o torus.ply --report --min-wall "$v"
        expect_text "mesh bad min wall message" err.txt "sdfcsg mesh: --min-wall expects a length greater than 0, got '$v'"
    done
    check "mesh report into a missing folder" 3 "$bin" mesh torus.json -o torus.ply \
        --report-json missing/report.json
}

# Valid scenes that show nothing say why, on standard error, and still exit 0.
case_degenerate() {
    one() { # one FILE ROOT: a scene of the node ROOT
        printf '{"version": 1, "root": %s}' "$2" >"$1"
    }
    one huge.json '{"type": "sphere", "radius": 3e38}'
    one scaled.json '{"type": "sphere", "radius": 1, "scale": 1e20}'
    one tiny.json '{"type": "sphere", "radius": 1e-30}'
    one shrunk.json '{"type": "sphere", "radius": 1, "scale": 1e-20}'
    one empty.json '{"type": "difference", "children": [{"type": "sphere", "radius": 1}, {"type": "sphere", "radius": 2}]}'
    one ball.json '{"type": "sphere", "radius": 1}'
    shows() { # shows FILE REASON [RENDER OPTIONS...]: render warns that FILE shows nothing
        file=$1 reason=$2
        shift 2
        check "render $file" 0 "$bin" render "$file" -o "$file.png" --width 64 --height 48 "$@"
        expect_text "render $file warning" err.txt "warning: $file.png shows nothing: $reason"
    }
    shows huge.json "the solid is too large for single precision: its bounds reach 3e+38"
    shows scaled.json "the solid is too large for single precision: its bounds reach 1e+20"
    shows tiny.json "the solid is smaller than a pixel: at most 3.46e-06 units across, seen from 0.00287 units away"
    shows shrunk.json "the solid is smaller than a pixel: at most 3.46e-06 units across, seen from 0.00287 units away"
    shows empty.json "the solid is empty: no point of its bounds lies inside it"
    shows ball.json "the solid lies outside the view" --eye 0,0,5 --target 0,0,10
    shows ball.json "the camera is inside the solid" --eye 0,0,0.5 --target 0,0,0
    check "render ball" 0 "$bin" render ball.json -o ball.png --width 64 --height 48
    [ ! -s err.txt ] || { echo "FAIL render ball: a warning"; cat err.txt; failures=$((failures + 1)); }

    check "mesh empty" 0 "$bin" mesh empty.json -o empty.ply
    expect_text "mesh empty warning" err.txt "warning: empty.ply holds an empty mesh: the solid is empty: no point of its bounds lies inside it"
    check "mesh resolution 1" 0 "$bin" mesh ball.json -o coarse.ply --resolution 1
    expect_text "mesh resolution 1 warning" err.txt "warning: coarse.ply holds an empty mesh: the grid is too coarse to find the surface; resolution 2 is the smallest that does"
    check "mesh resolution 2" 0 "$bin" mesh ball.json -o fine.ply --resolution 2
    [ ! -s err.txt ] || { echo "FAIL mesh resolution 2: a warning"; cat err.txt; failures=$((failures + 1)); }
    check "mesh huge" 1 "$bin" mesh huge.json -o huge.ply
    expect_text "mesh huge message" err.txt "<mesh>: the solid is too large for single precision: its bounds reach 3e+38"
}

spheres() { # spheres N FILE: a scene of N spheres of distinct sizes and places in one union
    awk -v n="$1" 'BEGIN {
        printf "{\"version\": 1, \"root\": {\"type\": \"union\", \"children\": ["
        for (i = 0; i < n; i++)
            printf "%s{\"type\": \"sphere\", \"radius\": %.5f, \"translate\": [%.5f, %.5f, %.5f]}",
                (i ? ", " : ""), 0.02 + 0.00001 * i, sin(i), cos(0.7 * i), sin(1.3 * i)
        print "]}}" }' >"$2"
}

# Inlined, 511 distinct spheres (512 nodes, the limit) take far longer than two seconds to
# compile; one more node is refused at once, naming the limit and the modes that take it.
case_interrupt_kernel_build() {
    spheres 511 limit.json
    interrupt "kernel build interrupted" TERM big.ply env SDFCSG_CACHE_DIR=off \
        MESA_SHADER_CACHE_DISABLE=true "$bin" mesh limit.json -o big.ply --evaluation inlined
    expect_text "kernel build interrupted message" err.txt "sdfcsg: interrupted; nothing was written"
    spheres 512 past.json
    for command in "render -o past.png" "mesh -o past.ply"; do
        start=$(date +%s%N)
        check "inlined past the limit: $command" 1 env SDFCSG_CACHE_DIR=off "$bin" $command \
            past.json --evaluation inlined
        ms=$((($(date +%s%N) - start) / 1000000))
        [ "$ms" -le "$deadline" ] ||
            { echo "FAIL inlined past the limit: $command took $ms ms"; failures=$((failures + 1)); }
        expect_text "inlined past the limit message" err.txt "past.json: root: inlined evaluation takes at most 512 nodes and this scene has 513; evaluate it from tapes (--evaluation tapes or auto)"
    done
}

# Ctrl-C while a language model is awaited (skipped without python3): a stand-in answers the
# first request and holds the next. generate keeps the exchanges so far in its --record file;
# eval-prompts reports the prompts done.
case_interrupt_generate() {
    command -v python3 >/dev/null 2>&1 || { echo "SKIPPED: python3 not found"; exit 77; }
    echo '{"version": 1, "root": {"type": "sphere", "radius": -1}}' >answer.json
    slow_llm() { # slow_llm ANSWERED: starts the stand-in, sets $llm_pid, $slow and $held
        rm -f port.txt port.txt.held
        held=port.txt.held
        python3 "$src/tests/viewer/fake_llm.py" answer.json port.txt "$1" &
        llm_pid=$!
        tries=0
        while [ ! -s port.txt ] && [ $tries -lt 100 ]; do sleep 0.1; tries=$((tries + 1)); done
        slow="--base-url http://127.0.0.1:$(cat port.txt)/v1 --model test-model"
    }
    slow_llm 1
    interrupt "generate interrupted" INT int.json "$bin" generate "a ball" -o int.json $slow --record int-rec.json
    expect_text "generate interrupted message" err.txt "sdfcsg: interrupted; int.json was not written, the exchanges so far are in int-rec.json"
    [ "$(grep -c '"url":' int-rec.json)" = 1 ] ||
        { echo "FAIL the recording of an interrupted generate"; cat int-rec.json; failures=$((failures + 1)); }
    kill "$llm_pid"
    echo '{"version": 1, "root": {"type": "sphere", "radius": 1}}' >answer.json
    slow_llm 1
    printf 'A ball\nA snowman\n' >prompts.txt
    interrupt "eval-prompts interrupted" TERM eval-int/02.json "$bin" eval-prompts prompts.txt --out eval-int $slow
    expect_text "eval-prompts interrupted report" eval-int/report.txt "interrupted after 1 prompt of 2; what follows covers those"
    [ -s eval-int/01.json ] && [ -s eval-int/contact-sheet.png ] ||
        { echo "FAIL eval-prompts interrupted outputs"; ls eval-int; failures=$((failures + 1)); }
    kill "$llm_pid"
    held=
}

type "case_$test_case" >/dev/null 2>&1 || { echo "no such case: $test_case"; exit 2; }
rm -rf "${work:?}/$test_case" && mkdir -p "$work/$test_case" && cd "$work/$test_case" || exit 1
"case_$test_case"
echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
