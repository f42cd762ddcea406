#!/bin/sh
# The viewer under a virtual X server: its screenshot matches the headless renderer, a scripted
# session (select, edit, modes, undo, save) changes the image at every step, an extracted mesh
# drawn by the window's pipeline covers the ray-marched silhouette, and a scripted generation
# against a stand-in language model is one undo step. The validation layer is on (the test's
# environment sets SDFCSG_VALIDATION), and any message fails the viewer's run.
# Usage: viewer_test.sh VIEWER CLI IMAGE_DIFF SOURCE_DIR WORK_DIR CASE, where CASE names one of
# the case_ functions below; it runs in WORK_DIR/CASE with an X server of its own, so cases may
# run in parallel. tests/CMakeLists.txt registers each case as a test of its own, viewer.CASE.
# Exits 77 (skipped) without Xvfb, or when a case cannot run.
set -eu
viewer=$1 cli=$2 diff=$3 src=$4 work=$5 test_case=$6
scene=$src/assets/scenes/snowman.json
# A crash prints the stacks of the viewer's threads from its core file (where gdb is installed and
# the kernel writes cores to the working folder), so that a rare one can be told apart.
run() {
    rc=0
    "$viewer" "$@" || rc=$?
    if [ $rc -ge 128 ]; then
        for core in core core.*; do
            [ -f "$core" ] && command -v gdb >/dev/null 2>&1 &&
                gdb -q -batch -ex 'thread apply all bt 25' "$viewer" "$core" 2>&1 | grep -v '^\[New LWP'
        done
    fi
    return $rc
}
fail() { echo "FAIL: $*"; exit 1; }

# The window shows what `sdfcsg render` computes for the same camera and size.
case_screenshot() {
    run "$scene" --screenshot viewer.png --frames 3 --size 320x240 --no-ui || fail "viewer screenshot"
    "$cli" render "$scene" -o headless.png --width 320 --height 240 || fail "headless render"
    # Kernels with values inlined or read from a buffer may round differently by a step or two.
    "$diff" viewer.png headless.png same 6 0.002 || fail "viewer image differs from the headless render"
    # The ground grid is the renderer's own (RenderOptions::grid), so it matches `render --grid`.
    printf 'grid on\nscreenshot grid.png\n' > grid.txt
    run "$scene" --script grid.txt --size 320x240 --no-ui || fail "viewer grid screenshot"
    "$cli" render "$scene" -o headless-grid.png --width 320 --height 240 --grid ||
        fail "headless render with the grid"
    "$diff" viewer.png grid.png differ 0.005 || fail "the grid changed nothing"
    "$diff" grid.png headless-grid.png same 6 0.002 ||
        fail "viewer image with the grid differs from the headless render"
}

# A scripted session; every step must change the image, and undo must bring it back.
case_session() {
    run "$scene" --screenshot viewer.png --frames 3 --size 320x240 --no-ui || fail "viewer screenshot"
    cp "$src/assets/scenes/snowman.json" edit.json
    cat > session.txt <<'SCRIPT'
# select a node, edit a value, switch modes, undo, save
screenshot 0-start.png
select nose
boxes selected
screenshot 1-selected.png
set radius 0.3
screenshot 2-edited.png
mode normals
screenshot 3-normals.png
mode depth
shadows off
screenshot 4-depth.png
mode shaded
shadows on
boxes none
select none
undo
screenshot 5-undone.png
save saved.json
SCRIPT
    run edit.json --script session.txt --size 320x240 --no-ui || fail "scripted session"
    "$diff" 0-start.png viewer.png same 0 0 || fail "the script's first image is not the plain one"
    "$diff" 0-start.png 1-selected.png differ 0.0003 || fail "selecting showed no bounding box"
    "$diff" 1-selected.png 2-edited.png differ 0.002 || fail "editing the nose changed nothing"
    "$diff" 2-edited.png 3-normals.png differ 0.3 || fail "normals mode looks like shaded"
    "$diff" 3-normals.png 4-depth.png differ 0.3 || fail "depth mode looks like normals"
    "$diff" 5-undone.png 0-start.png same 0 0 || fail "undo did not restore the scene"
    grep -q '"radius": 0.3\b' saved.json && fail "the saved scene holds the undone edit"
    "$cli" validate saved.json || fail "the saved scene does not load"
}

# Structural edits change the image and undo restores it; each view option changes the image.
case_structure() {
    cp "$src/assets/scenes/snowman.json" edit.json
    cat > structure.txt <<'SCRIPT'
screenshot t0.png
select coal
remove
expect-selected none
screenshot t1-removed.png
undo
screenshot t2-undone.png
select coal
op intersection
select none
screenshot t3-op.png
undo
select nose
kind box
select none
screenshot t4-kind.png
undo
select brim
move down
expect-selected brim
select coal
add sphere
select none
screenshot t5-added.png
undo
undo
mode steps
screenshot m-steps.png
mode shaded
grid on
screenshot m-grid.png
grid off
ao off
screenshot m-ao.png
ao on
boxes all
screenshot m-boxes.png
boxes none
screenshot t6-end.png
SCRIPT
    run edit.json --script structure.txt --size 320x240 --no-ui || fail "structural edits"
    "$diff" t0.png t1-removed.png differ 0.001 || fail "removing the coal changed nothing"
    "$diff" t0.png t2-undone.png same 0 0 || fail "undo did not restore the removed node"
    "$diff" t0.png t3-op.png differ 0.001 || fail "changing an operation changed nothing"
    "$diff" t0.png t4-kind.png differ 0.001 || fail "changing a kind changed nothing"
    "$diff" t0.png t5-added.png differ 0.001 || fail "adding a node changed nothing"
    "$diff" t0.png m-steps.png differ 0.3 || fail "steps mode looks like shaded"
    "$diff" t0.png m-grid.png differ 0.001 || fail "the grid shows nothing"
    "$diff" t0.png m-ao.png differ 0.01 || fail "turning AO off changed nothing"
    "$diff" t0.png m-boxes.png differ 0.005 || fail "boxes all shows nothing"
    "$diff" t0.png t6-end.png same 0 0 || fail "the view options did not go back"
}

# Moving a node into another operation: the head leaves the smooth white body for the black
# coal, as its first child, and stays selected; undo restores the image exactly. A target that
# is no operation fails the script with the edit's message.
case_parent() {
    cp "$src/assets/scenes/snowman.json" edit.json
    cat > parent.txt <<'SCRIPT'
screenshot q0.png
select head
parent coal 0
expect-selected head
select none
screenshot q1-moved.png
undo
screenshot q2-undone.png
SCRIPT
    run edit.json --script parent.txt --size 320x240 --no-ui || fail "moving a node"
    "$diff" q0.png q1-moved.png differ 0.01 || fail "moving the head into the coal changed nothing"
    "$diff" q0.png q2-undone.png same 0 0 || fail "undo did not restore the moved node"
    printf 'select head\nparent nose\n' > parent-bad.txt
    if run edit.json --script parent-bad.txt --size 320x240 --no-ui 2> parent-bad.err; then
        fail "moving a node under a primitive was accepted"
    fi
    grep -q "parent-bad.txt:2: .*only an operation can take children" parent-bad.err ||
        fail "unexpected message: $(cat parent-bad.err)"
}

# The selection: its highlight and its box lie within the node's projected bounds; a click
# selects the node under the cursor, and one on the sky clears the selection.
case_select() {
    cp "$src/assets/scenes/snowman.json" edit.json
    cat > select.txt <<'SCRIPT'
boxes none
screenshot p0.png
select head
screenshot p1-highlight.png
print-bounds head
boxes selected
select none
screenshot p2-nobox.png
select head
screenshot p3-box.png
select none
pick 160 60
expect-selected head
pick 2 2
expect-selected none
SCRIPT
    run edit.json --script select.txt --size 320x240 --no-ui > select.out ||
        fail "selection script: $(cat select.out)"
    set -- $(grep '^bounds head ' select.out | cut -d' ' -f3-)
    [ $# -eq 4 ] || fail "no bounds printed: $(cat select.out)"
    "$diff" p0.png p1-highlight.png within "$@" 3 0.2 || fail "the highlight is not on the head"
    "$diff" p0.png p2-nobox.png same 0 0 || fail "boxes selected without a selection drew something"
    "$diff" p1-highlight.png p3-box.png within "$@" 3 0.0 || fail "the box is not around the head"
    "$diff" p1-highlight.png p3-box.png differ 0.001 || fail "selecting showed no bounding box"
}

# The field notes that the Scene and Node panels show: those of `sdfcsg validate`, and none once
# an edit makes the field a distance again.
case_notes() {
    printf '{"version": 1, "root": {"type": "offset", "distance": 0.3, "children": [%s]}}' \
        '{"type": "twist", "name": "twist", "angle": 90, "children": [{"type": "box", "size": [1, 2, 1]}]}' >twisted.json
    printf 'print-notes\nselect twist\nset angle 0\nprint-notes\n' >notes.txt
    run twisted.json --script notes.txt --size 320x240 --no-ui >notes.out || fail "notes script: $(cat notes.out)"
    "$cli" validate twisted.json | sed -n 's/^twisted.json: \(.*\): note: /note \1: /p' >want.txt
    [ "$(wc -l <want.txt)" -eq 2 ] || fail "validate gave $(cat want.txt)"
    grep '^note ' notes.out >got.txt || true
    cmp -s want.txt got.txt || fail "the viewer's notes $(cat got.txt) are not validate's $(cat want.txt)"
}

# An invalid file on disk shows its error and keeps the last image; fixing it reloads. Opening
# an invalid file keeps the scene, and Save still writes the scene's own file.
case_reload() {
    cp "$src/assets/scenes/snowman.json" live.json
    echo '{' > bad.json
    cat > reload.txt <<'SCRIPT'
screenshot r0.png
ui on
screenshot u0.png
ui off
wait-reload
expect-error root.radius: expected a positive number, got -2
screenshot r1.png
ui on
screenshot u1.png
ui off
wait-reload
expect-error none
screenshot r2.png
open bad.json
expect-error bad.json
screenshot r3.png
save
SCRIPT
    run live.json --script reload.txt --size 320x240 --no-ui > reload.out 2>&1 &
    viewer_pid=$!
    replace() { # FILE CONTENT_FILE after WAIT_FOR appears
        tries=0
        while [ ! -e "$1" ] && [ $tries -lt 1200 ]; do sleep 0.1; tries=$((tries + 1)); done
        cp "$2" live.tmp && mv live.tmp live.json
    }
    echo '{"version": 1, "root": {"type": "sphere", "radius": -2}}' > broken.json
    replace u0.png broken.json
    replace u1.png "$src/assets/scenes/house.json"
    wait $viewer_pid || fail "reload script: $(cat reload.out)"
    "$diff" r0.png r1.png same 0 0 || fail "a broken file replaced the image"
    "$diff" u0.png u1.png differ 0.001 || fail "the panel shows no error"
    "$diff" r0.png r2.png differ 0.05 || fail "the fixed file was not reloaded"
    "$diff" r2.png r3.png same 0 0 || fail "opening a broken file replaced the image"
    [ "$(cat bad.json)" = "{" ] || fail "Save wrote over the broken file"
    "$cli" validate live.json || fail "Save did not write the scene's own file"
}

# Leaving right after a value edit does not wait for the background compiles (generous limit).
case_quit() {
    cp "$src/assets/scenes/snowman.json" edit.json
    printf 'select nose\nset radius 0.2\n' > quit.txt
    timeout 60 "$viewer" edit.json --script quit.txt \
        --size 320x240 --no-ui || fail "the viewer did not exit promptly after an edit"
}

# A screenshot with nothing to show is written within seconds, with the reason.
case_screenshot_empty() {
    timeout 10 "$viewer" --screenshot none.png --size 320x240 --no-ui 2>none.err ||
        fail "no screenshot within 10 s without a scene"
    [ -s none.png ] || fail "no screenshot without a scene"
    grep -qxF "note: none.png shows no scene: none is open" none.err || fail "$(cat none.err)"
    printf '{"version": 1, "root": {"type": "sphere", "radius": 3e38}}' >huge.json
    timeout 10 "$viewer" huge.json --screenshot huge.png --size 320x240 --no-ui 2>huge.err ||
        fail "no screenshot within 10 s of a solid beyond single precision"
    grep -qxF "note: huge.png shows nothing: the solid is too large for single precision: its bounds reach 3e+38" huge.err ||
        fail "$(cat huge.err)"
    printf '{"version": 1, "root": {"type": "difference", "children": [{"type": "sphere", "radius": 1}, {"type": "sphere", "radius": 2}]}}' >empty.json
    timeout 10 "$viewer" empty.json --screenshot empty.png --size 320x240 --no-ui 2>empty.err ||
        fail "no screenshot within 10 s of an empty solid"
    grep -qxF "note: empty.png shows nothing: the solid is empty: no point of its bounds lies inside it" empty.err ||
        fail "$(cat empty.err)"
}

# A script with a mistake is refused before any window opens.
case_bad_script() {
    cp "$src/assets/scenes/snowman.json" edit.json
    echo "select nose
    mode shiny" > bad.txt
    if run edit.json --script bad.txt 2> bad.err; then fail "a bad script was accepted"; fi
    grep -q "bad.txt:2:1: mode: expected one of shaded, normals, depth, steps, got \"shiny\"" bad.err ||
        fail "unexpected message: $(cat bad.err)"
}

# Mesh mode: the extracted mesh, shaded and as a wireframe, covers the pixels the ray marcher
# shows as the object (shading differs, the silhouette must not, up to the cells' size), the
# ground grid is drawn in the mesh view too, the export writes the file in the background, and
# the ray-marched view comes back unchanged.
case_mesh() {
    cat > mesh.txt <<'SCRIPT'
screenshot m0-march.png
mesh extract 128
screenshot m1-mesh.png
wireframe on
screenshot m2-wire.png
wireframe off
grid on
screenshot m4-grid.png
grid off
mesh export mesh.obj
view march
screenshot m3-march.png
SCRIPT
    run "$scene" --script mesh.txt --size 320x240 --no-ui || fail "scripted mesh session"
    "$diff" m0-march.png m1-mesh.png mask 3 0.98 || fail "the mesh's silhouette is not the scene's"
    "$diff" m0-march.png m2-wire.png mask 3 0.98 || fail "the wireframe's silhouette is not the scene's"
    "$diff" m1-mesh.png m2-wire.png differ 0.01 || fail "the wireframe shows no edges"
    "$diff" m1-mesh.png m4-grid.png differ 0.005 || fail "the mesh view shows no grid"
    # A plate 0.04 thick under a ball: thinner than 0.8 mm at a centimetre a unit, so it turns red.
    printf '{"version": 1, "root": {"type": "union", "children": [%s, %s]}}' \
        '{"type": "box", "size": [2, 0.04, 2], "color": "#808080"}' \
        '{"type": "sphere", "radius": 0.5, "translate": [0, 0.5, 0], "color": "#808080"}' >plate.json
    printf 'mesh extract 96\nscreenshot t0.png\nthin-walls on\nscreenshot t1.png\nthin-walls off\nscreenshot t2.png\n' >thin.txt
    run plate.json --script thin.txt --size 320x240 --no-ui || fail "scripted thin walls"
    "$diff" t0.png t1.png differ 0.05 || fail "thin-walls on showed no thin walls"
    "$diff" t0.png t2.png same 0 0 || fail "thin-walls off did not bring the colours back"
    "$diff" m3-march.png m0-march.png same 0 0 || fail "the ray-marched view did not come back"
    grep -q "^f " mesh.obj || fail "the exported mesh has no faces"
    printf 'view mesh\n' > no-mesh.txt
    if run "$scene" --script no-mesh.txt --size 320x240 --no-ui 2> no-mesh.err; then
        fail "showing a mesh before extracting one was accepted"
    fi
    grep -q "no-mesh.txt:1: view mesh: no mesh extracted" no-mesh.err ||
        fail "unexpected message: $(cat no-mesh.err)"
}

# Marching cubes, then a simplified mesh written as 3MF.
case_mesh_3mf() {
    cat > mesh3mf.txt <<'SCRIPT'
mesh extract 64 mc
mesh extract 96 dc 0.2
mesh export part.3mf
SCRIPT
    run "$scene" --script mesh3mf.txt --size 320x240 --no-ui || fail "scripted simplified mesh"
    [ "$(head -c 2 part.3mf)" = "PK" ] || fail "part.3mf is not a 3MF package"
}

# A large mesh is drawn coarse while the view moves (under the validation layer), and whole
# again once it settles.
case_mesh_preview() {
    cat > preview.txt <<'SCRIPT'
mesh extract 256
screenshot p0-full.png
drag 10 0
drag -10 0
screenshot p1-settled.png
SCRIPT
    run "$src/assets/scenes/mesh_b.json" --script preview.txt --size 320x240 --no-ui ||
        fail "scripted mesh preview session"
    "$diff" p0-full.png p1-settled.png same 0 0 || fail "the full mesh did not come back after a drag"
}

# Scripted generation against a stand-in language model (skipped without python3): the new
# scene replaces the old one as one undo step, and an answer that never loads fails the script
# while the scene stays.
case_generate() {
    command -v python3 >/dev/null 2>&1 || { echo "SKIPPED: python3 not found"; exit 77; }
    cp "$src/assets/scenes/snowman.json" edit.json
    echo '{"version": 1, "root": {"type": "sphere", "name": "ball", "radius": 1, "color": [1, 0, 0]}}' > answer.json
    python3 "$src/tests/viewer/fake_llm.py" answer.json port.txt &
    llm=$!
    pids="$pids $llm"
    tries=0
    while [ ! -s port.txt ] && [ $tries -lt 100 ]; do sleep 0.1; tries=$((tries + 1)); done
    [ -s port.txt ] || fail "the stand-in language model did not start"
    export SDFCSG_LLM_BASE_URL="http://127.0.0.1:$(cat port.txt)/v1" SDFCSG_LLM_MODEL=fake \
        SDFCSG_LLM_API_KEY= OPENAI_API_KEY= SDFCSG_LLM_API= no_proxy=127.0.0.1
    cat > generate.txt <<'SCRIPT'
screenshot g0-start.png
generate a red ball
screenshot g1-generated.png
save generated.json
undo
reset
screenshot g2-undone.png
SCRIPT
    run edit.json --script generate.txt --size 320x240 --no-ui 2> generate.err ||
        fail "scripted generation: $(cat generate.err)"
    grep -q "generate.txt:2: 1 node, valid on the first try" generate.err ||
        fail "no summary of the generation: $(cat generate.err)"
    grep -q '"name": "ball"' generated.json || fail "the generated scene was not the current one"
    "$diff" g0-start.png g1-generated.png differ 0.05 || fail "the generated scene is not shown"
    "$diff" g2-undone.png g0-start.png same 0 0 || fail "undo did not bring the scene back"

    echo '{"version": 1, "root": {"type": "sphere", "radius": -1}}' > answer.json
    printf 'edit-scene make it smaller\nsave unchanged.json\n' > bad-generate.txt
    if run edit.json --script bad-generate.txt --size 320x240 --no-ui 2> bad-generate.err; then
        fail "a failed generation did not fail the script"
    fi
    grep -q "bad-generate.txt:1: answer: no answer loaded after 3 repair rounds" bad-generate.err ||
        fail "unexpected message: $(cat bad-generate.err)"
    [ ! -e unchanged.json ] || fail "the script went on after a failed generation"
}

type "case_$test_case" >/dev/null 2>&1 || { echo "no such case: $test_case"; exit 2; }
if ! command -v Xvfb >/dev/null 2>&1; then
    echo "SKIPPED: Xvfb not found (Debian package xvfb)"
    exit 77
fi
rm -rf "${work:?}/$test_case" && mkdir -p "$work/$test_case" && cd "$work/$test_case"
ulimit -c unlimited 2>/dev/null || true
export XDG_CONFIG_HOME="$work/$test_case/config" # the recent-files list stays in here
# One X server for the case, on a display number that the server picks and writes to -displayfd
# (xvfb-run -a looks for a free number before starting the server, so two cases starting at once
# can pick the same). 24-bit colour: the default screen is 8-bit, which Vulkan cannot present to.
Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp 3> display.txt 2> xvfb.log &
pids=$!
trap 'kill $pids 2>/dev/null || true' EXIT
tries=0
while [ ! -s display.txt ] && [ $tries -lt 100 ]; do sleep 0.1; tries=$((tries + 1)); done
[ -s display.txt ] || fail "Xvfb did not start: $(cat xvfb.log)"
export DISPLAY=":$(cat display.txt)"
"case_$test_case"
echo "viewer.$test_case passed"
