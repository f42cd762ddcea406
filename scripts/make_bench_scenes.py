#!/usr/bin/env python3
# Writes four seeded benchmark scenes (molecule_1k, groups_1k, flat_4k, forest_10k) into assets/bench/.
# Run from anywhere: python3 scripts/make_bench_scenes.py  (standard library only; same files every run)
import json
import math
import os
import random
import re

OUT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "assets", "bench"))

# Bounded primitive kinds (plane is unbounded and never used here).
KINDS = ["sphere", "box", "round_box", "triangular_prism", "torus", "cylinder", "cone", "capsule"]
OPERATIONS = ("union", "intersection", "difference")
PALETTE = ["#d94a4a", "#4a90d9", "#e8c547", "#5bb85b", "#b070d0", "#e0883a", "#cfcfcf", "#40b0b0"]

# ---------------------------------------------------------------- numbers and JSON output


def num(x, digits=4):
    """x rounded to `digits` decimals; whole values as ints so they print short."""
    x = round(x, digits)
    return int(x) if x == int(x) else x


def vec(v, digits=4):
    return [num(c, digits) for c in v]


def angles(rng):
    return vec([rng.uniform(-180, 180) for _ in range(3)], 1)


def dump_node(node, out):
    """One node per line: an operation's own keys, then its children each on their own line(s)."""
    if "children" not in node:
        out.append(json.dumps(node, separators=(",", ":")))
        return
    head = {k: v for k, v in node.items() if k != "children"}
    out.append(json.dumps(head, separators=(",", ":"))[:-1] + ',"children":[')
    for i, child in enumerate(node["children"]):
        dump_node(child, out)
        if i + 1 < len(node["children"]):
            out[-1] += ","
    out[-1] += "]}"


def dump_scene(scene):
    """Compact JSON, the scene's own keys and the root on the first line, then one node a line."""
    head = {k: v for k, v in scene.items() if k != "root"}
    out = []
    dump_node(scene["root"], out)
    out[0] = json.dumps(head, separators=(",", ":"))[:-1] + ',"root":' + out[0]
    out[-1] += "}"
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------- primitives


def primitive(rng, kind, size):
    """A primitive of `kind` whose extent is about `size`, randomly rotated (no translate yet)."""
    s = lambda lo=0.5, hi=1.0: size * rng.uniform(lo, hi)
    n = {"type": kind}
    if kind == "sphere":
        n["radius"] = num(0.5 * s(0.8))
    elif kind == "box":
        n["size"] = vec([s(), s(), s()])
    elif kind == "round_box":
        n["size"] = vec([s(), s(), s()])
        n["radius"] = num(rng.uniform(0.1, 0.3) * min(n["size"]))
    elif kind == "triangular_prism":
        n.update(width=num(s()), height=num(s()), length=num(s()))
    elif kind == "torus":
        major = 0.5 * s(0.5, 0.75)
        n.update(major_radius=num(major), minor_radius=num(major * rng.uniform(0.2, 0.4)))
    elif kind == "cylinder":
        n.update(radius=num(0.5 * s(0.4, 0.9)), height=num(s()))
    elif kind == "cone":
        radius = 0.5 * s()
        n.update(radius=num(radius), height=num(s(0.6)))
        if rng.random() < 0.5:
            n["top_radius"] = num(radius * rng.uniform(0.1, 0.5))
    else:  # capsule, along y before rotation
        radius = 0.5 * s(0.3, 0.5)
        h = max(0.5 * s(0.6) - radius, 0.25 * radius)
        n.update(a=[0, num(-h), 0], b=[0, num(h), 0], radius=num(radius))
    n["rotate"] = angles(rng)
    return n


# ---------------------------------------------------------------- scenes


def molecule(rng):
    """1,000 atoms along a random-walk chain inside the ball of radius 0.95, one smooth union."""
    atoms = [("#404040", 4), ("#d94a4a", 2), ("#4a6ad9", 2), ("#e8e8e8", 3), ("#e8c547", 1)]
    colors = [c for c, w in atoms for _ in range(w)]
    spheres, p = [], [0.0, 0.0, 0.0]
    for i in range(1000):
        if i:
            while True:  # resample any step that would leave the ball
                d = [rng.gauss(0, 1) for _ in range(3)]
                length = math.sqrt(sum(c * c for c in d)) or 1.0
                step = rng.uniform(0.03, 0.04)
                q = [p[j] + d[j] / length * step for j in range(3)]
                if math.sqrt(sum(c * c for c in q)) <= 0.95:
                    break
            p = q
        spheres.append({"type": "sphere", "radius": num(rng.uniform(0.025, 0.035)),
                        "translate": vec(p), "color": rng.choice(colors)})
    return {"version": 1, "name": "molecule_1k",
            "description": "A chain of 1,000 atom spheres along a random walk in the unit ball, "
                           "all blended by one smooth union.",
            "root": {"type": "union", "name": "chain", "smooth": 0.026, "children": spheres}}


def groups(rng):
    """100 well separated smooth unions of 10 mixed primitives each, under one sharp union."""
    centres = []
    while len(centres) < 100:  # dart throwing: centres at least 1.0 apart
        c = [rng.uniform(-5, 5), rng.uniform(-1, 1), rng.uniform(-5, 5)]
        if all(sum((c[j] - o[j]) ** 2 for j in range(3)) >= 1.0 for o in centres):
            centres.append(c)
    out = []
    for g, c in enumerate(centres):
        kinds = KINDS + [rng.choice(KINDS), rng.choice(KINDS)]
        rng.shuffle(kinds)
        palette = rng.sample(PALETTE, 2)
        members = []
        for kind in kinds:
            n = primitive(rng, kind, rng.uniform(0.05, 0.25))
            n["translate"] = vec([c[j] + rng.uniform(-0.25, 0.25) for j in range(3)])
            n["color"] = rng.choice(palette)
            members.append(n)
        out.append({"type": "union", "name": f"group_{g:03d}",
                    "smooth": num(rng.uniform(0.05, 0.15)), "children": members})
    return {"version": 1, "name": "groups_1k",
            "description": "100 separated smooth unions of 10 mixed, rotated primitives each, "
                           "joined by one sharp union.",
            "root": {"type": "union", "name": "groups", "children": out}}


def flat(rng):
    """4,000 primitives of every bounded kind under one sharp union."""
    kinds = [KINDS[i % len(KINDS)] for i in range(4000)]
    rng.shuffle(kinds)
    out = []
    for kind in kinds:
        n = primitive(rng, kind, rng.uniform(0.02, 0.1))
        n["translate"] = vec([rng.uniform(-2, 2), rng.uniform(-0.5, 0.5), rng.uniform(-2, 2)])
        n["color"] = rng.choice(PALETTE)
        out.append(n)
    return {"version": 1, "name": "flat_4k",
            "description": "4,000 small random primitives of all eight bounded kinds in a flat "
                           "slab, one sharp union.",
            "root": {"type": "union", "name": "all", "children": out}}


TRUNK, LEAVES = "#7a5230", ["#3f8f3f", "#2f7a3a", "#5a9a35", "#4c8a4c"]
WALLS, ROOFS = ["#e6d3a8", "#d8c0a0", "#f0ece0", "#c9b48a"], ["#b84030", "#8a3a2a", "#606870"]
WINDOW, DOOR = "#304870", "#5a3a20"


def tree(rng, x, z):
    """A smooth union of a cylinder trunk and 3-5 rounded boxes / spheres as canopy."""
    h = rng.uniform(0.5, 0.9)
    parts = [{"type": "cylinder", "radius": num(rng.uniform(0.04, 0.07)), "height": num(h),
              "translate": [0, num(h / 2), 0], "color": TRUNK}]
    leaves = rng.choice(LEAVES)
    for _ in range(rng.randint(3, 5)):
        s = rng.uniform(0.25, 0.45)
        t = vec([rng.uniform(-0.15, 0.15), h + rng.uniform(-0.05, 0.3), rng.uniform(-0.15, 0.15)])
        if rng.random() < 0.5:
            b = vec([s * rng.uniform(0.8, 1.0) for _ in range(3)])
            parts.append({"type": "round_box", "size": b, "radius": num(0.3 * min(b)),
                          "translate": t, "rotate": vec([0, rng.uniform(0, 90), 0], 1),
                          "color": leaves})
        else:
            parts.append({"type": "sphere", "radius": num(0.5 * s), "translate": t,
                          "color": leaves})
    return {"type": "union", "smooth": 0.1, "translate": vec([x, 0, z]),
            "scale": num(rng.uniform(0.85, 1.15), 3), "children": parts}


def house(rng, x, z):
    """A difference: (box body + triangular_prism roof) minus a door and 2-5 windows."""
    w, d, h = rng.uniform(0.6, 0.9), rng.uniform(0.6, 0.9), rng.uniform(0.45, 0.65)
    roof = rng.uniform(0.25, 0.4)
    body = {"type": "union", "children": [
        {"type": "box", "size": vec([w, h, d]), "translate": [0, num(h / 2), 0],
         "color": rng.choice(WALLS)},
        {"type": "triangular_prism", "width": num(w * 1.15), "height": num(roof),
         "length": num(d * 1.1), "translate": [0, num(h + roof / 2), 0],
         "color": rng.choice(ROOFS)}]}
    door_x = rng.uniform(-0.25, 0.25) * w
    holes = [{"type": "box", "size": [0.16, 0.3, 0.1], "translate": vec([door_x, 0.15, d / 2]),
              "color": DOOR}]
    for _ in range(rng.randint(2, 5)):
        y = h * rng.uniform(0.55, 0.7)
        face = rng.randrange(4)  # 0 front (+z, beside the door), 1 back, 2 and 3 the sides
        if face < 2:
            u = rng.uniform(0.15, 0.35) * w * rng.choice([-1, 1])
            if face == 0:  # front windows go on the other side of the door
                u = math.copysign(u, -door_x)
            holes.append({"type": "box", "size": [0.14, 0.14, 0.1],
                          "translate": vec([u, y, d / 2 if face == 0 else -d / 2]),
                          "color": WINDOW})
        else:
            u = rng.uniform(-0.3, 0.3) * d
            holes.append({"type": "box", "size": [0.1, 0.14, 0.14],
                          "translate": vec([w / 2 if face == 2 else -w / 2, y, u]),
                          "color": WINDOW})
    return {"type": "difference", "translate": vec([x, 0, z]),
            "rotate": [0, num(rng.uniform(0, 360), 1), 0], "children": [body] + holes}


def forest(rng):
    """A 60 x 60 ground box with a jittered 43 x 43 grid of trees (75 %) and houses (25 %),
    grouped as root > bands of rows > rows > tree or house."""
    n, spacing, band = 43, 1.36, 6
    bands, rows = [], []
    for i in range(n):
        row = []
        for j in range(n):
            x = (i - (n - 1) / 2 + rng.uniform(-0.15, 0.15)) * spacing
            z = (j - (n - 1) / 2 + rng.uniform(-0.15, 0.15)) * spacing
            row.append(house(rng, x, z) if rng.random() < 0.25 else tree(rng, x, z))
        rows.append({"type": "union", "name": f"row_{i:02d}", "children": row})
        if len(rows) == band or i == n - 1:
            bands.append({"type": "union", "name": f"band_{len(bands)}", "children": rows})
            rows = []
    ground = {"type": "box", "name": "ground", "size": [60, 0.2, 60], "translate": [0, -0.1, 0],
              "color": "#6a9a50"}
    return {"version": 1, "name": "forest_10k",
            "description": "A village of trees and houses with cut-out windows and doors on a "
                           "jittered 43 x 43 grid over a ground box, about 10,000 primitives.",
            "root": {"type": "union", "name": "forest", "children": [ground] + bands}}


# ---------------------------------------------------------------- checks

# Allowed keys, copied from assets/scene.schema.json (format version 1).
TOP_KEYS = {"version", "name", "description", "camera", "lights", "background", "root"}
COMMON_KEYS = {"type", "name", "translate", "rotate", "scale", "color"}
FIELDS = {
    "sphere": {"radius"},
    "box": {"size"},
    "round_box": {"size", "radius"},
    "plane": {"normal", "offset"},
    "triangular_prism": {"width", "height", "length"},
    "torus": {"major_radius", "minor_radius"},
    "cylinder": {"radius", "height"},
    "cone": {"radius", "height", "top_radius"},
    "capsule": {"a", "b", "radius"},
    "union": {"children", "smooth"},
    "intersection": {"children", "smooth"},
    "difference": {"children", "smooth"},
}
REQUIRED = {
    "sphere": {"radius"}, "box": {"size"}, "round_box": {"size", "radius"},
    "triangular_prism": {"width", "height", "length"}, "torus": {"major_radius", "minor_radius"},
    "cylinder": {"radius", "height"}, "cone": {"radius", "height"},
    "capsule": {"a", "b", "radius"}, "union": {"children"}, "intersection": {"children"},
    "difference": {"children"},
}
POSITIVE = {"radius", "width", "height", "length", "major_radius", "minor_radius", "scale"}
NON_NEGATIVE = {"top_radius", "smooth"}
VEC3 = {"translate", "rotate", "a", "b"}
COLOR = re.compile(r"^#[0-9a-fA-F]{6}$")


def is_num(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def check_node(node, path, depth, stats):
    assert isinstance(node, dict), path
    kind = node.get("type")
    assert kind in FIELDS and kind != "plane", f"{path}: bad or unbounded type {kind!r}"
    extra = set(node) - COMMON_KEYS - FIELDS[kind]
    assert not extra, f"{path}: keys not allowed for {kind}: {sorted(extra)}"
    missing = REQUIRED[kind] - set(node)
    assert not missing, f"{path}: missing {sorted(missing)}"
    for k, v in node.items():
        if k in POSITIVE:
            assert is_num(v) and v > 0, f"{path}.{k}: {v!r}"
        elif k in NON_NEGATIVE:
            assert is_num(v) and v >= 0, f"{path}.{k}: {v!r}"
        elif k in VEC3:
            assert isinstance(v, list) and len(v) == 3 and all(map(is_num, v)), f"{path}.{k}"
        elif k == "size":
            assert isinstance(v, list) and len(v) == 3 and all(is_num(c) and c > 0 for c in v), path
        elif k == "color":
            assert isinstance(v, str) and COLOR.match(v), f"{path}.color: {v!r}"
        elif k == "name":
            assert isinstance(v, str) and len(v) <= 200, path
    if kind == "round_box":
        assert node["radius"] <= 0.5 * min(node["size"]), f"{path}: rounding too large"
    stats["nodes"] += 1
    stats["depth"] = max(stats["depth"], depth)
    if kind in OPERATIONS:
        kids = node["children"]
        assert isinstance(kids, list) and kids, f"{path}: empty children"
        for i, child in enumerate(kids):
            check_node(child, f"{path}.children[{i}]", depth + 1, stats)
    else:
        stats["primitives"] += 1


def check_scene(scene):
    """Walks a loaded scene; returns (nodes, primitives, depth in node levels)."""
    extra = set(scene) - TOP_KEYS
    assert not extra, f"top-level keys not allowed: {sorted(extra)}"
    assert scene.get("version") == 1 and "root" in scene and "camera" not in scene
    assert isinstance(scene.get("name"), str) and isinstance(scene.get("description"), str)
    stats = {"nodes": 0, "primitives": 0, "depth": 0}
    check_node(scene["root"], "root", 1, stats)
    assert stats["nodes"] <= 16384, "over the loader's node limit"
    assert stats["depth"] <= 10, "nested deeper than 10 levels"
    return stats["nodes"], stats["primitives"], stats["depth"]


# ---------------------------------------------------------------- main


def main():
    os.makedirs(OUT, exist_ok=True)
    expected = {"molecule_1k": (1001, 1000), "groups_1k": (1101, 1000), "flat_4k": (4001, 4000)}
    for make, seed in ((molecule, 1), (groups, 2), (flat, 3), (forest, 4)):
        scene = make(random.Random(seed))
        path = os.path.join(OUT, scene["name"] + ".json")
        with open(path, "w", newline="\n") as f:
            f.write(dump_scene(scene))
        with open(path) as f:
            loaded = json.load(f)  # the file parses and holds exactly what was built
        assert loaded == scene, path
        nodes, prims, depth = check_scene(loaded)
        if scene["name"] in expected:
            assert (nodes, prims) == expected[scene["name"]], (scene["name"], nodes, prims)
        else:
            assert 9500 <= prims <= 10500, f"forest has {prims} primitives"
        size = os.path.getsize(path)
        assert size < 2_000_000, f"{path} is {size} bytes"
        print(f"{os.path.relpath(path)}: {nodes} nodes, {prims} primitives, depth {depth}, "
              f"{size} bytes")


if __name__ == "__main__":
    main()
