#!/bin/sh
# The viewer under a virtual X server: its screenshot matches the headless renderer, a scripted
# session (select, edit, modes, undo, save) changes the image at every step, an extracted mesh
# drawn by the window's pipeline covers the ray-marched silhouette, and a scripted generation
# against a stand-in language model is one undo step. The validation layer is on (the test's
# environment sets SDFCSG_VALIDATION), and any message fails the viewer's run.
# Usage: viewer_test.sh VIEWER CLI IMAGE_DIFF SOURCE_DIR WORK_DIR. Exits 77 (skipped) without
# xvfb-run.
set -eu
viewer=$1 cli=$2 diff=$3 src=$4 work=$5
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "SKIPPED: xvfb-run not found (Debian package xvfb)"
    exit 77
fi
rm -rf "$work" && mkdir -p "$work" && cd "$work"
# 24-bit colour: xvfb-run's default screen is 8-bit, which Vulkan cannot present to.
run() { xvfb-run -a -s "-screen 0 1280x1024x24" "$viewer" "$@"; }
fail() { echo "FAIL: $*"; exit 1; }

# 1. The window shows what `sdfcsg render` computes for the same camera and size.
scene=$src/assets/scenes/snowman.json
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

# 2. A scripted session; every step must change the image, and undo must bring it back.
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

# 3. A script with a mistake is refused before any window opens.
echo "select nose
mode shiny" > bad.txt
if run edit.json --script bad.txt 2> bad.err; then fail "a bad script was accepted"; fi
grep -q "bad.txt:2:1: mode: expected one of shaded, normals, depth, steps, got \"shiny\"" bad.err ||
    fail "unexpected message: $(cat bad.err)"
# 4. Mesh mode: the extracted mesh, shaded and as a wireframe, covers the pixels the ray marcher
# shows as the object (shading differs, the silhouette must not, up to the cells' size), the
# ground grid is drawn in the mesh view too, the export writes the file in the background, and
# the ray-marched view comes back unchanged.
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
"$diff" m3-march.png m0-march.png same 0 0 || fail "the ray-marched view did not come back"
grep -q "^f " mesh.obj || fail "the exported mesh has no faces"
printf 'view mesh\n' > no-mesh.txt
if run "$scene" --script no-mesh.txt --size 320x240 --no-ui 2> no-mesh.err; then
    fail "showing a mesh before extracting one was accepted"
fi
grep -q "no-mesh.txt:1: view mesh: no mesh extracted" no-mesh.err ||
    fail "unexpected message: $(cat no-mesh.err)"

# 5. Scripted generation against a stand-in language model (skipped without python3): the new
# scene replaces the old one as one undo step, and an answer that never loads fails the script
# while the scene stays.
if command -v python3 >/dev/null 2>&1; then
    echo '{"version": 1, "root": {"type": "sphere", "name": "ball", "radius": 1, "color": [1, 0, 0]}}' > answer.json
    python3 "$src/tests/viewer/fake_llm.py" answer.json port.txt &
    llm=$!
    trap 'kill $llm 2>/dev/null' EXIT
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
    grep -q "generate.txt:2: 1 nodes, valid on the first try" generate.err ||
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
else
    echo "skipped the generation session: python3 not found"
fi
echo "viewer tests passed"
