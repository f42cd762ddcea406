#!/bin/sh
# Adds a primitive the way docs/vocabulary.md says, in a scratch copy of the tree, then builds the
# copy and runs its whole suite: the docs' claim that a new primitive is its line in kinds.h, its
# table entry, its formula and a true-distance test, held by a build. The dummy kind, "dummy", is
# a ball of radius `radius` under a formula of its own.
# Usage: sh scripts/check-new-kind.sh [SCRATCH_DIR] (default: a new temporary folder).
set -eu
cd "$(dirname "$0")/.."
scratch=${1:-$(mktemp -d)}
echo "check-new-kind: a scratch copy in $scratch"
mkdir -p "$scratch"
git ls-files -z | xargs -0 cp --parents -t "$scratch"
cd "$scratch"

# Inserts the text of stdin before the one line of FILE that is exactly LINE.
insert_before() {
    text=$(cat)
    [ "$(grep -cxF -- "$2" "$1")" = 1 ] || { echo "check-new-kind: no single line '$2' in $1"; exit 1; }
    TEXT=$text awk -v line="$2" '$0 == line { print ENVIRON["TEXT"] } { print }' "$1" >"$1.new"
    mv "$1.new" "$1"
}

# 1. Its line in kinds.h.
insert_before engine/include/sdfcsg/kinds.h '    X(CappedTorus)' <<'END'
    X(Dummy)                                                                                       \
END
# 2. Its formula and its line in sdPrimitive.
insert_before shaders/sdf.glsl '// A primitive'"'"'s local distance by its kind (NodeKind'"'"'s numbering) and kernel parameters (a:' <<'END'
SDF_FN float sdDummy(vec3 p, float r) { return sqrt(dot(p, p)) - r; }

END
insert_before shaders/sdf.glsl '    if (SDF_IS(kKindCircle)) return sdCircle(q, a.x);' <<'END'
    if (SDF_IS(kKindDummy)) return sdDummy(q, a.x);
END
# 3. Its table entry, in the kinds' order.
insert_before engine/src/scene/nodes.cpp '    {NodeKind::CappedTorus, "capped_torus", false, kCappedTorus,' <<'END'
    {NodeKind::Dummy, "dummy", false, kSphere, "A ball, to check that kinds are added in one place.",
     R"("radius": 0.7)", "sdDummy", kA0, [](const Params& v) -> Params { return {v[0]}; },
     [](const Params& k, vec3& lo, vec3& hi) { return symmetric(vec3(k[0]), lo, hi); }},
END
# 4. A case against the true distance.
insert_before tests/unit/test_primitives.cpp '    for (double r : {0.5, 1.7})' <<'END'
    add(
        "dummy", NodeKind::Dummy, {0.7f}, [](dvec3 p) { return length(p) - 0.7; }, 0.7);
END
# 5. The files made from the table, and the GoogleTest suites (`unit` and `gpu`: the kind's true
# distance, the device against the CPU, random trees of every kind). The Python module, the
# command line's and the viewer's sessions and the consumer project add nothing a new primitive
# changes (the module's functions come from the table, and their tests run in the main suite), so
# they are left out here to keep CI short. The build is clang's (CXX overrides it), which built
# the library in less than half GCC's time where both were measured (under the sanitizers: 140 s
# against 302 s on 2 cores); GCC's build is the test command's.
CXX=${CXX:-clang++-14} SDFCSG_CMAKE_ARGS="${SDFCSG_CMAKE_ARGS:-} -DSDFCSG_PYTHON=OFF" \
    sh scripts/build.sh
sh scripts/regenerate.sh
grep -q '"dummy"' assets/scene.schema.json
ctest --test-dir build --output-on-failure -j2 -L 'unit|gpu'
echo "check-new-kind: a dummy kind builds and passes the suite"
