"""Text that holds no mesh fails fast (issue 53): statements without geometry (``o``, ``s``, ``usemtl``,
``mtllib``, ...) past the budget of a 2 MiB stretch (:data:`~affinity.loaders.obj.scan.STATEMENT_BUDGET`,
4,096, plus four per v/vt/vn/f line) are one Q901 line at the statement past it, before any is read one
by one; an exporter that writes ``g``, ``usemtl`` and ``s`` before every face stays within it.

The costs (64 MB of ``o x`` lines against a valid 64 MB OBJ) are in benchmarks/bench_no_geometry.py."""

from __future__ import annotations

import pytest
from helpers.cli import run, write

from affinity.loaders import load
from affinity.loaders.obj.scan import STATEMENT_BUDGET

QUAD = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"


@pytest.mark.parametrize("statement", ["o x", "s 1", "usemtl m", "g part", "mtllib {k}.mtl"])
def test_a_file_of_statements_without_geometry_is_one_q901_line_at_the_statement_past_the_budget(
        tmp_path, statement):
    lines = [statement.format(k=k) for k in range(100_000)]
    path = write(tmp_path, "junk.obj", "\n".join(lines) + "\n" + QUAD)
    done = run("check", str(path))
    assert done.returncode == 2
    (line,) = done.stderr.splitlines()
    # one stretch (under 2 MiB) holds them all and the quad's 9 lines: a budget of 4,096 + 4 x 9
    assert line.startswith(f"{path}:{STATEMENT_BUDGET + 4 * 9 + 1}: Q901 unreadable: 100,000 statements "
                           "(o, g, s, usemtl, mtllib, ...) beside 9 v/vt/vn/f lines")
    assert line.endswith("more than 4,096 plus 4 per geometry line, not a mesh")


def test_statements_before_every_face_are_within_the_budget(tmp_path):
    """50,000 quads, each after its own ``g``, ``usemtl`` and ``s`` line (three statements a face, against a
    budget of four per geometry line): every face is read, with its group and material."""
    n = 50_000
    body = ["mtllib none.mtl"]
    for k in range(n):
        body += [f"v {k} 0 0", f"v {k + 1} 0 0", f"v {k + 1} 1 0", f"v {k} 1 0", f"g g{k}", f"usemtl m{k % 7}",
                 f"s {k % 2}", f"f {4 * k + 1} {4 * k + 2} {4 * k + 3} {4 * k + 4}"]
    mesh = load(write(tmp_path, "many.obj", "\n".join(body) + "\n"))
    assert mesh.n_faces == n
    assert len(mesh.group_names) == n and mesh.material_names[:7] == [f"m{k}" for k in range(7)]


def test_a_few_thousand_statements_with_no_geometry_are_still_read(tmp_path):
    """At the budget (4,096 ``o`` lines, then the quad): the file is a mesh as before."""
    path = write(tmp_path, "objects.obj", "o x\n" * STATEMENT_BUDGET + QUAD)
    assert load(path).n_faces == 1
