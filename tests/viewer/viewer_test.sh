#!/bin/sh
# The viewer under a virtual X server: its screenshot matches the headless renderer, and a
# scripted session (select, edit, modes, undo, save) changes the image at every step.
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
echo "viewer tests passed"
