"""`affinity check` as a gate (issue 18): levels and --fail-on, the fold angle, bounded output,
no silent switches, where a finding is, missing resources, and walking a repository.

Every test runs the command line (``helpers.cli.run``) and looks at the exit code and the output.
"""

from __future__ import annotations

import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, write
from helpers.quads import trapezoids
from helpers.sarif import assert_valid

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib



@pytest.fixture
def makehuman(shared_meshes):
    return shared_meshes / "makehuman_base_hm08.obj"


@pytest.fixture
def spot(shared_meshes):
    return shared_meshes / "gen_spot_cc4.obj"

#: The unit square with corner 2 lifted by ``h``: the split along 0-2 folds by
#: acos(1 / (1 + h^2)), the split along 1-3 by acos(1 / sqrt(1 + 2 h^2)) (normals (0,-h,1), (-h,0,1);
#: (-h,-h,1), (0,0,1)).
LIFTED = "v 0 0 0\nv 1 0 0\nv 1 1 {h}\nv 0 1 0\nf 1 2 3 4\n"
#: A mirrored UV island: Q302 (info by default) and nothing else.
MIRRORED = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 1 0\nvt 0 0\nvt 0 1\nvt 1 1\nf 1/1 2/2 3/3 4/4\n"


def findings(result) -> list[dict]:
    assert result.returncode in (0, 1), result.stderr
    return json.loads(result.stdout)["findings"]


# 1. Levels, --fail-on, --exit-zero, the fold angle.

def test_every_format_carries_the_level(tmp_path):
    path = str(write(tmp_path, "mirrored.obj", MIRRORED))
    (finding,) = findings(run("check", "--format", "json", path))
    assert (finding["code"], finding["level"], finding["unit"]) == ("Q302", "info", "relative area")
    sarif = json.loads(run("check", "--format", "sarif", path).stdout)
    assert sarif["runs"][0]["results"][0]["level"] == "note"  # SARIF's word for info
    assert run("check", "--format", "github", path, cwd=tmp_path).stdout.startswith("::notice ")
    assert "Found 1 finding: 1 info" in run("check", path).stdout


def test_fail_on_and_exit_zero(tmp_path):
    info = str(write(tmp_path, "mirrored.obj", MIRRORED))
    # top 1.992 of bottom 2 wide: (1 - r) / (1 + sqrt r)^2 * 1024 = 1.03 texels, a warning (under 2 texels)
    warning = str(write(tmp_path, "mild.obj", trapezoids([1.992])))
    error = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    assert run("check", info).returncode == 0, "info does not fail the default gate"
    assert run("check", "--fail-on", "info", info).returncode == 1
    assert run("check", warning).returncode == 0, "the default gate fails on errors only"
    assert run("check", "--fail-on", "warning", warning).returncode == 1
    assert run("check", error).returncode == 1
    assert run("check", "--exit-zero", error).returncode == 0
    broken = str(write(tmp_path, "broken.obj", "v 0 0 0\nf 1 2 3\n"))
    assert run("check", "--exit-zero", warning, broken).returncode == 2, "unreadable input still exits 2"
    pointer = str(write(tmp_path, "pointer.obj", "version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 1\n"))
    assert run("check", "--exit-zero", pointer).returncode == 0
    assert run("check", "--exit-zero", "--fail-on-skip", pointer).returncode == 2


@pytest.mark.parametrize("table, name", [("[levels]", "affinity.toml"), ("[tool.affinity.levels]", "pyproject.toml")])
def test_levels_table_overrides_a_rules_level(tmp_path, table, name):
    write(tmp_path, name, f'{table}\nQ302 = "error"\nQ101 = "info"\n')
    mirrored = str(write(tmp_path, "mirrored.obj", MIRRORED))
    trapezoid = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    result = run("check", "--format", "json", mirrored, trapezoid)
    assert result.returncode == 1
    assert {f["code"]: f["level"] for f in findings(result)} == {"Q302": "error", "Q101": "info"}
    assert run("check", trapezoid).returncode == 0, "Q101 at info no longer fails the gate"
    write(tmp_path, name, f'{table}\nQ302 = "fatal"\n')
    bad = run("check", mirrored)
    assert bad.returncode == 2 and "Q302 = 'fatal'" in bad.stderr


@pytest.mark.parametrize("h", [0.2, 1.0, 3.0])
def test_q202_is_the_fold_angle_along_the_diagonal(tmp_path, h):
    path = str(write(tmp_path, "lifted.obj", LIFTED.format(h=h)))
    fold02 = np.degrees(np.arccos(1 / (1 + h * h)))
    fold13 = np.degrees(np.arccos(1 / np.sqrt(1 + 2 * h * h)))
    for diagonal, expected in (("02", fold02), ("13", fold13), ("both", max(fold02, fold13))):
        (finding,) = findings(run("check", "--format", "json", "--select", "Q202", "--threshold", "Q202=0",
                                  "--diagonal", diagonal, path))
        assert finding["unit"] == "degrees" and finding["threshold"] == 0
        assert finding["value"] == pytest.approx(expected, rel=1e-9)
    flagged = findings(run("check", "--format", "json", "--select", "Q202", path))
    assert bool(flagged) == (max(fold02, fold13) > 45), "the default threshold is 45 degrees"


def test_a_degenerate_quad_is_q201s_not_a_fold(tmp_path):
    path = str(write(tmp_path, "pole.obj", "v 0 0 0\nv 1 0 0\nv 0.5 1 1\nf 1 2 3 3\nf 1 2 3 2\n"))
    result = run("check", "--format", "json", "--select", "Q201,Q202", "--threshold", "Q202=0", path)
    assert {f["code"] for f in findings(result)} == {"Q201"}


def test_a_flat_concave_quad_does_not_fold(tmp_path):
    path = str(write(tmp_path, "dart.obj", "v 0 0 0\nv 2 0 0\nv 0.5 0.5 0\nv 0 2 0\nf 1 2 3 4\n"))
    result = run("check", "--format", "json", "--select", "Q202,Q203", "--threshold", "Q202=1", path)
    assert [(f["code"], f["level"]) for f in findings(result)] == [("Q203", "info")]


def test_defaults_are_calibrated_on_the_shared_meshes(makehuman, spot):
    doc = json.loads(run("check", "--format", "json", str(makehuman), str(spot)).stdout)
    human = doc["files"][0]
    q202 = [f for f in doc["findings"] if f["path"] == str(makehuman) and f["code"] == "Q202"]
    assert 0 < len(q202) <= 0.05 * human["quads"]
    assert all(f["value"] > 45 and f["unit"] == "degrees" for f in q202)
    on_spot = [f for f in doc["findings"] if f["path"] == str(spot) and f["code"] in ("Q203", "Q302")]
    assert on_spot, "Spot's mirrored UVs are still reported"
    assert {f["level"] for f in on_spot} == {"info"}


# 2. Bounded output.

def test_github_output_on_makehuman_is_one_line_per_rule(makehuman):
    result = run("check", "--format", "github", str(makehuman))
    lines = result.stdout.splitlines()
    titles = [line.split("title=", 1)[1].split("::", 1)[0] for line in lines]
    assert len(titles) == len(set(titles)) >= 2
    q202 = next(line for line in lines if "title=Q202" in line)
    assert "findings, the worst:" in q202 and "; first: face " in q202


def test_max_findings_sarif_on_makehuman_is_small_valid_and_says_truncated(tmp_path, makehuman):
    full = json.loads(run("check", "--format", "json", str(makehuman)).stdout)
    counts = full["summary"]["by_rule"]
    result = run("check", "--format", "sarif", "--max-findings", "100", str(makehuman))
    assert len(result.stdout.encode()) < 200_000
    log = json.loads(result.stdout)
    assert_valid(log)
    (sarif_run,) = log["runs"]
    truncated = {t["code"]: t for t in sarif_run["properties"]["truncated"]}
    assert {code for code, n in counts.items() if n > 100} == set(truncated)
    assert all(t["total"] == counts[code] and t["kept"] == 100 for code, t in truncated.items())
    kept = [r for r in sarif_run["results"] if r["ruleId"] == "Q202"]
    assert len(kept) == 100
    worst = sorted((f["value"] for f in full["findings"] if f["code"] == "Q202"), reverse=True)[:100]
    assert sorted((r["properties"]["value"] for r in kept), reverse=True) == worst


def test_max_findings_keeps_the_worst_and_json_is_compact(tmp_path):
    widths = [1.0, 0.2, 1.5, 0.6, 1.2, 0.1, 0.9]
    path = str(write(tmp_path, "many.obj", trapezoids(widths)))
    full = run("check", "--format", "json", path)
    assert "\n" not in full.stdout.rstrip("\n") and ": " not in full.stdout.split('"settings"')[0]
    values = sorted((f["value"] for f in findings(full)), reverse=True)
    assert len(values) == len(widths)
    capped = run("check", "--format", "json", "--max-findings", "3", path)
    doc = json.loads(capped.stdout)
    assert sorted((f["value"] for f in doc["findings"]), reverse=True) == values[:3]
    assert [f["face"] for f in doc["findings"]] == sorted(f["face"] for f in doc["findings"]), "in file order"
    assert doc["truncated"] == [{"path": path, "code": "Q101", "kept": 3, "total": len(widths)}]
    assert doc["summary"]["findings"] == len(widths)
    assert run("check", "--max-findings", "0", path).returncode == 2


def test_statistics_works_with_every_format(tmp_path):
    path = str(write(tmp_path, "many.obj", trapezoids([1.0, 0.5, 0.2])))
    doc = json.loads(run("check", "--format", "json", "--statistics", path).stdout)
    assert doc["statistics"] == [{"code": "Q101", "name": "uv-disaffine", "level": "error", "count": 3}]
    assert len(doc["findings"]) == 3, "statistics never remove findings"
    log = json.loads(run("check", "--format", "sarif", "--statistics", path).stdout)
    assert log["runs"][0]["properties"]["statistics"][0]["count"] == 3 and len(log["runs"][0]["results"]) == 3
    assert_valid(log)
    github = run("check", "--format", "github", "--statistics", path, cwd=tmp_path).stdout
    assert "::notice file=.,title=statistics::3 findings of Q101 uv-disaffine (error)" in github
    junit = run("check", "--format", "junit", "--statistics", path).stdout
    (statistic,) = ET.fromstring(junit).findall("properties/property")
    assert (statistic.get("name"), statistic.get("value")) == ("Q101 uv-disaffine (error)", "3")


# 3. No silent switches.

@pytest.mark.parametrize("args", [
    ["--threshold", "nan"], ["--threshold", "Q102=inf"], ["--threshold", "-inf"], ["--select="], ["--select", ","],
])
def test_flags_that_would_switch_checks_off_are_usage_errors(tmp_path, args):
    path = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    result = run("check", *args, path)
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert result.stdout == ""


@pytest.mark.parametrize("config", ["[thresholds]\nQ101 = nan\n", "threshold = inf\n", "select = []\n"])
def test_configuration_that_would_switch_checks_off_is_a_usage_error(tmp_path, config):
    write(tmp_path, "affinity.toml", config)
    result = run("check", str(write(tmp_path, "trapezoid.obj", TRAPEZOID)))
    assert result.returncode == 2 and "affinity.toml" in result.stderr and len(result.stderr.splitlines()) == 1


def test_show_settings_is_toml_that_reads_back(tmp_path):
    write(tmp_path, "affinity.toml", 'ignore = ["Q3"]\nextend-exclude = ["wip"]\n[thresholds]\nQ102 = 3\n'
                                     '[levels]\nQ203 = "warning"\n[per-file-ignores]\n'
                                     '"caf\u00e9 \U0001F600/*.obj::helper-*" = ["Q101"]\n')
    result = run("check", "--show-settings", "--threshold", "Q201=1e-12", str(tmp_path))
    assert result.returncode == 0
    settings = tomllib.loads(result.stdout)
    assert settings["ignore"] == ["Q3"] and settings["extend-exclude"] == ["wip"]
    assert settings["thresholds"]["Q102"] == 3 and settings["thresholds"]["Q201"] == 1e-12
    assert settings["levels"]["Q203"] == "warning" and settings["levels"]["Q302"] == "info"
    assert settings["per-file-ignores"] == {"caf\u00e9 \U0001F600/*.obj::helper-*": ["Q101"]}
    assert {".git", ".venv", "venv", "site-packages", "build", "dist", ".tox", ".nox", ".mypy_cache", "node_modules",
            "__pycache__"} <= set(settings["exclude"]), "ruff's default folder names"


@pytest.mark.parametrize("args", [
    ["--pixel-tolerance", "nan"], ["--pixel-tolerance", "-1"],
    ["--camera", "0,0,5,0,0,0,0"], ["--camera", "0,0,5,0,0,0,180"], ["--camera", "0,0,5,0,0,0,nan"],
])
def test_render_rejects_tolerances_and_fields_of_view_that_draw_nothing(tmp_path, args):
    result = run("render", *args, "-o", str(tmp_path / "out.png"))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert not (tmp_path / "out.png").exists()


@pytest.mark.parametrize("up", ["y", "z"])
def test_a_top_down_camera_picks_an_up_vector_that_works(tmp_path, up):
    pytest.importorskip("PIL")
    from PIL import Image

    eye = {"y": "0,6,0", "z": "0,0,6"}[up]
    out = tmp_path / "top.png"
    result = run("render", "--up", up, "--camera", f"{eye},0,0,0,40", "--size", "64x48", "-o", str(out))
    assert result.returncode == 0, result.stderr
    pixels = np.asarray(Image.open(out).convert("RGB")).reshape(-1, 3)
    assert len(np.unique(pixels, axis=0)) > 2, "the sphere is in the picture"


# 4. Finding a finding.

def test_binary_ply_lines_are_zero(tmp_path):
    import struct

    header = (b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
              b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
    body = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 3, 0, 1, 0) + struct.pack("<B4i", 4, 0, 1, 2, 3)
    path = tmp_path / "lifted.ply"
    path.write_bytes(header + body)
    result = run("check", "--fail-on", "warning", str(path))
    assert result.returncode == 1
    assert result.stdout.startswith(f"{path}:0:0: Q202 warning nonplanar-quad: ")
    assert " degrees) [face 0]\n" in result.stdout


GROUPED = (
    "v 0 0 0\nv 1 0 0\nv 1 1 3\nv 0 1 0\n"
    "g body\nf 1 2 3 4\n"
    "g helper-tongue\nf 1 2 3 4\nf 1 2 3 4\n"
    "g helper-eyes\nf 1 2 3 4\n"
    "o teeth\nf 1 2 3 4\n"
)


def test_per_file_ignores_name_groups(tmp_path):
    write(tmp_path, "affinity.toml", '[per-file-ignores]\n"chars/*.obj::helper-*" = ["Q2"]\n"*.obj::teeth" = ["ALL"]\n')
    (tmp_path / "chars").mkdir()
    path = str(write(tmp_path, "chars/human.obj", GROUPED))
    other = str(write(tmp_path, "props.obj", GROUPED))
    doc = json.loads(run("check", "--format", "json", path, other).stdout)
    faces = {p: [f["face"] for f in doc["findings"] if f["path"] == p] for p in (path, other)}
    assert faces == {path: [0], other: [0, 1, 2, 3]}
    assert {f["group"] for f in doc["findings"]} == {"body", "helper-tongue", "helper-eyes"}


def test_per_file_ignores_name_usd_prims(tmp_path):
    pytest.importorskip("pxr")
    scene = Path(__file__).parent / "data" / "usd" / "scene.usda"
    (tmp_path / "scene.usda").write_bytes(scene.read_bytes())
    before = findings(run("check", "--format", "json", "scene.usda", cwd=tmp_path))
    assert {f["prim"] for f in before} == {"/World/Panel"}
    write(tmp_path, "affinity.toml", '[per-file-ignores]\n"*.usda::/World/Pan*" = ["Q101", "Q102"]\n')
    after = findings(run("check", "--format", "json", "scene.usda", cwd=tmp_path))
    assert [f["code"] for f in after] == ["Q103"] and len(before) == 3


def test_inline_ignore_comments(tmp_path):
    text = GROUPED.replace("g body\nf 1 2 3 4\n", "g body\nf 1 2 3 4  # affinity: ignore[Q202]\n")
    text = text.replace("g helper-tongue\n", "g helper-tongue # affinity: ignore[Q1, Q20]\n")
    text = text.replace("o teeth\nf 1 2 3 4\n", "o teeth\nf 1 2 3 4 # affinity: ignore[Q101]\n")
    path = str(write(tmp_path, "human.obj", text))
    faces = [f["face"] for f in findings(run("check", "--format", "json", path))]
    assert faces == [3, 4], "face 0 by its line, faces 1-2 by their group's line; Q101 does not silence Q202"


# 5. Missing resources.

def test_missing_mtllib_is_an_info_finding(tmp_path):
    path = str(write(tmp_path, "crate.obj", "mtllib crate.mtl\n" + MIRRORED.replace("f ", "usemtl wood\nf ")))
    result = run("check", "--format", "json", "--select", "Q9", path)
    assert result.returncode == 0, "a checkout without textures does not fail the gate"
    (finding,) = findings(result)
    assert (finding["code"], finding["name"], finding["level"], finding["line"]) == ("Q902", "missing-resource",
                                                                                      "info", 1)
    assert "mtllib crate.mtl not found; texels use texture-size 1024" in finding["message"]
    assert run("check", "--select", "Q9", "--fail-on", "info", path).returncode == 1


def test_missing_and_lfs_textures_are_reported_once_each(tmp_path):
    write(tmp_path, "crate.mtl", "newmtl wood\nmap_Kd wood.png\nnewmtl oak\nmap_Kd wood.png\n"
                                 "newmtl lid\nmap_Kd lid.png\n")
    write(tmp_path, "lid.png", "version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 9\n")
    path = str(write(tmp_path, "crate.obj", "mtllib crate.mtl\nusemtl wood\n" + MIRRORED))
    result = run("check", "--select", "Q902", "--texture-size", "512", path)
    lines = [line for line in result.stdout.splitlines() if "Q902" in line]
    head = f"{path}:1:1: Q902 info missing-resource: an mtllib or map_Kd named by the file cannot be found or read: "
    assert lines == [
        head + "map_Kd wood.png (in crate.mtl) not found; texels use texture-size 512",
        head + "map_Kd lid.png (in crate.mtl) is a Git LFS pointer (run git lfs pull)",
    ]


# 6. Walking a repository.

def make_repo(root: Path) -> None:
    """A repository with meshes where they belong and where a walk must not go."""
    for name in ("assets/a.obj", "assets/deep/b.obj", "assets/build/c.obj", "assets/scratch.obj", "local/d.obj",
                 ".git/objects/e.obj", "node_modules/pkg/f.obj", "assets/__pycache__/g.obj",
                 ".venv/lib/site-packages/pxr/h.usda", ".venv-ci/lib/i.obj", "envs/conda/j.obj", "docs/k.txt"):
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(TRAPEZOID)  # OBJ text: the .usda under .venv would be unreadable
    (root / ".venv" / "pyvenv.cfg").write_text("home = /usr\n")
    (root / ".venv-ci" / "pyvenv.cfg").write_text("home = /usr\n")
    (root / "envs" / "conda" / "conda-meta").mkdir()
    (root / ".gitignore").write_text("/local/\n")
    (root / "assets" / ".gitignore").write_text("build/\n")
    (root / ".git" / "info").mkdir(parents=True)
    (root / ".git" / "info" / "exclude").write_text("scratch.obj\n")


def test_check_with_no_path_walks_the_repository_like_ruff(tmp_path):
    make_repo(tmp_path)
    result = run("check", "--show-files", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == ["assets/a.obj", "assets/deep/b.obj"]
    checked = run("check", "--format", "json", cwd=tmp_path)
    assert checked.returncode == 1 and "Q901" not in checked.stderr
    assert [f["path"] for f in json.loads(checked.stdout)["files"]] == ["assets/a.obj", "assets/deep/b.obj"]


def test_exclude_replaces_the_default_skips_and_extend_exclude_adds(tmp_path):
    make_repo(tmp_path)
    write(tmp_path, "affinity.toml", 'extend-exclude = ["deep"]\n')
    assert run("check", "--show-files", cwd=tmp_path).stdout.splitlines() == ["assets/a.obj"]
    write(tmp_path, "affinity.toml", 'exclude = ["deep"]\n')
    shown = run("check", "--show-files", cwd=tmp_path).stdout.splitlines()
    assert "node_modules/pkg/f.obj" in shown and "assets/deep/b.obj" not in shown
    assert not any(p.startswith((".venv", "envs/")) for p in shown), "environments are never walked"


def test_a_directory_without_meshes_among_others_is_a_warning(tmp_path):
    (tmp_path / "empty").mkdir()
    path = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    result = run("check", str(tmp_path / "empty"), path)
    assert result.returncode == 1 and "Q101" in result.stdout
    assert f"warning: {tmp_path / 'empty'}: no mesh files" in result.stderr
    assert run("check", str(tmp_path / "empty")).returncode == 2


def test_output_file_is_written_whole(tmp_path):
    path = str(write(tmp_path, "trapezoid.obj", TRAPEZOID))
    out = tmp_path / "report.sarif"
    result = run("check", "--format", "sarif", "--output-file", str(out), path)
    assert result.returncode == 1 and result.stdout == ""
    assert_valid(json.loads(out.read_text()))
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".report")] == [], "no temporary file left"
    missing = run("check", "--output-file", str(tmp_path / "no" / "such" / "out.txt"), path)
    assert missing.returncode == 2 and "cannot write the output" in missing.stderr
    assert not (tmp_path / "no").exists()


def test_default_excludes_skip_environments_by_name_like_ruff(tmp_path):
    """Issue 29: a ``.venv`` without ``pyvenv.cfg`` holding a package's schema file is not walked into."""
    (tmp_path / ".git").mkdir()
    write(tmp_path, "panel.obj", SQUARE)
    schema = tmp_path / ".venv" / "lib" / "python3.11" / "site-packages" / "pkg" / "generatedSchema.usda"
    schema.parent.mkdir(parents=True)
    schema.write_text("#usda 1.0\nclass \"Broken\" (\n")  # unreadable: checking it would exit 2
    for name in ("venv", "build", "dist", ".tox", ".nox", ".mypy_cache", "site-packages"):
        (tmp_path / name / "sub").mkdir(parents=True)
        (tmp_path / name / "sub" / "other.obj").write_text("not a mesh\n")
    result = run("check", cwd=tmp_path)
    assert (result.returncode, result.stderr) == (0, ""), result.stdout + result.stderr
    assert "generatedSchema" not in result.stdout and "other.obj" not in result.stdout
    assert run("check", "--show-files", cwd=tmp_path).stdout.splitlines() == ["panel.obj"]


def test_a_path_named_explicitly_is_checked_inside_a_default_excluded_folder(tmp_path):
    write(tmp_path, "affinity.toml", "texture-size = 1024\n")  # a configuration root: globs match from here
    (tmp_path / "build" / "deep").mkdir(parents=True)
    mesh = write(tmp_path / "build" / "deep", "trapezoid.obj", TRAPEZOID)
    assert "Q101" in run("check", str(mesh), cwd=tmp_path).stdout
    assert run("check", "--show-files", "build", cwd=tmp_path).stdout.splitlines() == ["build/deep/trapezoid.obj"]
    write(tmp_path, "affinity.toml", 'extend-exclude = ["deep"]\n')
    assert run("check", "--show-files", str(mesh), cwd=tmp_path).stdout == "", "configured globs still apply"
