"""Scenes written as Python programs (Scene.python, `sdfcsg convert OUT.py`, `sdfcsg generate
--emit python`): run, each program saves the JSON of the scene it was written from."""
import json
import os
import pathlib
import subprocess
import sys

import pytest

import sdfcsg

ROOT = pathlib.Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets" / "scenes"
CLI = os.environ.get("SDFCSG_CLI")


def run_program(program):
    """The scene that a program builds, run as the module's user would run it."""
    namespace = {"__name__": "scene_program"}
    exec(compile(program, "<program>", "exec"), namespace)
    return namespace["scene"]


def same_json(a, b):
    """The same JSON values. A definition's node keeps its members in the order they were
    written, which its program may not: the values are compared, not the text."""
    assert json.loads(a) == json.loads(b)


@pytest.mark.parametrize("path", sorted(ASSETS.glob("*.json")), ids=lambda p: p.stem)
def test_every_bundled_scene_as_a_program_builds_the_same_scene(path, monkeypatch):
    monkeypatch.chdir(ASSETS)  # the files that image and mesh nodes read
    scene = sdfcsg.load(str(path))
    program = scene.python()
    assert program.startswith("#") and "import sdfcsg as s" in program
    built = run_program(program).json()
    same_json(built, scene.json())
    if "definitions" not in json.loads(built):
        assert built == scene.json()


def kind_examples():
    """Every kind's example node, from the schema that the node table writes."""
    schema = json.loads((ROOT / "assets" / "scene.schema.json").read_text())
    for name, definition in schema["$defs"].items():
        if name != "use" and definition.get("properties", {}).get("type", {}).get("const") == name:
            yield name, definition["examples"][0]


@pytest.mark.parametrize("name,example", list(kind_examples()), ids=lambda v: v if isinstance(v, str) else "")
def test_every_kind_as_a_program_builds_its_example(name, example, monkeypatch):
    monkeypatch.chdir(ASSETS)
    try:
        scene = sdfcsg.loads(json.dumps({"version": 1, "root": example}))
    except sdfcsg.Error:  # a profile, which only extrude and revolve hold
        scene = sdfcsg.loads(json.dumps({"version": 1, "root": {
            "type": "extrude", "height": 1, "children": [example]}}))
    program = scene.python()
    assert f"s.{name}(" in program or f".{name}(" in program or f"s.{name}_(" in program
    same_json(run_program(program).json(), scene.json())


# Definitions in an order their uses do not follow, unused ones, names the program takes itself, a use inside a definition, "$name"
# values in place of a transform and a colour, a parameter named as a Python keyword, texts that
# need escapes, and every setting of the top level.
TRICKY = r"""{
  "version": 1,
  "name": "tricky \"one\"",
  "description": "a line\nand another, caf\u00e9",
  "camera": {"eye": [3, 2, 4], "target": [0, 0.5, 0], "fov": 35},
  "lights": [{"direction": [-1, -2, -1], "color": "#ffeedd", "intensity": 0.8}],
  "background": [0.1, 0.2, 0.3],
  "definitions": {
    "chair": {"node": {"type": "union", "children": [
      {"type": "use", "definition": "leg", "parameters": {"class": 0.5}, "translate": [0.3, 0, 0]},
      {"type": "use", "definition": "leg", "translate": [-0.3, 0, 0], "rotate": [0, 0, 10]}]}},
    "leg": {"parameters": {"class": 1.0, "where": [0, 0.5, 0], "tint": "#804020"},
            "node": {"type": "cylinder", "radius": 0.1, "height": "$class", "translate": "$where",
                     "color": "$tint"}},
    "s": {"node": {"type": "sphere", "radius": 0.2}},
    "len": {"node": {"type": "use", "definition": "s"}}
  },
  "root": {"type": "difference", "smooth": 0.05, "name": "a \\ name", "children": [
    {"type": "use", "definition": "chair", "scale": [1, 2, 1]},
    {"type": "extrude", "height": 0.1, "translate": [0, 0.5, 0.2], "scale": 0.5, "children": [
      {"type": "text", "text": "Hi \"there\"", "size": 0.3}]},
    {"type": "revolve", "children": [{"type": "circle", "radius": 0.1, "translate": [0.5, 0, 0]}]}
  ]}
}"""


def test_definitions_settings_and_escapes_as_a_program(tmp_path):
    scene = sdfcsg.loads(TRICKY)
    program = scene.python("tricky.json")
    assert 'leg = s.Part(' in program and '**{"class": 1}' in program
    assert program.index("leg = s.Part(") < program.index("chair = s.Part(")
    assert "s_ = s.Part(" in program and "parts=[chair, leg, s_, len_]" in program
    same_json(run_program(program).json(), scene.json())
    (tmp_path / "tricky.py").write_text(program)
    subprocess.run([sys.executable, "tricky.py"], cwd=tmp_path, check=True)
    same_json((tmp_path / "tricky.json").read_text(), scene.json())


def test_a_program_run_by_python_saves_the_scene(tmp_path):
    scene = sdfcsg.load(str(ASSETS / "table_and_chairs.json"))
    (tmp_path / "table.py").write_text(scene.python("table.json"))
    subprocess.run([sys.executable, "table.py"], cwd=tmp_path, check=True)
    subprocess.run([sys.executable, "table.py", "other.json"], cwd=tmp_path, check=True)
    same_json((tmp_path / "table.json").read_text(), scene.json())
    same_json((tmp_path / "other.json").read_text(), scene.json())


@pytest.mark.skipif(not CLI, reason="the command line was not built")
def test_convert_and_generate_emit_python(tmp_path):
    subprocess.run([CLI, "convert", str(ASSETS / "snowman.json"), "-o", "snowman.py"],
                   cwd=tmp_path, check=True)
    subprocess.run([sys.executable, "snowman.py"], cwd=tmp_path, check=True)
    assert (tmp_path / "snowman.json").read_text() == sdfcsg.load(str(ASSETS / "snowman.json")).json()

    # A recorded conversation, replayed: the program saves the scene that --emit json writes.
    llm = ["--base-url", "http://127.0.0.1:9/v1", "--model", "test-model",
           "--replay", str(ROOT / "tests" / "data" / "llm" / "snowman.recording.json")]
    env = dict(os.environ, no_proxy="127.0.0.1,localhost")
    subprocess.run([CLI, "generate", "A snowman", "-o", "snow.json"] + llm, cwd=tmp_path,
                   env=env, check=True)
    subprocess.run([CLI, "generate", "A snowman", "-o", "snow.py", "--emit", "python"] + llm,
                   cwd=tmp_path, env=env, check=True)
    generated = sdfcsg.load(str(tmp_path / "snow.json")).json()
    (tmp_path / "snow.json").unlink()
    subprocess.run([sys.executable, "snow.py"], cwd=tmp_path, check=True)
    assert (tmp_path / "snow.json").read_text() == generated
