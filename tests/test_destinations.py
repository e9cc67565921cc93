"""Outputs never follow links, never replace an input (issue 53): ``affinity fix`` with a symlinked
``NAME.fixed.EXT`` (to its input, to another file) refuses in one line and both targets keep their bytes;
``affinity fix a.obj a.fixed.obj`` never replaces the second input; the ``-o`` of check, merge, render and
report refuses a link to a file and a path that is one of the run's inputs, and still writes to
``/dev/stdout``-like links to a stream."""

from __future__ import annotations

import os

import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, write

from affinity.atomic import UnsafeDestination, refuse_unsafe


def test_fix_refuses_a_default_output_linked_to_its_input(tmp_path):
    vase = write(tmp_path, "vase.obj", TRAPEZOID)
    (tmp_path / "vase.fixed.obj").symlink_to("vase.obj")
    done = run("fix", "--max-refine", "24", str(vase))
    assert done.returncode == 2
    assert done.stderr.splitlines() == [
        f"{vase}: cannot write {tmp_path / 'vase.fixed.obj'}: is a symbolic link (to vase.obj): an output is never "
        "written through a link; remove it or name a plain file"]
    assert vase.read_text() == TRAPEZOID
    assert os.readlink(tmp_path / "vase.fixed.obj") == "vase.obj"


def test_fix_refuses_a_default_output_linked_to_another_file(tmp_path):
    vase = write(tmp_path, "vase.obj", TRAPEZOID)
    precious = write(tmp_path, "precious.txt", "keep me\n")
    (tmp_path / "vase.fixed.obj").symlink_to(precious)
    done = run("fix", "--max-refine", "24", str(vase))
    assert done.returncode == 2 and "is a symbolic link" in done.stderr
    assert len(done.stderr.splitlines()) == 1
    assert precious.read_text() == "keep me\n" and vase.read_text() == TRAPEZOID


def test_fix_of_a_and_its_default_output_b_never_replaces_b(tmp_path):
    """b.obj is a.obj's default output and an input of the same run: a's fix is refused (one line), b is read
    and fixed as it was (its own fix beside it), exit 2."""
    a = write(tmp_path, "a.obj", TRAPEZOID)
    b_text = TRAPEZOID.replace("v 0.5 1 0", "v 0.6 1 0")
    b = write(tmp_path, "a.fixed.obj", b_text)
    done = run("fix", "--max-refine", "24", str(a), str(b))
    assert done.returncode == 2
    assert f"{a}: cannot write {b}: is the input {b}: an output never replaces an input" in done.stderr.splitlines()
    assert b.read_text() == b_text and a.read_text() == TRAPEZOID
    assert (tmp_path / "a.fixed.fixed.obj").exists()


def test_fix_without_links_still_writes_beside_the_input(tmp_path):
    vase = write(tmp_path, "vase.obj", TRAPEZOID)
    assert run("fix", "--max-refine", "24", str(vase)).returncode == 0
    assert (tmp_path / "vase.fixed.obj").is_file() and not (tmp_path / "vase.fixed.obj").is_symlink()


@pytest.mark.parametrize("command", ["check", "report", "render"])
def test_o_refuses_a_link_to_a_file_and_the_input(tmp_path, command):
    mesh = write(tmp_path, "m.obj", SQUARE)
    precious = write(tmp_path, "precious.txt", "keep me\n")
    link = tmp_path / "out.link"
    link.symlink_to(precious)
    option = {"check": "-o", "report": "-o", "render": "-o"}[command]
    for target in (link, mesh):
        done = run(command, str(mesh), option, str(target))
        assert done.returncode == 2, done.stderr
        assert ("is a symbolic link" if target == link else "is the input") in done.stderr
        assert "Traceback" not in done.stderr
    assert precious.read_text() == "keep me\n" and mesh.read_text() == SQUARE and link.is_symlink()


def test_merge_o_refuses_one_of_its_results(tmp_path):
    mesh = write(tmp_path, "m.obj", TRAPEZOID)
    shard = write(tmp_path, "shard.json", run("check", "--shard", "1/1", "--format", "json", str(mesh)).stdout)
    before = shard.read_text()
    done = run("merge", "--format", "json", "-o", str(shard), str(shard))
    assert done.returncode == 2 and "is the input" in done.stderr
    assert shard.read_text() == before


def test_a_link_to_a_stream_is_written(tmp_path):
    """``-o /dev/stdout`` is a link to a stream on Linux: written, not refused."""
    if not os.path.islink("/dev/stdout"):
        pytest.skip("no /dev/stdout link on this system")
    refuse_unsafe("/dev/stdout", [])
    mesh = write(tmp_path, "m.obj", TRAPEZOID)
    done = run("check", "--format", "json", "-o", "/dev/stdout", str(mesh))
    assert done.returncode == 1 and '"Q101"' in done.stdout


def test_refuse_unsafe_names_why(tmp_path):
    plain = write(tmp_path, "plain.txt", "x")
    refuse_unsafe(tmp_path / "new.txt", [plain])
    refuse_unsafe(plain, [])
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere")
    with pytest.raises(UnsafeDestination, match="symbolic link"):
        refuse_unsafe(tmp_path / "dangling")
    (tmp_path / "sub").mkdir()
    with pytest.raises(UnsafeDestination, match="is the input"):
        refuse_unsafe(tmp_path / "sub" / ".." / "plain.txt", [plain])
