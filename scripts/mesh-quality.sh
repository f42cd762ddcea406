#!/bin/sh
# Dual contouring's quality, one build of sdfcsg against another on the same scenes, in one run:
# flipped triangles (facing against the field's gradient), self-intersecting pairs and the
# vertices' largest distance from the surface in cells, over the seeded random scenes that
# build/tests/test_mesh writes (MeshQuality.FiguresOfWrittenMeshes: 12 random trees of every
# kind, 12 random Booleans of turned primitives) at 37, 64, 96 and 131 cells and over
# assets/scenes/table_and_chairs.json at 64, 97, 101, 128 and 143.
#   sh scripts/mesh-quality.sh OLD_SDFCSG NEW_SDFCSG [WORK_DIR]
# Prints each build's totals per family of scenes (the meshes' own lines go to WORK_DIR). NEW_SDFCSG
# may be "-" to measure one build. Each sdfcsg run compiles the scene (about 4 s on lavapipe).
set -eu
cd "$(dirname "$0")/.."
old=$1
new=$2
work=${3:-$(mktemp -d)}
mkdir -p "$work/scenes"
SDFCSG_MESH_QUALITY_SCENES="$work/scenes" build/tests/test_mesh \
    --gtest_filter=MeshQuality.FiguresOfWrittenMeshes >/dev/null
cp assets/scenes/table_and_chairs.json "$work/scenes/table.json"

for family in trees booleans table; do
    if [ "$family" = table ]; then resolutions="64 97 101 128 143"; else resolutions="37 64 96 131"; fi
    for build in old new; do
        if [ "$build" = old ]; then sdfcsg=$old; else sdfcsg=$new; fi
        [ "$sdfcsg" = - ] && continue
        mkdir -p "$work/$build"
        list="$work/$build/$family.list"
        : >"$list"
        for scene in "$work/scenes/$family"*.json; do
            name=$(basename "$scene" .json)
            for r in $resolutions; do
                mesh="$work/$build/${name}_$r.ply"
                h=$("$sdfcsg" mesh "$scene" -o "$mesh" --resolution "$r" --stats |
                    sed -n 's/^grid:.* cells of \([^,]*\),.*/\1/p')
                echo "$scene $mesh $h" >>"$list"
            done
        done
        SDFCSG_MESH_QUALITY="$list" build/tests/test_mesh \
            --gtest_filter=MeshQuality.FiguresOfWrittenMeshes >"$work/$build/$family.out"
        printf '%-8s %-4s %s\n' "$family" "$build" "$(grep '^total' "$work/$build/$family.out")"
    done
done
