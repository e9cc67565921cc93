"""quad-affinity inside USD's validators, run as a USD application runs them.

The UsdValidation validators run in a fresh process whose ``PXR_PLUGINPATH_NAME`` is what
``affinity usd-plugin`` prints (USD's plug-in registry imports the plug-in module itself);
``nvidia_usd_validate`` runs as a command with the entry point this package declares in
pyproject.toml. Each must find the faces and levels ``affinity check`` finds, and its fixer
must leave ``affinity fix``'s mesh: the truth for "clean" is the validators and ``affinity
check`` run again on the fixed stage, and the original layer's bytes.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run
from helpers.usd_stages import define_mesh, flagged_stage, referenced_stage
from helpers.usd_validation import validate

pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")

ROOT = Path(__file__).resolve().parents[1]
FINDING = re.compile(r"^(?P<prim>/\S*) face (?P<face>\d+): (?P<code>Q\d{3}) ")
LEVELS = {"Error": "error", "Warn": "warning", "Info": "info"}

#: Validates the stage given on the command line, or applies the fixers of its errors with the
#: stage's root layer as edit target first (--fix), and prints its errors as JSON lines.
def from_message(message: str) -> tuple:
    """(prim, face, code) of a finding's message."""
    match = FINDING.match(message)
    assert match, message
    return match["prim"], int(match["face"]), match["code"]


def check_json(path: Path) -> dict:
    result = run("check", "--no-cache", "--format", "json", str(path))
    assert result.returncode in (0, 1), result.stderr
    return json.loads(result.stdout)


def checked(path: Path) -> list[tuple]:
    """(prim, face, code, level) of every finding ``affinity check`` makes in the stage."""
    return sorted((f["prim"], f["face"], f["code"], f["level"]) for f in check_json(path)["findings"])


def validated(errors: list[dict]) -> list[tuple]:
    """(prim, face, code, level) of every finding among the validators' errors (notes left out)."""
    return sorted((*from_message(e["message"]), LEVELS[e["type"]]) for e in errors if e["name"] != "note")


def test_affinity_usd_plugin_prints_the_folder_of_the_plugins_plug_info():
    folder = Path(run("usd-plugin").stdout.strip())
    [plugin] = json.loads((folder / "plugInfo.json").read_text())["Plugins"]
    from affinity.usd.families import families

    assert (plugin["Type"], plugin["Name"]) == ("python", "affinity.usd.validators")
    validators = plugin["Info"]["Validators"]
    assert list(validators) == [family.name for family in families()]
    assert [v["doc"] for v in validators.values()] == [family.doc for family in families()]
    assert all(v["keywords"] == ["quad-affinity"] and v["schemaTypes"] == ["UsdGeomMesh"] for v in validators.values())


def test_validators_find_the_faces_and_levels_of_affinity_check(tmp_path):
    stage = flagged_stage(tmp_path)
    errors = validate(stage)
    assert checked(stage) == [("/World/Panel", 0, "Q101", "error"), ("/World/Panel", 1, "Q101", "warning")]
    assert validated(errors) == checked(stage)
    assert {(e["validator"], e["name"], tuple(e["fixers"])) for e in errors} == \
        {("affinity.usd.validators:UvAffinity", "uv-disaffine", ("RefineQuads",))}


def composed(path: Path):
    """The stage's meshes as the loader composes them (world space)."""
    from affinity.loaders import load

    return load(path)


def assert_same_mesh(mesh, expected):
    """Face sizes, corner positions and corner uv (float32 in the layer) of two meshes."""
    assert np.diff(mesh.face_start).tolist() == np.diff(expected.face_start).tolist()
    np.testing.assert_allclose(mesh.positions[mesh.corner_vertex], expected.positions[expected.corner_vertex],
                               rtol=0, atol=1e-6)
    np.testing.assert_allclose(mesh.texcoords[mesh.corner_texcoord], expected.texcoords[expected.corner_texcoord],
                               rtol=0, atol=1e-6)


def fixed_by_affinity_fix(path: Path):
    """The stage ``affinity fix`` writes for ``path`` (``NAME.fixed.usda``, an override layer), composed."""
    result = run("fix", str(path))
    assert result.returncode == 0, result.stderr  # every flagged quad fixed
    return composed(path.with_suffix(".fixed.usda"))


def test_the_fixer_leaves_a_clean_stage_and_the_original_layer_unchanged(tmp_path):
    """The fix goes to an override layer that sublayers the flagged one (the edit target)."""
    original = flagged_stage(tmp_path)
    before = original.read_bytes()
    override = tmp_path / "override.usda"
    override.write_text('#usda 1.0\n(\n    subLayers = [@flagged.usda@]\n)\n')
    assert validate(override, "--fix") == []
    assert original.read_bytes() == before
    assert check_json(override)["findings"] == []
    fixed = composed(override)
    assert_same_mesh(fixed, fixed_by_affinity_fix(original))
    assert fixed.n_faces > 3


def test_a_mesh_four_prims_reference_is_one_error_per_finding_naming_them(tmp_path):
    stage = referenced_stage(tmp_path)
    errors = validate(stage)
    prims = [f"/Set/{name}/Knight" for name in "ABCD"]
    assert validated(errors) == [("/Set/A/Knight", 0, "Q101", "error"), ("/Set/A/Knight", 1, "Q101", "warning")]
    for error in errors:
        assert error["prims"] == prims
        assert error["layers"] == [str(tmp_path / "knight.usda")]
        assert f"referenced by {', '.join(prims)}]" in error["message"]


def test_the_fixer_on_shared_geometry_refines_every_referencing_prim_and_not_the_geometry_layer(tmp_path):
    stage = referenced_stage(tmp_path)
    geometry = (tmp_path / "knight.usda").read_bytes()
    override = tmp_path / "override.usda"
    override.write_text('#usda 1.0\n(\n    subLayers = [@set.usda@]\n)\n')
    assert validate(override, "--fix") == []
    assert (tmp_path / "knight.usda").read_bytes() == geometry
    assert_same_mesh(composed(override), fixed_by_affinity_fix(stage))


def test_a_prim_that_cannot_be_read_is_an_error_naming_it_and_the_others_are_checked(tmp_path):
    from pxr import Usd, UsdGeom

    path = tmp_path / "broken.usda"
    stage = Usd.Stage.CreateNew(str(path))
    define_mesh(stage, "/World/Good", scheme="none")
    define_mesh(stage, "/World/Bad", scheme="none").GetFaceVertexIndicesAttr().Set([0, 1, 2, 99] * 3)
    UsdGeom.Mesh.Define(stage, "/World/Missing").GetPrim().GetReferences().AddReference("no_such_file.usda")
    stage.GetRootLayer().Save()
    errors = validate(path)
    unreadable = sorted((e for e in errors if e["name"] == "unreadable"), key=lambda e: e["prims"])
    assert [(e["type"], e["prims"]) for e in unreadable] == [("Error", ["/World/Bad"]), ("Error", ["/World/Missing"])]
    assert unreadable[0]["message"] == \
        "/World/Bad: Q901 unreadable: faceVertexIndices has an entry outside the 10 points"
    assert unreadable[1]["message"].startswith(
        "/World/Missing: Q901 unreadable: Could not open asset @no_such_file.usda@")
    assert validated([e for e in errors if e["name"] != "unreadable"]) == \
        [("/World/Good", 0, "Q101", "error"), ("/World/Good", 1, "Q101", "warning")]


def test_the_subdivision_note_is_said_once_per_stage(tmp_path):
    from pxr import Usd

    path = tmp_path / "smooth.usda"
    stage = Usd.Stage.CreateNew(str(path))
    define_mesh(stage, "/World/Default")  # no subdivisionScheme authored: USD's default, catmullClark
    define_mesh(stage, "/World/Loop", scheme="loop")
    define_mesh(stage, "/World/Flat", scheme="none")
    stage.GetRootLayer().Save()
    notes = [e for e in validate(path) if e["name"] == "note"]
    assert [(e["type"], e["prims"]) for e in notes] == [("Info", ["/World/Default"])]
    assert notes[0]["message"].startswith("note: 2 of 3 mesh prims subdivide (subdivisionScheme catmullClark or loop")
    assert check_json(path)["files"][0]["notes"] == [notes[0]["message"].removeprefix("note: ")]


# --- usd-validation-nvidia --------------------------------------------------------------------------------------


def nvidia_env(tmp_path: Path) -> dict:
    """The environment of ``nvidia_usd_validate`` with this package's declared entry point on the path.

    The dev venv may hold another checkout's editable install, so the entry point declared in
    pyproject.toml is written into a distribution of its own (installed packages declare the same
    one, which usd-validation-nvidia counts once).
    """
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["entry-points"]["usd_validation_nvidia"]
    info = tmp_path / "entry-points" / "quad_affinity_entry_points-0.dist-info"
    info.mkdir(parents=True, exist_ok=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: quad-affinity-entry-points\nVersion: 0\n")
    (info / "entry_points.txt").write_text("[usd_validation_nvidia]\n" + "".join(
        f"{name} = {value}\n" for name, value in declared.items()))
    path = os.pathsep.join(filter(None, [str(ROOT), str(info.parent), os.environ.get("PYTHONPATH")]))
    return {**os.environ, "PYTHONPATH": path}


def nvidia_validate(tmp_path: Path, stage: Path, *flags: str) -> list[dict]:
    """The issues ``nvidia_usd_validate -c quad-affinity`` reports on ``stage`` (from its JSON output)."""
    command = shutil.which("nvidia_usd_validate", path=os.path.dirname(sys.executable)) or "nvidia_usd_validate"
    out = tmp_path / "issues.json"
    result = subprocess.run([command, "-c", "quad-affinity", "--no-init-rules", "--json-output", str(out), *flags,
                             str(stage)], capture_output=True, text=True, env=nvidia_env(tmp_path), timeout=300)
    assert "Traceback" not in result.stderr, result.stderr
    return [issue for rule in json.loads(out.read_text())["rules"] for issue in rule["issues"]]


NVIDIA_LEVELS = {"ERROR": "error", "WARNING": "warning", "INFO": "info"}


def test_nvidia_usd_validate_finds_the_faces_and_levels_of_affinity_check(tmp_path):
    stage = flagged_stage(tmp_path)
    issues = nvidia_validate(tmp_path, stage)
    assert sorted((*from_message(i["message"]), NVIDIA_LEVELS[i["severity"]]) for i in issues) == checked(stage)
    assert {(i["rule"]["name"], i["at"]["path"]) for i in issues} == {("UvAffinityChecker", "/World/Panel")}
    assert all(i["suggestion"]["message"] == "Refine the quads Q101 flags (affinity fix)" for i in issues)


def test_nvidia_fix_gives_the_composed_mesh_of_affinity_fix(tmp_path):
    """NVIDIA's fixer saves the layer it edits in place: the copy of the flagged stage is fixed."""
    original = flagged_stage(tmp_path, "original.usda")
    stage = Path(shutil.copy(original, tmp_path / "fixed.usda"))
    nvidia_validate(tmp_path, stage, "--fix")
    assert_same_mesh(composed(stage), fixed_by_affinity_fix(original))
    assert check_json(stage)["findings"] == []
    assert nvidia_validate(tmp_path, stage) == []


def test_nvidia_fix_on_shared_geometry_overrides_each_prim_in_the_stage(tmp_path):
    """One issue per finding, sited at the first referencing prim; --fix refines all four in set.usda
    (the strongest layer with an opinion on them) and leaves the geometry layer as it was."""
    stage = referenced_stage(tmp_path)
    expected = fixed_by_affinity_fix(stage)
    geometry = (tmp_path / "knight.usda").read_bytes()
    issues = nvidia_validate(tmp_path, stage)
    assert [(i["at"]["path"], from_message(i["message"])[1:]) for i in issues] == \
        [("/Set/A/Knight", (0, "Q101")), ("/Set/A/Knight", (1, "Q101"))]
    nvidia_validate(tmp_path, stage, "--fix")
    assert (tmp_path / "knight.usda").read_bytes() == geometry
    assert_same_mesh(composed(stage), expected)


def test_the_plug_in_is_not_imported_by_import_affinity_nor_check(tmp_path):
    """Registration happens in the plug-in module only: start-up pays for no pxr and no affinity.usd."""
    obj = tmp_path / "square.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    code = ("import sys, affinity; from affinity.cli import main; main(['check', '--no-cache', sys.argv[1]]); "
            "print(sorted(m for m in sys.modules if m == 'pxr' or m.startswith('affinity.usd')))")
    result = subprocess.run([sys.executable, "-c", code, str(obj)], capture_output=True, text=True, cwd=ROOT)
    assert result.stdout.strip().splitlines()[-1] == "[]", result.stderr


def test_an_older_usd_core_is_told_it_needs_26_11(monkeypatch, capsys):
    from pxr import Usd

    from affinity.cli import main
    from affinity.usd import usd_too_old

    assert usd_too_old() is None  # the dev extra installs 26.11 or newer
    monkeypatch.setattr(Usd, "GetVersion", lambda: (0, 26, 5))
    assert usd_too_old() == ("the USD plug-in needs usd-core 26.11 or newer (found 26.5): "
                             "pip install -U 'quad-affinity[usd]'")
    assert main(["usd-plugin"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "needs usd-core 26.11 or newer" in captured.err
