"""USD stage speed: ``affinity check`` on a big ``.usdc`` against the bare open + extract.

Writes (once) a stage with one mesh of ``--quads`` quads on a wavy grid, with
``st`` and ``normals`` per vertex, then runs every case in a fresh process and
reports the time of the call itself, the wall time of the whole process
(interpreter start and imports included) and its peak resident memory:

- ``bare open + extract``: importing pxr, ``Usd.Stage.Open`` and every mesh
  array handed to NumPy, the floor any USD reader pays;
- ``affinity.loaders.load``: the same stage as one :class:`~affinity.mesh.Mesh`
  (world-space points, per-corner index arrays);
- ``affinity check``: the command as a user runs it (load, every rule, output),
  and with ``--select Q205`` (no quad rule) to show what the rules cost.

    python benchmarks/bench_usd.py                   # 1M quads, .usdc in a temp dir
    python benchmarks/bench_usd.py --quads 200000 --path /tmp/grid.usda
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile

import numpy as np
from bench_load import generated_input, run

BARE = """
import sys, time
t = time.perf_counter()
import numpy as np
from pxr import Usd, UsdGeom
stage = Usd.Stage.Open(sys.argv[1])
for prim in stage.Traverse():
    if prim.IsA(UsdGeom.Mesh):
        mesh, st = UsdGeom.Mesh(prim), UsdGeom.PrimvarsAPI(prim).GetPrimvar("st")
        arrays = [np.asarray(a.Get()) for a in (mesh.GetPointsAttr(), mesh.GetFaceVertexCountsAttr(),
                  mesh.GetFaceVertexIndicesAttr(), mesh.GetNormalsAttr(), st)]
print(time.perf_counter() - t)
"""
LOAD = """
import sys, time
t = time.perf_counter()
from affinity.loaders import load
load(sys.argv[1])
print(time.perf_counter() - t)
"""


def write_grid_stage(path: str, quads: int) -> None:
    """A stage with one mesh: ``quads`` quads on an n x m grid, ``st`` and ``normals`` per vertex."""
    from pxr import Sdf, Usd, UsdGeom, Vt

    n = int(np.ceil(np.sqrt(quads)))
    m = -(-quads // n)
    v, u = np.indices((m + 1, n + 1)).reshape(2, -1) / np.array([[m], [n]])
    points = np.stack([10 * u - 5, 10 * v - 5, 0.3 * np.sin(7 * u) * np.cos(5 * v)], axis=1)
    corner = (np.arange(m)[:, None] * (n + 1) + np.arange(n)).ravel()[:quads]
    indices = np.stack([corner, corner + 1, corner + n + 2, corner + n + 1], axis=1)

    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    mesh = UsdGeom.Mesh.Define(stage, "/Grid")
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(points.astype(np.float32)))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(quads, 4, dtype=np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(indices.ravel().astype(np.int32)))
    normals = np.stack([np.zeros_like(u), np.sin(v), np.cos(v)], axis=1).astype(np.float32)
    mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(normals))
    mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
    st.Set(Vt.Vec2fArray.FromNumpy(np.stack([u, v], axis=1).astype(np.float32)))
    stage.Save()


def measure(command: list[str], timed: bool) -> list[str]:
    """[call s, process s, peak RSS MiB]; the call time is what the child printed last."""
    wall, peak, out, code = run(command)
    if code not in (0, 1):
        return ["failed", f"{wall:.2f} (exit {code})", f"{peak:.0f}"]
    return [f"{float(out.split()[-1]):.2f}" if timed else "-", f"{wall:.2f}", f"{peak:.0f}"]


def print_table(cases: list[tuple[str, list[str], bool]], repeat: int) -> None:
    """A Markdown table: per case ``(name, command, timed)``, the fastest of ``repeat`` runs."""
    print("| case | call s | process s | peak RSS MiB |")
    print("|---|---:|---:|---:|")
    for name, command, timed in cases:
        rows = [measure(command, timed) for _ in range(repeat)]
        best = min(rows, key=lambda r: float(r[1].split()[0]))
        print(f"| {name} | " + " | ".join(best) + " |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quads", type=int, default=1_000_000, help="quads in the generated stage (default 1,000,000)")
    parser.add_argument("--path",
                        help="stage to use (.usdc or .usda); generated there when missing (default: a temp .usdc)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per case; the fastest is reported")
    args = parser.parse_args(argv)

    with tempfile.TemporaryDirectory() as folder:
        path = generated_input(args.path or os.path.join(folder, f"grid_{args.quads}.usdc"), args.quads,
                               write_grid_stage)
        check = [shutil.which("affinity") or "affinity", "check", "-q"]
        print_table([
            ("bare open + extract (pxr, NumPy)", [sys.executable, "-c", BARE, path], True),
            ("affinity.loaders.load", [sys.executable, "-c", LOAD, path], True),
            ("affinity check -q --select Q205 (no quad rule)", [*check, "--select", "Q205", path], False),
            ("affinity check -q", [*check, path], False),
        ], args.repeat)


if __name__ == "__main__":
    main()
