"""Four parametric models built with the Python module (docs/python.md): a bracket with bolt
holes, a gear, a vase made by revolving its wall's profile, and a lattice cut to a sphere.
examples/models.cpp builds the same four in C++; the test `examples` holds the two to one JSON
each.

Usage: python3 examples/models.py FOLDER [--render]: writes FOLDER/NAME.json (and NAME.png)."""
import math
import pathlib
import sys

import sdfcsg as s


def bracket(width=3.0, thickness=0.3, hole=0.25):
    """An angle plate: a base and an upright blended together, two bolt holes through each."""
    base = s.round_box([width, thickness, 1.5], 0.05)
    upright = s.round_box([width, 1.5, thickness], 0.05).translate(0, 0.6, -0.6)
    bolt = s.cylinder(hole / 2, 1)
    holes = s.Shape()
    for x in (-width / 3, width / 3):
        holes = holes | bolt.translate(x, 0, 0.2) | bolt.rotate(90, 0, 0).translate(x, 0.8, -0.6)
    return s.difference(s.union(base, upright, smooth=0.15), holes).color("#7c8ea0").name("bracket")


def gear(teeth=18, radius=1.0, thickness=0.3):
    """A spur gear: a disc, teeth copied around it, a bore and a keyway."""
    tooth = 2 * math.pi * radius / teeth / 2
    disc = s.cylinder(radius, thickness)
    ring = s.box([0.25, thickness, tooth]).polar_repeat(teeth, radius + 0.1)
    bore = s.cylinder(0.25, 1) | s.box([0.1, 1, 0.1]).translate(0.28, 0, 0)
    return ((disc | ring) - bore).color("#c0a040").name("gear")


def vase(height=2.0, wall=0.06, samples=24):
    """A vase: the profile of its wall, a band that swells and narrows with height, turned about y."""
    outer, inner = [], []
    for i in range(samples + 1):
        t = i / samples
        y = t * height
        r = 0.45 + 0.25 * math.sin(3.0 * t + 0.4) - 0.1 * t
        outer.append([r, y])
        inner.insert(0, [r - wall, max(y, wall)])
    profile = [[0, 0]] + outer + inner + [[0, wall]]
    return s.polygon(profile).revolve().translate(0, -height / 2, 0).color("#3a7bd5").name("vase")


def lattice(cells=5, spacing=0.5, strut=0.06):
    """A cubic lattice of struts, cut to a sphere."""
    x = s.box([spacing, strut, strut])
    y = s.box([strut, spacing, strut])
    z = s.box([strut, strut, spacing])
    cell = s.union(x, y, z, smooth=0.02)
    grid = cell.repeat([cells] * 3, [spacing] * 3)
    return (grid & s.sphere(spacing * cells * 0.45)).color("#d05030").name("lattice")


def main():
    folder = pathlib.Path(sys.argv[1])
    folder.mkdir(parents=True, exist_ok=True)
    for name, shape in [("bracket", bracket()), ("gear", gear()), ("vase", vase()),
                        ("lattice", lattice())]:
        s.save(shape, str(folder / f"{name}.json"))
        if "--render" in sys.argv[2:]:
            (folder / f"{name}.png").write_bytes(shape._repr_png_())

if __name__ == "__main__":
    main()
