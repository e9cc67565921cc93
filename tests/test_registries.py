"""The attribute, resource and format registries: one place each, and one read of a mesh file per check.

Issue 27's problems, reproduced first: ``mtllib lib#1.mtl`` read as ``lib`` by Q902
alone, four readers of one big OBJ, formats listed in six places, a rule on a
normal map that the cache and Q902 would not see.
"""

from __future__ import annotations

import builtins
import io
import json
import os
import re
import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from affinity import cli
from affinity.attributes import ATTRIBUTES, attribute_named, canonical_name
from affinity.lint import lint_mesh, scored_codes
from affinity.loaders import load
from affinity.loaders.formats import LOADERS, MESH_SUFFIXES, hook_pattern
from affinity.loaders.resources import ResourceRole, register_role, unregister_role
from affinity.measures import texels
from affinity.output import FORMATS
from affinity.pipeline import check as check_module
from affinity.pipeline.cache import ResultCache
from affinity.pipeline.check import check_file, check_files
from affinity.rules import RULES, Measured, rule, unregister
from affinity.settings import Settings

ROOT = Path(__file__).resolve().parents[1]
#: A unit-square uv on a trapezoid: the split misplaces the texture (Q101 at the default threshold).
TRAPEZOID_OBJ = """v 0 0 0
v 4 0 0
v 3 1 0
v 1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 2/2 3/3 4/4
"""


def png_header(width: int, height: int) -> bytes:
    """The first bytes of a PNG: enough for the texel unit, which reads only the image size."""
    return b"\x89PNG\r\n\x1a\n" + struct.pack(">I4sII", 13, b"IHDR", width, height) + b"\x08\x02\x00\x00\x00"


def grid_obj(n: int, header: str = "") -> str:
    """An n x n grid of unit quads with per-corner uv (a v/vt face per quad), after ``header``."""
    j, i = np.mgrid[0 : n + 1, 0 : n + 1]
    vertices = "".join(f"v {x} {y} 0\n" for x, y in zip(i.ravel(), j.ravel()))
    uvs = "".join(f"vt {x / n} {y / n}\n" for x, y in zip(i.ravel(), j.ravel()))
    a = (j[:-1, :-1] * (n + 1) + i[:-1, :-1] + 1).ravel()
    quads = np.stack([a, a + 1, a + n + 2, a + n + 1], axis=1)
    faces = "".join("f " + " ".join(f"{k}/{k}" for k in quad) + "\n" for quad in quads.tolist())
    return header + vertices + uvs + faces


def run_cli(args: list[str], capsys) -> tuple[int, str, str]:
    code = cli.main(args)
    out, err = capsys.readouterr()
    return code, out, err


# -- one spelling per attribute ---------------------------------------------------------------------


def test_every_command_names_an_attribute_one_way_and_takes_its_alias(tmp_path, capsys):
    assert [a.name for a in ATTRIBUTES.values()] == ["uv", "color", "normal"]
    assert canonical_name("colour") == "color" and attribute_named("colour") is ATTRIBUTES["colors"]
    parser = cli.build_parser()
    for command, option in (("render", "--show"), ("view", "--attribute")):
        choices = next(a.choices for a in parser._subparsers._group_actions[0].choices[command]._actions
                       if option in a.option_strings)
        assert {a.name for a in ATTRIBUTES.values()} <= set(choices), (command, choices)
        assert "colour" not in choices
    mesh = tmp_path / "square.obj"
    mesh.write_text("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 0 0 0\nf 1 2 3 4\n")
    code, _, err = run_cli(["render", str(mesh), "-o", str(tmp_path / "a.png"), "--show", "colour", "-q",
                            "--size", "16x16"], capsys)
    assert code == 0, err
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# -- resources: one reader --------------------------------------------------------------------------


def test_an_mtllib_named_with_a_hash_is_found_and_a_comment_still_ends_the_name(tmp_path, capsys):
    (tmp_path / "lib#1.mtl").write_text("newmtl m\n")
    mesh = tmp_path / "a.obj"
    mesh.write_text("mtllib lib#1.mtl\n" + TRAPEZOID_OBJ)
    code, out, err = run_cli(["check", "--no-cache", "--select", "Q902", str(mesh)], capsys)
    assert (code, out.count("Q902"), err) == (0, 0, "")
    # A word starting with '#' starts a comment, as the loader reads every statement.
    mesh.write_text("mtllib lib #1.mtl\n" + TRAPEZOID_OBJ)
    code, out, _ = run_cli(["check", "--no-cache", "--select", "Q902", str(mesh)], capsys)
    assert "a.obj:1:1: Q902 info missing-resource:" in out and out.rstrip().count("mtllib lib not found") == 1


class OpenCounter:
    """``builtins.open`` and ``os.open`` (regular files are opened by descriptor, :mod:`affinity.loaders.regular`)
    that count the opens of one file."""

    def __init__(self, path: Path, monkeypatch):
        self.path = os.path.abspath(path)
        self.opens = 0

        def counting(real):
            def counting_open(file, *args, **kwargs):
                if isinstance(file, (str, os.PathLike)) and os.path.abspath(os.fspath(file)) == self.path:
                    self.opens += 1
                return real(file, *args, **kwargs)
            return counting_open

        monkeypatch.setattr(builtins, "open", counting(builtins.open))
        monkeypatch.setattr(io, "open", counting(io.open))
        monkeypatch.setattr(os, "open", counting(os.open))


def test_a_big_obj_is_opened_once_per_check_with_and_without_the_cache(tmp_path, monkeypatch, capsys,
                                                                         an_hour_later):
    (tmp_path / "tex.png").write_bytes(png_header(64, 64))
    (tmp_path / "look.mtl").write_text("newmtl wood\nmap_Kd tex.png\n")
    mesh = tmp_path / "big.obj"
    header = "mtllib look.mtl\nusemtl wood\ng top # affinity: ignore[Q2]\n"
    mesh.write_text(grid_obj(300, header))  # 90,000 quads, 3.5 MB
    assert mesh.stat().st_size > 3_000_000
    monkeypatch.setenv("AFFINITY_CACHE_DIR", str(tmp_path / "cache"))
    outputs = []
    for args, opens in ((["--no-cache"], 1), ([], 1), ([], 0)):  # no cache; a cold cache; a warm one
        counter = OpenCounter(mesh, monkeypatch)
        code, out, err = run_cli(["check", "--format", "json", *args, str(mesh)], capsys)
        assert code == 0, err
        assert counter.opens == opens, (args, counter.opens)
        outputs.append(out)
        monkeypatch.undo()
        monkeypatch.setenv("AFFINITY_CACHE_DIR", str(tmp_path / "cache"))
    assert outputs[0] == outputs[1] == outputs[2]
    assert json.loads(outputs[0])["files"][0]["quads"] == 90_000
    # Touched, unchanged: hashed once (the pre-key changed), served from the cache, not parsed again.
    os.utime(mesh, (mesh.stat().st_atime, mesh.stat().st_mtime - 10))
    counter = OpenCounter(mesh, monkeypatch)
    code, out, _ = run_cli(["check", "--format", "json", str(mesh)], capsys)
    assert (code, counter.opens, out) == (0, 1, outputs[0])


# -- a new rule on a new resource: one rule and one role --------------------------------------------

#: A role the registry does not hold: ``norm`` is a built-in role now (the visible reading reads normal maps),
#: so the hypothetical normal map is named by a statement no built-in role reads.
NORMAL_MAP = ResourceRole(name="normal-map", statement="map_Nx", named_in="mtl", image=True,
                          summary="the tangent-space normal map of a material")


def _normal_map_size(mesh) -> tuple[int, int] | None:
    from affinity.loaders.imagesize import image_size

    paths = [r.path for r in mesh.resources if r.role == NORMAL_MAP.name]
    return image_size(paths[0]) if paths else None


@pytest.fixture
def q104():
    """A hypothetical Q104: the split misplaces the normal map, in the normal map's texels."""
    register_role(NORMAL_MAP)

    @rule(code="Q104", name="normal-map-disaffine", unit="texels", default_threshold=0.5, attribute="texcoords",
          scored=True, family="UvAffinity")
    def normal_map_disaffine(quads):
        """Texture coordinates misplace the normal map.

        What it does:
            Q101's measure in the texels of the material's normal map (norm).
        Why it matters:
            Shading shifts where the split bends the normal map.
        Example:
            v 0 0 0
            f 1 1 1
        How to fix:
            Re-UV the quad as a parallelogram.
        """
        size = _normal_map_size(quads.mesh)
        rows, uv = quads.uv
        if size is None:
            return Measured.nothing()
        return Measured(rows, texels(quads.split_error(rows, uv).T, size))

    try:
        yield RULES["Q104"]
    finally:
        unregister("Q104")
        unregister_role(NORMAL_MAP.name)


@pytest.fixture
def normal_mapped(tmp_path, an_hour_later) -> Path:
    """``mesh.obj`` (the trapezoid) -> ``look.mtl`` -> ``tex.png`` (64 px) and ``nrm.png`` (128 px)."""
    (tmp_path / "tex.png").write_bytes(png_header(64, 64))
    (tmp_path / "nrm.png").write_bytes(png_header(128, 128))
    (tmp_path / "look.mtl").write_text("newmtl wood\nmap_Kd tex.png\nmap_Nx nrm.png\n")
    (tmp_path / "mesh.obj").write_text("mtllib look.mtl\nusemtl wood\n" + TRAPEZOID_OBJ)
    return tmp_path


def _cached_check(folder: Path, mesh: Path) -> list:
    cache = ResultCache(str(folder), tool="tool")
    try:
        return check_files([(str(mesh), Settings())], jobs=1, cache=cache)
    finally:
        cache.close()


def _recheck_after_touching_the_normal_map(assets: Path, cache: Path, monkeypatch) -> list[str]:
    """The files checked again (not served by the cache) after the normal map changed."""
    checked = []
    real = check_module.load_and_check
    monkeypatch.setattr(check_module, "load_and_check",
                        lambda path, *args: checked.append(os.path.basename(path)) or real(path, *args))
    _cached_check(cache, assets / "mesh.obj")
    assert checked == ["mesh.obj"]
    (assets / "nrm.png").write_bytes(png_header(256, 256))
    checked.clear()
    _cached_check(cache, assets / "mesh.obj")
    return checked


def test_without_its_role_the_cache_does_not_see_a_normal_map(normal_mapped, tmp_path_factory, monkeypatch):
    assert _recheck_after_touching_the_normal_map(normal_mapped, tmp_path_factory.mktemp("c"), monkeypatch) == []


def test_a_normal_map_rule_needs_one_rule_and_one_resource_role(q104, normal_mapped, tmp_path_factory,
                                                               monkeypatch):
    mesh = load(normal_mapped / "mesh.obj")
    assert [(r.role, r.name) for r in mesh.resources] == [("mtllib", "look.mtl"), ("map_Kd", "tex.png"),
                                                          ("normal-map", "nrm.png")]
    # Scored: the attribute has two scoring rules now, and the lint reads Q104 in the normal map's texels.
    assert scored_codes(mesh, "uv") == ["Q101", "Q104"]
    hits = {h.code: h for h in lint_mesh(mesh, Settings(select=["Q101", "Q104"]))}
    np.testing.assert_allclose(hits["Q104"].values, 2 * hits["Q101"].values)  # 128 px against 64 px
    # The cache follows the normal map: touching it checks the mesh again.
    assert _recheck_after_touching_the_normal_map(normal_mapped, tmp_path_factory.mktemp("c"), monkeypatch) == [
        "mesh.obj"]
    # Q902 names it when it is missing.
    (normal_mapped / "nrm.png").unlink()
    report = check_file(str(normal_mapped / "mesh.obj"), Settings(select=["Q902"]))
    [missing] = report.hits
    assert missing.code == "Q902" and missing.lines.tolist() == [1]
    assert missing.details == ["map_Nx nrm.png (in look.mtl) not found"]


def test_the_cache_follows_a_built_in_normal_map_role(tmp_path, tmp_path_factory, monkeypatch, an_hour_later):
    """``norm`` is registered (design.md, "Textures by role"): touching the normal map checks the mesh again."""
    (tmp_path / "tex.png").write_bytes(png_header(64, 64))
    (tmp_path / "nrm.png").write_bytes(png_header(128, 128))
    (tmp_path / "look.mtl").write_text("newmtl wood\nmap_Kd tex.png\nnorm nrm.png\n")
    (tmp_path / "mesh.obj").write_text("mtllib look.mtl\nusemtl wood\n" + TRAPEZOID_OBJ)
    assert _recheck_after_touching_the_normal_map(tmp_path, tmp_path_factory.mktemp("c"), monkeypatch) == ["mesh.obj"]


def test_a_role_registered_after_the_cache_was_warmed_is_followed(normal_mapped, tmp_path_factory, monkeypatch):
    cache = tmp_path_factory.mktemp("c")
    _cached_check(cache, normal_mapped / "mesh.obj")  # look.mtl's files read without the normal-map role
    register_role(NORMAL_MAP)
    try:
        assert _recheck_after_touching_the_normal_map(normal_mapped, cache, monkeypatch) == ["mesh.obj"]
    finally:
        unregister_role(NORMAL_MAP.name)


# -- formats: one table -----------------------------------------------------------------------------


def test_the_pre_commit_hook_matches_the_format_table():
    text = (ROOT / ".pre-commit-hooks.yaml").read_text()
    [pattern] = re.findall(r"^\s*files:\s*(\S+)\s*$", text, re.MULTILINE)
    assert pattern == hook_pattern()
    for suffix in MESH_SUFFIXES:
        assert re.search(pattern, f"assets/chair{suffix}") and re.search(pattern, f"CHAIR{suffix.upper()}")
    assert not re.search(pattern, "look.mtl") and not re.search(pattern, "chair.obj.bak")
    assert all(f"{suffix.lstrip('.')}" in text.split("description:")[1].split("\n")[0] for suffix in (".obj", ".usd"))


def test_every_suffix_of_the_table_is_walked_and_loaded(tmp_path):
    from affinity.pipeline.files import collect_paths

    for suffix in MESH_SUFFIXES:
        (tmp_path / f"m{suffix.upper()}").write_bytes(b"x")
    (tmp_path / "look.mtl").write_text("newmtl m\n")
    assert sorted(os.path.basename(p) for p in collect_paths([str(tmp_path)])) == sorted(
        f"m{s.upper()}" for s in MESH_SUFFIXES)
    assert set(LOADERS) == set(MESH_SUFFIXES) and all(f.load_function() for f in LOADERS.values()
                                                      if f.extra is None)


def test_every_output_format_writes_one_mesh(tmp_path, capsys):
    modules = sorted(p.stem for p in (ROOT / "affinity" / "output").glob("*.py")
                     if re.search(r"^def write\(", p.read_text(), re.MULTILINE))
    assert sorted(FORMATS) == modules  # a new format module is in the registry, so this test runs it
    mesh = tmp_path / "trapezoid.obj"
    mesh.write_text(TRAPEZOID_OBJ)
    for name in FORMATS:
        code, out, err = run_cli(["check", "--no-cache", "--format", name, str(mesh)], capsys)
        assert code == 1, (name, err)
        assert "Q101" in out and "trapezoid.obj" in out, name
        if name in ("json", "sarif"):
            document = json.loads(out)
            findings = document["findings"] if name == "json" else document["runs"][0]["results"]
            assert len([f for f in findings if "Q101" in json.dumps(f)]) == 1, name
        elif name == "junit":
            assert ET.fromstring(out).iter("failure")
        elif name == "github":
            assert out.startswith("::") and "line=9" in out
        else:
            assert "trapezoid.obj:9:1: Q101 error uv-disaffine:" in out


def test_a_usd_stage_lists_its_layers_as_resources_and_the_cache_hashes_them(tmp_path):
    pytest.importorskip("pxr")
    from affinity.pipeline.cache import _hash_file

    (tmp_path / "quad.usda").write_text("""#usda 1.0
def Mesh "quad"
{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
}
""")
    (tmp_path / "stage.usda").write_text('#usda 1.0\n(\n    subLayers = [@./quad.usda@, @./gone.usda@]\n)\n')
    mesh = load(tmp_path / "stage.usda")
    assert mesh.n_faces == 1
    assert [(r.role, r.name, r.path) for r in mesh.resources] == [
        ("usd-asset", "./gone.usda", str(tmp_path / "gone.usda")),
        ("usd-asset", "./quad.usda", str(tmp_path / "quad.usda"))]
    _, deps = _hash_file(str(tmp_path / "stage.usda"))
    assert deps == [r.path for r in mesh.resources]
    assert check_file(str(tmp_path / "stage.usda"), Settings(select=["Q902"])).hits == []


def test_the_check_and_report_help_name_every_suffix_of_the_table():
    commands = cli.build_parser()._subparsers._group_actions[0].choices
    for command in ("check", "report"):
        text = " ".join(commands[command].format_help().split())
        assert all(suffix in text for suffix in MESH_SUFFIXES), command
