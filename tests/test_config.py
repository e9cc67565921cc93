"""Configuration: affinity.toml / [tool.affinity], walking up, precedence, exclude, per-file-ignores.

The trapezoid with a unit-square uv measures 176 texels (Q101, default
threshold 0.5), so a Q101 threshold of 1000 makes it clean and one of 1 keeps
it flagged: the exit code tells which threshold was applied.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.quads import UNIT_UV, quad_obj, trapezoid

from affinity.config import ConfigError, Resolver, find_config
from affinity.settings import Settings, glob_matches

BAD = quad_obj([(trapezoid(), UNIT_UV)])


def put(root: Path, rel: str, text: str) -> Path:
    path = root / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


# Resolution (no mesh is read).

def test_walks_up_past_a_pyproject_without_our_table(tmp_path):
    config = put(tmp_path, "pyproject.toml", "[tool.affinity]\nthreshold = 1000\n")
    put(tmp_path, "a/pyproject.toml", "[project]\nname = 'unrelated'\n")
    mesh = put(tmp_path, "a/b/m.obj", BAD)
    assert find_config(mesh.parent) == config
    resolved = Resolver({}).resolve(str(mesh))
    assert resolved.source == config and resolved.settings.threshold("Q101") == 1000
    assert resolved.settings.root == str(tmp_path)


def test_affinity_toml_wins_over_pyproject_in_the_same_folder(tmp_path):
    put(tmp_path, "pyproject.toml", "[tool.affinity]\nthreshold = 1000\n")
    config = put(tmp_path, "affinity.toml", "threshold = 1\n")
    resolved = Resolver({}).resolve(str(put(tmp_path, "m.obj", BAD)))
    assert resolved.source == config and resolved.settings.threshold("Q101") == 1


def test_nearest_configuration_wins(tmp_path):
    put(tmp_path, "affinity.toml", "ignore = ['Q1']\n")
    inner = put(tmp_path, "sub/pyproject.toml", "[tool.affinity]\nselect = ['Q101']\n")
    resolver = Resolver({})
    assert resolver.resolve(str(put(tmp_path, "sub/m.obj", BAD))).source == inner
    assert resolver.resolve(str(put(tmp_path, "m.obj", BAD))).settings.ignore == ["Q1"]


def test_flags_win_and_thresholds_merge_per_rule(tmp_path):
    put(tmp_path, "affinity.toml", "measure = 'barycentric'\n[thresholds]\nQ101 = 1000\nQ102 = 7\n")
    mesh = str(put(tmp_path, "m.obj", BAD))
    settings = Resolver({"thresholds": {"Q102": 3.0}, "measure": "centre"}).resolve(mesh).settings
    assert (settings.threshold("Q101"), settings.threshold("Q102"), settings.measure) == (1000, 3, "centre")
    assert Resolver({}, isolated=True).resolve(mesh).settings == Settings()


@pytest.mark.parametrize("text, message", [
    ("threshold = 'high'\n", "threshold: expected a number"),
    ("select = ['Q999']\n", "select: unknown rule Q999"),
    ("colour = 1\n", "unknown key 'colour'"),
    ("[thresholds]\nQ204 = 1\n", "Q204 is not a rule with a threshold"),
    ("diagonal = 2\n", "diagonal: expected one of"),
    ("threshold = 1\n[thresholds]\nQ101 = 2\n", "both set the Q101 threshold"),
    ("select = [\n", "invalid TOML"),
])
def test_invalid_configuration_names_file_and_key(tmp_path, text, message):
    config = put(tmp_path, "affinity.toml", text)
    with pytest.raises(ConfigError, match=message) as err:
        Resolver({}).resolve(str(put(tmp_path, "m.obj", BAD)))
    assert str(err.value).startswith(str(config))


def test_exclude_and_per_file_ignores_are_relative_to_the_configuration(tmp_path):
    put(tmp_path, "affinity.toml", "exclude = ['wip', 'old/*.ply']\n[per-file-ignores]\n'scans/**/*.obj' = ['Q2']\n")
    settings = Resolver({}).resolve(str(tmp_path)).settings
    assert settings.is_excluded(str(tmp_path / "a/wip/m.obj"))
    assert settings.is_excluded(str(tmp_path / "old/m.ply")) and not settings.is_excluded(str(tmp_path / "x/old/m.ply"))
    assert not settings.is_excluded(str(tmp_path / "old/m.obj"))
    assert settings.for_file(str(tmp_path / "scans/m.obj")).ignore == ["Q2"]
    assert settings.for_file(str(tmp_path / "scans/a/m.obj")).ignore == ["Q2"]
    assert settings.for_file(str(tmp_path / "m.obj")).ignore is None


@pytest.mark.parametrize("pattern, rel, expected", [
    ("*.ply", "a/b.ply", True), ("*.ply", "a/b.obj", False), ("b.obj", "a/b.obj", True),
    ("a/*", "a/b/c.obj", True), ("a/b", "a/b/c.obj", True), ("b", "a/b/c.obj", True),
    ("a/b", "x/a/b/c.obj", False), ("a/**/c.obj", "a/c.obj", True), ("/a/", "a/c.obj", True),
])
def test_glob_matches(pattern, rel, expected):
    assert glob_matches(pattern, rel) is expected


# As the user runs it.

def test_precedence_end_to_end(tmp_path):
    mesh = put(tmp_path, "assets/deep/bad.obj", BAD)
    assert run("check", str(mesh)).returncode == 1  # no configuration: flagged
    put(tmp_path, "pyproject.toml", "[tool.affinity]\nthreshold = 1000\n")
    assert run("check", str(mesh)).returncode == 0  # found walking up
    put(tmp_path, "affinity.toml", "threshold = 1\n")
    assert run("check", str(mesh)).returncode == 1  # affinity.toml wins in the same folder
    put(tmp_path, "assets/affinity.toml", "[thresholds]\nQ101 = 1000\n")
    assert run("check", str(mesh)).returncode == 0  # the nearer one wins
    assert run("check", "--threshold", "1", str(mesh)).returncode == 1  # the flag wins
    assert run("check", "--isolated", str(mesh)).returncode == 1
    assert run("check", "--config", str(tmp_path / "affinity.toml"), str(mesh)).returncode == 1


def test_per_file_ignores_and_exclude_end_to_end(tmp_path):
    put(tmp_path, "affinity.toml", "exclude = ['wip']\n[per-file-ignores]\n'legacy/*' = ['Q101']\n")
    for rel in ("new/bad.obj", "legacy/bad.obj", "wip/bad.obj"):
        put(tmp_path, rel, BAD)
    result = run("check", "--format", "json", ".", cwd=tmp_path)
    assert result.returncode == 1, result.stderr
    doc = json.loads(result.stdout)
    assert [f["path"] for f in doc["files"]] == ["legacy/bad.obj", "new/bad.obj"]
    assert [(f["path"], f["code"]) for f in doc["findings"]] == [("new/bad.obj", "Q101")]
    # Excluded even when named, as pre-commit names every file.
    named = run("check", "wip/bad.obj", cwd=tmp_path)
    assert named.returncode == 0 and "0 files checked" in named.stdout


def test_show_settings_prints_the_resolved_values_and_their_source(tmp_path):
    config = put(tmp_path, "pyproject.toml", "[tool.affinity]\nignore = ['Q202']\ntexture-size = 2048\n")
    result = run("check", "--show-settings", "--threshold", "Q102=3", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert f"# from {config}" in out
    for line in ('ignore = ["Q202"]', "texture-size = 2048", "Q101 = 0.5", "Q102 = 3.0"):
        assert f"\n{line}\n" in out
    # What it prints is itself a valid affinity.toml with the same meaning.
    (tmp_path / "copy").mkdir()
    (tmp_path / "copy" / "affinity.toml").write_text(out)
    again = run("check", "--show-settings", cwd=tmp_path / "copy").stdout
    assert again.split("# rules enabled")[1] == out.split("# rules enabled")[1]


def test_bad_configuration_is_one_line_and_exit_2(tmp_path):
    put(tmp_path, "affinity.toml", "threshold = 'high'\n")
    result = run("check", str(put(tmp_path, "m.obj", BAD)))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.strip().count("\n") == 0 and "affinity.toml: threshold: expected a number" in result.stderr
