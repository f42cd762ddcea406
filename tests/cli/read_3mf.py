#!/usr/bin/env python3
"""Reads a 3MF file with Python's own ZIP and XML readers and checks it against the PLY of the
same mesh (sdfcsg's binary PLY: x y z nx ny nz as floats, red green blue as bytes).

Usage: read_3mf.py MESH.3mf MESH.ply UNIT. Checks: the archive's CRCs, the content types and the
relationship to the model, the unit, every PLY vertex turned z up ((x, y, z) -> (x, -z, y)) and
every triangle, a closed mesh (each edge used once in each direction), and colour indices in
range. Colours come as a colour group with each corner's colour (p1, p2, p3), checked against
the PLY's vertex colours, or, for a mesh with a colour per triangle, as base materials with one
per triangle (p1 alone), each one of the PLY's vertex colours. Prints one line of counts; exits
1 with a message on the first failure."""
import struct
import sys
import xml.etree.ElementTree as ET
import zipfile

CORE = "{http://schemas.microsoft.com/3dmanufacturing/core/2015/02}"
MAT = "{http://schemas.microsoft.com/3dmanufacturing/material/2015/02}"


def fail(message):
    print("read_3mf: " + message)
    sys.exit(1)


def single(text):
    """The float32 nearest the decimal text: what a reader in single precision gets."""
    return struct.unpack("<f", struct.pack("<f", float(text)))[0]


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().split("\n")
    vertices = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    faces = int(next(l for l in header if l.startswith("element face")).split()[2])
    points, colours, triangles = [], [], []
    at = end
    for _ in range(vertices):
        x, y, z, _nx, _ny, _nz, r, g, b = struct.unpack_from("<6f3B", data, at)
        at += 27
        points.append((x, y, z))
        colours.append("#%02X%02X%02X" % (r, g, b))
    for _ in range(faces):
        n, a, b, c = struct.unpack_from("<B3I", data, at)
        at += 13
        triangles.append((a, b, c))
    return points, colours, triangles


def main():
    path, ply, unit = sys.argv[1:4]
    archive = zipfile.ZipFile(path)
    if archive.testzip() is not None:
        fail("a CRC does not match")
    types = ET.fromstring(archive.read("[Content_Types].xml"))
    if not any(d.get("Extension") == "model" and
               d.get("ContentType") == "application/vnd.ms-package.3dmanufacturing-3dmodel+xml"
               for d in types):
        fail("no content type for .model")
    rels = ET.fromstring(archive.read("_rels/.rels"))
    targets = [r.get("Target") for r in rels
               if r.get("Type") == "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"]
    if len(targets) != 1:
        fail("expected one 3D model relationship, got %d" % len(targets))
    model = ET.fromstring(archive.read(targets[0].lstrip("/")))
    if model.get("unit") != unit:
        fail("unit %s, expected %s" % (model.get("unit"), unit))
    objects = model.findall("%sresources/%sobject" % (CORE, CORE))
    items = model.findall("%sbuild/%sitem" % (CORE, CORE))
    if len(objects) != 1 or len(items) != 1 or items[0].get("objectid") != objects[0].get("id"):
        fail("expected one object and one build item naming it")
    mesh = objects[0].find(CORE + "mesh")
    vertices = [(single(v.get("x")), single(v.get("y")), single(v.get("z")))
                for v in mesh.find(CORE + "vertices")]
    materials = model.find("%sresources/%sbasematerials" % (CORE, CORE))
    group = model.find("%sresources/%scolorgroup" % (CORE, MAT))
    per_triangle = materials is not None
    if per_triangle:
        if materials.get("id") != objects[0].get("pid") or group is not None:
            fail("the object's base materials are missing, or a colour group is there too")
        colours = [b.get("displaycolor") for b in materials]
        if any(b.get("name") is None for b in materials):
            fail("a base material without a name")
        triangles = []
        for t in mesh.find(CORE + "triangles"):
            if t.get("p2") is not None or t.get("p3") is not None:
                fail("a triangle of one base material names p2 or p3")
            p = int(t.get("p1"))
            triangles.append((int(t.get("v1")), int(t.get("v2")), int(t.get("v3")), p, p, p))
    else:
        if group is None or group.get("id") != objects[0].get("pid"):
            fail("the object's colour group is missing")
        colours = [c.get("color") for c in group]
        triangles = [(int(t.get("v1")), int(t.get("v2")), int(t.get("v3")),
                      int(t.get("p1")), int(t.get("p2")), int(t.get("p3")))
                     for t in mesh.find(CORE + "triangles")]

    points, ply_colours, ply_triangles = read_ply(ply)
    if len(vertices) != len(points):
        fail("%d vertices, the PLY has %d" % (len(vertices), len(points)))
    for i, ((x, y, z), v) in enumerate(zip(points, vertices)):
        if v != (x, -z if z != 0 else 0.0, y):
            fail("vertex %d is %s, expected %s turned z up" % (i, v, (x, y, z)))
    kept = [t for t in ply_triangles if len(set(t)) == 3]
    if [t[:3] for t in triangles] != kept:
        fail("the triangles differ from the PLY's")
    edges = set()
    for t in triangles:
        for k in range(3):
            if not 0 <= t[3 + k] < len(colours):
                fail("colour index %d out of range" % t[3 + k])
            if not per_triangle and colours[t[3 + k]] != ply_colours[t[k]]:
                fail("vertex %d has colour %s, the PLY %s" % (t[k], colours[t[3 + k]],
                                                             ply_colours[t[k]]))
            edge = (t[k], t[(k + 1) % 3])
            if edge in edges:
                fail("edge %s is used twice in one direction" % (edge,))
            edges.add(edge)
    if any((b, a) not in edges for a, b in edges):
        fail("the mesh is not closed")
    if per_triangle:
        if len(set(colours)) != len(colours):
            fail("a colour has two base materials")
        used = set(t[3] for t in triangles)
        for i, colour in enumerate(colours):
            if i not in used:
                fail("base material %d (%s) colours no triangle" % (i, colour))
            if colour not in ply_colours:
                fail("base material %s is the colour of no vertex" % colour)
    zs = [v[2] for v in vertices]
    print("3mf: %d vertices, %d triangles, %d colours %s, z from %g to %g" %
          (len(vertices), len(triangles), len(colours),
           "per triangle" if per_triangle else "per corner", min(zs), max(zs)))


main()
