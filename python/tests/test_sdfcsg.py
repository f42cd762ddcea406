"""The Python module against the engine: every kind by its function is its table example, the
operators are the explicit operations, errors carry the loader's message and JSON path with the
line of Python that made the node, and renders, meshes and field values come back as NumPy arrays
of the documented shapes and types, equal between the CPU and the device."""
import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import sdfcsg

OUTPUT = pathlib.Path(os.environ.get("SDFCSG_TEST_OUTPUT_DIR", "/tmp/sdfcsg-python"))
ASSETS = pathlib.Path(__file__).resolve().parents[2] / "assets" / "scenes"


def scene_json(root):
    return json.dumps({"version": 1, "root": root})


def same(a, b):
    """Two shapes or scenes make one scene: the same JSON out."""
    ja = a.json() if isinstance(a, (sdfcsg.Shape, sdfcsg.Scene)) else a
    jb = b.json() if isinstance(b, (sdfcsg.Shape, sdfcsg.Scene)) else b
    assert ja == jb


def test_keyword_and_positional_arguments():
    expected = sdfcsg.loads(scene_json({"type": "cone", "radius": 0.5, "height": 1, "top_radius": 0.2}))
    same(sdfcsg.cone(0.5, 1, 0.2), expected)
    same(sdfcsg.cone(radius=0.5, height=1, top_radius=0.2), expected)
    same(sdfcsg.cone(0.5, height=1, top_radius=0.2), expected)
    with pytest.raises(TypeError):
        sdfcsg.cone(0.5, radius=0.5)


def test_operators_are_the_explicit_operations():
    a, b, c = sdfcsg.sphere(0.5), sdfcsg.box([0.6, 0.6, 0.6]).translate(0.3, 0, 0), sdfcsg.cylinder(0.2, 2)
    same(a | b | c, sdfcsg.union(a, b, c))
    same(a & b, sdfcsg.intersection([a, b]))
    same(a - b - c, sdfcsg.difference(a, b, c))
    same(sdfcsg.union(a, b, smooth=0.1, blend="round"),
         sdfcsg.loads(scene_json({"type": "union", "smooth": 0.1, "blend": "round", "children": [
             {"type": "sphere", "radius": 0.5},
             {"type": "box", "size": [0.6, 0.6, 0.6], "translate": [0.3, 0, 0]}]})))


def test_chained_operations_and_transforms():
    shape = sdfcsg.box([0.2, 1, 0.2]).translate(0.5, 0, 0).twist(30).mirror(axes="xz", smooth=0.1)
    shape = shape.shell(0.02).color("#ff8000").name("blades")
    expected = {"type": "shell", "name": "blades", "thickness": 0.02, "color": "#ff8000", "children": [
        {"type": "mirror", "axes": "xz", "smooth": 0.1, "children": [
            {"type": "twist", "angle": 30, "children": [
                {"type": "box", "size": [0.2, 1, 0.2], "translate": [0.5, 0, 0]}]}]}]}
    same(shape, sdfcsg.loads(scene_json(expected)))


def test_parts_are_definitions():
    leg = sdfcsg.Part("leg", sdfcsg.cylinder("$radius", "$height"), height=1.0, radius=0.1)
    table = sdfcsg.box([1, 0.1, 1]) | leg(height=0.5).translate(0.4, 0.2, 0.4) | leg()
    scene = table.scene()
    assert scene.node_count == 6  # the union, the box, and each use a union over its copy
    assert '"definitions"' in table.json()


def test_errors_carry_the_loaders_message_and_path():
    line = None
    with pytest.raises(sdfcsg.Error) as caught:
        line = 1 + __import__("inspect").currentframe().f_lineno
        bad = sdfcsg.sphere(1) | sdfcsg.box([1, -2, 1])
        bad.json()
    with pytest.raises(sdfcsg.Error) as loaded:
        sdfcsg.loads(scene_json({"type": "union", "children": [
            {"type": "sphere", "radius": 1}, {"type": "box", "size": [1, -2, 1]}]}))
    got, want = caught.value.diagnostics[0], loaded.value.diagnostics[0]
    assert got[1] == want[1] == "root.children[1].size[1]"
    assert got[2] == want[2]
    assert got[0] == f"{__file__}:{line}"
    assert caught.value.kind == "validation"
    assert str(caught.value) == f"{__file__}:{line}: root.children[1].size[1]: {want[2]}"


def test_load_save_and_edit(tmp_path):
    scene = sdfcsg.load(str(ASSETS / "csg_part.json"))
    path = tmp_path / "saved.json"
    sdfcsg.save(scene, str(path))
    same(sdfcsg.load(str(path)), scene)
    same(scene.shape(), scene.shape().scene())
    ball = sdfcsg.sphere(0.5).name("ball").scene()
    ball.set("ball", "radius", 0.7)
    same(ball, sdfcsg.sphere(0.7).name("ball"))
    with pytest.raises(sdfcsg.Error, match=r"root.radius: "):
        ball.set("ball", "radius", -1)
    with pytest.raises(sdfcsg.Error, match="missing.json: cannot read file"):
        sdfcsg.load(str(tmp_path / "missing.json"))


def test_every_kind_has_a_function_with_the_tables_doc():
    scene = sdfcsg.loads(scene_json({"type": "sphere", "radius": 1}))
    assert scene.node_count == 1
    for name in ["sphere", "round_box", "polar_repeat", "transition_linear", "extrude", "text"]:
        assert getattr(sdfcsg, name).__doc__.startswith(name + "(")
    assert "thickness" in sdfcsg.Shape.shell.__doc__


def test_render_returns_rgba_rows():
    image = sdfcsg.render(sdfcsg.sphere(1).color([0.9, 0.2, 0.1]), 64, 48,
                          camera={"eye": [0, 0, 4], "target": [0, 0, 0]})
    assert image.shape == (48, 64, 4) and image.dtype == np.uint8
    centre = image[24, 32]
    assert centre[0] > centre[2]  # the red sphere fills the middle
    png = sdfcsg.sphere(1)._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert sdfcsg._validation_messages() == 0


def test_mesh_arrays_and_saved_file(tmp_path):
    mesh = sdfcsg.mesh(sdfcsg.box([1, 1, 1]).color("#00ff00"), resolution=24)
    assert mesh.vertices.dtype == np.float32 and mesh.vertices.shape[1] == 3
    assert mesh.faces.dtype == np.uint32 and mesh.faces.shape[1] == 3
    assert mesh.colors.shape == mesh.vertices.shape
    assert np.all(np.abs(mesh.vertices) <= 0.5 + 1e-3)
    # Every edge used twice: closed.
    edges = np.sort(np.concatenate([mesh.faces[:, [0, 1]], mesh.faces[:, [1, 2]], mesh.faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
    path = tmp_path / "box.obj"
    mesh.save(str(path))
    vertices = [line for line in path.read_text().splitlines() if line.startswith("v ")]
    faces = [line for line in path.read_text().splitlines() if line.startswith("f ")]
    assert len(vertices) == len(mesh.vertices) and len(faces) == len(mesh.faces)
    simplified = sdfcsg.mesh(sdfcsg.box([1, 1, 1]), resolution=24, simplify=0.01)
    assert len(simplified.faces) < len(mesh.faces)


def test_evaluate_on_the_cpu_and_the_device():
    shape = sdfcsg.sphere(1) - sdfcsg.box([1, 1, 3]).color([0, 0, 1])
    rng = np.random.default_rng(3)
    points = rng.uniform(-1.5, 1.5, size=(5000, 3)).astype(np.float32)
    cpu = sdfcsg.evaluate(shape, points, device=False)
    assert cpu.shape == (5000,) and cpu.dtype == np.float32
    gpu, colors = sdfcsg.evaluate(shape, points, colors=True, device=True)
    assert colors.shape == (5000, 3)
    np.testing.assert_allclose(gpu, cpu, atol=1e-5)
    sphere = sdfcsg.evaluate(sdfcsg.sphere(1), points, device=False)
    np.testing.assert_allclose(sphere, np.linalg.norm(points, axis=1) - 1, atol=1e-6)
    with pytest.raises(ValueError):
        sdfcsg.evaluate(shape, np.zeros((4, 2), np.float32))


def test_progress_reports_and_stops():
    seen = []
    sdfcsg.render(sdfcsg.sphere(1), 64, 48, progress=seen.append)
    assert seen and seen[-1] == pytest.approx(1.0) and seen == sorted(seen)
    with pytest.raises(sdfcsg.Error) as stopped:
        sdfcsg.mesh(sdfcsg.sphere(1), resolution=32, progress=lambda done: False)
    assert stopped.value.kind == "cancelled"

    def fails(done):
        raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        sdfcsg.render(sdfcsg.sphere(1), 64, 48, progress=fails)


def test_numpy_is_imported_only_for_arrays():
    """Building, saving and loading shapes leaves NumPy out (its import is most of a first
    render's cost beyond the engine's); the first array brings it in."""
    code = """
import sys
import sdfcsg as s
shape = s.round_box([2, 1, 1], 0.1).color("#ff8000") - s.sphere(0.6).translate([0.5, 0.5, 0])
s.loads(shape.json())
assert "numpy" not in sys.modules, "imported by the modelling API"
image = s.render(shape, 32, 24)
assert type(image).__module__ == "numpy" and image.shape == (24, 32, 4)
"""
    subprocess.run([sys.executable, "-c", code], check=True)
    # NumPy's scalars are values as Python's numbers are, once NumPy is there.
    same(sdfcsg.sphere(np.float32(0.5)).translate(np.float64(1), 0, 0),
         sdfcsg.sphere(0.5).translate(1, 0, 0))
