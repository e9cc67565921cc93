"""Issue 17 as a user meets it: broken files, skipped files and outputs that must not be destroyed.

Every command runs as ``helpers.cli.run`` runs it (exit code, stdout, stderr: file descriptors 1
and 2 are pipes); FIFOs, links and device nodes are made in tmp_path.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import stat
import struct
import subprocess
import sys

import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, write
from helpers.nodes import make_null_device, read_fifo_in_background

from affinity.errors import SkippedFile

LFS_POINTER = "version https://git-lfs.github.com/spec/v1\noid sha256:0123\nsize 123456\n"
requires_usd = pytest.mark.skipif(importlib.util.find_spec("pxr") is None, reason="needs the usd extra (usd-core)")


def binary_ply(vertices: int, body: bytes) -> bytes:
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\n"
              "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
    return header.encode() + body


TRIANGLE = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2)


def broken_folder(tmp_path):
    folder = tmp_path / "assets"
    folder.mkdir()
    write(folder, "liar.ply", binary_ply(4_000_000_000, TRIANGLE))  # a header lying about its size
    write(folder, "truncated.ply", binary_ply(3, TRIANGLE[:30]))
    write(folder, "junk.usda", "#usda 1.0\n(\n  this is not USD\n")
    write(folder, "one_finding.obj", TRAPEZOID)
    write(folder, "clean.obj", SQUARE)
    return folder


def test_broken_files_are_one_q901_line_each_and_the_others_are_checked(tmp_path):
    folder = broken_folder(tmp_path)
    broken = (["junk.usda", "liar.ply", "truncated.ply"] if importlib.util.find_spec("pxr")
              else ["liar.ply", "truncated.ply"])
    result = run("check", str(folder), "--format", "json")
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    lines = [line for line in result.stderr.splitlines() if "Q901" in line]
    assert sorted(os.path.basename(line.split(":")[0]) for line in lines) == broken
    assert len(lines) == len(result.stderr.splitlines()) - (0 if importlib.util.find_spec("pxr") else 1)
    document = json.loads(result.stdout)
    files = {os.path.basename(f["path"]): f for f in document["files"]}
    assert files["clean.obj"]["quads"] == 1 and "error" not in files["clean.obj"]
    assert [f["code"] for f in document["findings"]] == ["Q101"]
    assert document["findings"][0]["path"].endswith("one_finding.obj")
    assert all("error" in files[name] for name in broken)
    assert "truncated" in files["liar.ply"]["error"] and "4000000000" in files["liar.ply"]["error"]


def test_an_exception_inside_one_file_is_that_files_q901(tmp_path, monkeypatch):
    """A defect in lint (or a MemoryError in a loader) is one file's 'internal error', not the run's end."""
    import affinity.lint
    import affinity.loaders
    from affinity.pipeline.check import check_files
    from affinity.settings import Settings

    good, other = write(tmp_path, "good.obj", SQUARE), write(tmp_path, "other.obj", TRAPEZOID)
    real_lint = affinity.lint.lint_pass

    def failing_lint(mesh, settings, *args, **kwargs):
        if mesh.path.endswith("good.obj"):
            raise IndexError("index 7 is out of bounds for axis 0 with size 4")
        return real_lint(mesh, settings, *args, **kwargs)

    monkeypatch.setattr(affinity.lint, "lint_pass", failing_lint)
    reports = check_files([(str(good), Settings()), (str(other), Settings())], jobs=1)
    assert reports[0].error == "internal error: IndexError: index 7 is out of bounds for axis 0 with size 4"
    assert reports[0].error_line == 0
    assert reports[1].error is None and reports[1].n_findings == 1

    def out_of_memory(path, usd=None, source=None):
        raise MemoryError("Unable to allocate 29.8 GiB for an array with shape (4000000000,)")

    monkeypatch.setattr(affinity.loaders, "load", out_of_memory)
    [report] = check_files([(str(good), Settings())], jobs=1)
    assert report.error.startswith("internal error: MemoryError: Unable to allocate 29.8 GiB")


def test_fail_on_skip(tmp_path):
    write(tmp_path, "big.obj", LFS_POINTER)
    write(tmp_path, "clean.obj", SQUARE)
    assert run("check", str(tmp_path)).returncode == 0
    result = run("check", "--fail-on-skip", str(tmp_path))
    assert result.returncode == 2 and "big.obj: skipped (lfs-pointer)" in result.stderr
    assert "No findings" in result.stdout
    quiet = run("check", "--fail-on-skip", "-q", str(tmp_path))  # the line that explains the exit stays
    assert quiet.returncode == 2 and quiet.stderr.splitlines() == [f"{tmp_path / 'big.obj'}: skipped (lfs-pointer)"]


def test_options_are_never_abbreviated(tmp_path):
    from affinity.cli import build_parser

    result = run("check", "--stat", str(write(tmp_path, "clean.obj", SQUARE)))
    assert result.returncode == 2 and "unrecognized arguments: --stat" in result.stderr
    parser = build_parser()
    [sub] = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    assert not parser.allow_abbrev and sub.choices and not any(p.allow_abbrev for p in sub.choices.values())


@requires_usd
def test_stage_without_a_mesh_is_skipped(tmp_path):
    from affinity.loaders import load

    path = write(tmp_path, "layout.usda", '#usda 1.0\ndef Xform "World"\n{\n    def Xform "Lamp"\n    {\n    }\n}\n')
    with pytest.raises(SkippedFile) as caught:
        load(path)
    assert caught.value.reason == "no-mesh"
    result = run("check", "--format", "json", str(path))
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["files"][0]["skipped"] == "no-mesh"
    assert run("check", "--fail-on-skip", str(path)).returncode == 2


@requires_usd
def test_a_stage_of_materials_and_no_mesh_is_checked_without_findings(tmp_path):
    """A look layer (design.md, Clarifications): checked, no findings, not a skip, so --fail-on-skip passes."""
    path = write(tmp_path, "materials.usda", '#usda 1.0\ndef Material "Wood"\n{\n}\ndef Xform "World"\n{\n}\n')
    result = run("check", "--format", "json", "--fail-on-skip", str(path))
    assert result.returncode == 0, result.stderr
    (entry,) = json.loads(result.stdout)["files"]
    assert "skipped" not in entry and (entry["faces"], entry["findings"]) == (0, 0)


@requires_usd
def test_unreadable_stage_metadata_is_a_note(tmp_path, monkeypatch):
    """Stage metadata of a type pxr will not convert (metersPerUnit stored as float, in some
    USD versions) is read inside the loader's error handling: a note, the meshes still checked."""
    from pxr import UsdGeom

    from affinity.loaders import load

    def refuses(stage):
        raise TypeError("metersPerUnit holds a float, not a double")

    monkeypatch.setattr(UsdGeom, "GetStageMetersPerUnit", refuses)
    scene = os.path.join(os.path.dirname(__file__), "data", "usd", "scene.usda")
    mesh = load(scene)
    assert mesh.meters_per_unit is None and mesh.n_faces > 0
    assert any(note.startswith("the stage's metersPerUnit cannot be read (metersPerUnit holds a float")
               for note in mesh.notes)


def test_render_of_a_skipped_file_is_one_line_and_writes_nothing(tmp_path):
    pointer = write(tmp_path, "big.obj", LFS_POINTER)
    out = tmp_path / "out.png"
    result = run("render", str(pointer), "-o", str(out))
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"affinity render: error: {pointer}: "
                                          "skipped (lfs-pointer): nothing to render"]
    assert not out.exists()


def test_report_of_skipped_files(tmp_path):
    pointer = write(tmp_path, "big.obj", LFS_POINTER)
    out = tmp_path / "report.html"
    single = run("report", "-q", str(pointer), "-o", str(out))
    assert single.returncode == 2
    assert single.stderr.splitlines() == [f"affinity report: error: {pointer}: "
                                          "skipped (lfs-pointer): nothing to report"]
    assert not out.exists()
    several = run("report", "-q", str(pointer), str(write(tmp_path, "clean.obj", SQUARE)), "-o", str(out))
    assert several.returncode == 2, several.stderr
    assert f"{pointer}: skipped (lfs-pointer)" in several.stderr.splitlines()
    assert "skipped (lfs-pointer)" in out.read_text()


RENDER = ("render", "--size", "32x24", "-q")


def test_render_onto_a_fifo_writes_the_png_through_it(tmp_path):
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    received = read_fifo_in_background(fifo)
    result = run(*RENDER, "-o", str(fifo))
    assert result.returncode == 0, result.stderr
    assert received().startswith(b"\x89PNG\r\n\x1a\n")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode) and os.listdir(tmp_path) == ["pipe.png"]


def test_render_onto_a_device_node_keeps_the_node(tmp_path):
    device = make_null_device(tmp_path)
    result = run(*RENDER, "-o", str(device))
    assert result.returncode == 0, result.stderr
    assert stat.S_ISCHR(os.stat(device).st_mode) and os.listdir(tmp_path) == ["null"]


def test_outputs_onto_a_symlink_are_refused_and_the_link_and_its_target_kept(tmp_path):
    """Outputs never follow links (issue 53): one line, exit 2, the link and the file it names as they were."""
    (tmp_path / "store").mkdir()
    mesh = str(write(tmp_path, "trap.obj", TRAPEZOID))  # one quad: its report is written as the demo's is
    commands = {"image.png": [*RENDER, "-o"], "report.html": ["report", mesh, "-q", "--size", "48x36", "-o"],
                "findings.json": ["check", mesh, "--format", "json", "-o"]}
    for name, command in commands.items():
        target = tmp_path / "store" / name
        target.write_text("old")
        link = tmp_path / name
        link.symlink_to(target)
        result = run(*command, str(link))
        assert result.returncode == 2 and result.stderr.count("\n") == 1, (name, result.stderr)
        assert "is a symbolic link" in result.stderr and "Traceback" not in result.stderr, name
        assert link.is_symlink() and os.readlink(link) == str(target), name
        assert target.read_text() == "old", name


def test_stability_folder_files_follow_the_same_rules(tmp_path):
    folder, store = tmp_path / "out", tmp_path / "store"
    folder.mkdir()
    store.mkdir()
    (store / "stability.csv").write_text("old")
    (folder / "stability.csv").symlink_to(store / "stability.csv")
    (folder / "stability.md").mkdir()  # a directory where a file is expected
    result = run("stability", "-o", str(folder))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert (folder / "stability.csv").is_symlink() and (store / "stability.csv").read_text() != "old"
    assert os.listdir(folder / "stability.md") == []


@pytest.mark.parametrize("command", [RENDER, ("report", "-q")])
def test_a_directory_is_refused_where_a_file_is_named(tmp_path, command):
    folder = tmp_path / "out"
    folder.mkdir()
    result = run(*command, "-o", str(folder))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "directory" in result.stderr and os.listdir(folder) == []


def test_baseline_onto_a_directory_is_refused(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    result = run("check", "--write-baseline", str(folder), str(write(tmp_path, "trap.obj", TRAPEZOID)))
    assert result.returncode == 2 and "directory" in result.stderr and os.listdir(folder) == []


def test_render_to_standard_output_through_a_link(tmp_path):
    """A link to the process's own stdout (as /dev/stdout is) on a pipe: the PNG goes down the pipe."""
    link = tmp_path / "stdout.png"
    link.symlink_to("/proc/self/fd/1")
    result = subprocess.run([sys.executable, "-m", "affinity.cli", *RENDER, "-o", str(link)],
                            capture_output=True, timeout=300, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(b"\x89PNG\r\n\x1a\n")
    assert link.is_symlink() and os.listdir(tmp_path) == ["stdout.png"]
