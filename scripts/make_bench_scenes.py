#!/usr/bin/env python3
# Writes the benchmark scenes of thousands of primitives into assets/bench/ (seeded, so the same
# files every run): molecule_1k, groups_1k, flat_4k and forest_10k. Run from the repository root:
#   python3 scripts/make_bench_scenes.py
import json
import math
import os
import random

OUT = os.path.join(os.path.dirname(__file__), "..", "assets", "bench")
COLORS = ["#d94a4a", "#4a90d9", "#e8c547", "#5bb85b", "#b070d0", "#e0883a", "#cfcfcf"]


def r4(x):
    return round(x, 4)


def vec(v):
    return [r4(c) for c in v]


def primitive(rng, kind, size):
    """A primitive of `kind` about `size` across, randomly rotated."""
    s = lambda: size * rng.uniform(0.6, 1.0)
    n = {"type": kind}
    if kind == "sphere":
        n["radius"] = r4(0.5 * s())
    elif kind == "box":
        n["size"] = vec([s(), s(), s()])
    elif kind == "round_box":
        b = [s(), s(), s()]
        n["size"] = vec(b)
        n["radius"] = r4(0.2 * min(b))
    elif kind == "triangular_prism":
        n.update(width=r4(s()), height=r4(s()), length=r4(s()))
    elif kind == "torus":
        major = 0.35 * s()
        n.update(major_radius=r4(major), minor_radius=r4(0.35 * major))
    elif kind == "cylinder":
        n.update(radius=r4(0.4 * s()), height=r4(s()))
    elif kind == "cone":
        n.update(radius=r4(0.45 * s()), height=r4(s()), top_radius=r4(0.15 * s()))
    else:  # capsule
        h = 0.35 * s()
        n.update(a=[0, r4(-h), 0], b=[0, r4(h), 0], radius=r4(0.25 * s()))
    n["rotate"] = vec([rng.uniform(-180, 180) for _ in range(3)])
    return n


KINDS = ["sphere", "box", "round_box", "triangular_prism", "torus", "cylinder", "cone", "capsule"]


def molecule(rng):
    spheres, p = [], [0.0, 0.0, 0.0]
    for i in range(1000):
        while True:
            d = [rng.gauss(0, 1) for _ in range(3)]
            length = math.sqrt(sum(c * c for c in d)) or 1.0
            step = rng.uniform(0.03, 0.04)
            q = [p[j] + d[j] / length * step for j in range(3)]
            if math.sqrt(sum(c * c for c in q)) < 0.95:
                break
        p = q
        spheres.append({"type": "sphere", "radius": r4(rng.uniform(0.025, 0.035)),
                        "translate": vec(p), "color": rng.choice(COLORS[:4])})
    return {"version": 1, "name": "molecule_1k",
            "description": "A chain of 1,000 atoms along a random walk, one smooth union.",
            "root": {"type": "union", "smooth": 0.026, "children": spheres}}


def groups(rng):
    out = []
    for g in range(100):
        c = [rng.uniform(-5, 5), rng.uniform(-1, 1), rng.uniform(-5, 5)]
        members = []
        for i in range(10):
            n = primitive(rng, KINDS[i % len(KINDS)], rng.uniform(0.1, 0.5))
            n["translate"] = vec([c[j] + rng.uniform(-0.3, 0.3) for j in range(3)])
            members.append(n)
        out.append({"type": "union", "smooth": r4(rng.uniform(0.05, 0.15)),
                    "color": COLORS[g % len(COLORS)], "children": members})
    return {"version": 1, "name": "groups_1k",
            "description": "100 smooth unions of 10 mixed primitives each.",
            "root": {"type": "union", "children": out}}


def flat(rng):
    out = []
    for i in range(4000):
        n = primitive(rng, KINDS[i % len(KINDS)], rng.uniform(0.04, 0.2))
        n["translate"] = vec([rng.uniform(-2, 2), rng.uniform(-0.5, 0.5), rng.uniform(-2, 2)])
        n["color"] = COLORS[i % len(COLORS)]
        out.append(n)
    return {"version": 1, "name": "flat_4k",
            "description": "4,000 random primitives of every bounded kind, one sharp union.",
            "root": {"type": "union", "children": out}}


def tree(rng, x, z):
    h = rng.uniform(0.8, 1.4)
    parts = [{"type": "cylinder", "radius": r4(rng.uniform(0.05, 0.08)), "height": r4(h),
              "translate": [0, r4(h / 2), 0], "color": "#7a5230"}]
    for i in range(rng.randint(3, 5)):
        s = rng.uniform(0.25, 0.45)
        parts.append({"type": "round_box", "size": vec([s, s, s]), "radius": r4(0.3 * s),
                      "translate": vec([rng.uniform(-0.2, 0.2), h + rng.uniform(-0.1, 0.4),
                                        rng.uniform(-0.2, 0.2)]),
                      "rotate": vec([0, rng.uniform(0, 90), 0]), "color": "#3f8f3f"})
    return {"type": "union", "smooth": 0.1, "translate": vec([x, 0.1, z]), "children": parts}


def house(rng, x, z):
    w, d, h = rng.uniform(1.0, 1.6), rng.uniform(1.0, 1.6), rng.uniform(0.8, 1.1)
    body = {"type": "union", "children": [
        {"type": "box", "size": vec([w, h, d]), "translate": [0, r4(h / 2), 0], "color": "#e6d3a8"},
        {"type": "triangular_prism", "width": r4(w * 1.15), "height": r4(0.5 * h),
         "length": r4(d * 1.1), "rotate": [0, 90, 0], "translate": [0, r4(h * 1.25), 0],
         "color": "#b84030"}]}
    holes = [{"type": "box", "size": [0.25, r4(0.55 * h), 0.2],
              "translate": [0, r4(0.28 * h), r4(d / 2)], "color": "#5a3a20"}]
    for i in range(rng.randint(3, 5)):
        side = rng.choice([-1, 1])
        holes.append({"type": "box", "size": [0.22, 0.22, 0.2],
                      "translate": vec([rng.uniform(-0.35, 0.35) * w, 0.6 * h,
                                        side * d / 2]), "color": "#304870"})
    return {"type": "difference", "translate": vec([x, 0.1, z]),
            "rotate": [0, r4(rng.uniform(0, 360)), 0], "children": [body] + holes}


def forest(rng):
    rows, count = [], 1
    n = 43
    for i in range(n):
        row = []
        for j in range(n):
            x = (i - n / 2 + rng.uniform(0.1, 0.9)) * 1.6
            z = (j - n / 2 + rng.uniform(0.1, 0.9)) * 1.6
            if rng.random() < 0.3:
                row.append(house(rng, x, z))
            else:
                row.append(tree(rng, x, z))
        rows.append({"type": "union", "children": row})
    ground = {"type": "box", "size": [72, 0.2, 72], "color": "#6a9a50"}
    return {"version": 1, "name": "forest_10k",
            "description": "Trees and houses with windows and doors on a ground box.",
            "root": {"type": "union", "children": [ground] + rows}}


def count(node):
    kids = node.get("children", [])
    return (1 + sum(count(c)[0] for c in kids), (0 if kids or node["type"] in
            ("union", "intersection", "difference") else 1) + sum(count(c)[1] for c in kids))


def main():
    os.makedirs(OUT, exist_ok=True)
    for make, seed in ((molecule, 1), (groups, 2), (flat, 3), (forest, 4)):
        scene = make(random.Random(seed))
        path = os.path.join(OUT, scene["name"] + ".json")
        with open(path, "w") as f:
            json.dump(scene, f, separators=(",", ":"))
            f.write("\n")
        nodes, prims = count(scene["root"])
        print(f"{path}: {nodes} nodes, {prims} primitives, {os.path.getsize(path)} bytes")


if __name__ == "__main__":
    main()
