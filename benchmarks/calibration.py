"""The calibration table of the README: what the default gate says about real and generated meshes.

For every mesh of ``../shared/meshes/MANIFEST.json`` and three generated
families (a trapezoid whose uv is subdivided ever finer, a jittered grid with
the unit square as every quad's uv, a clean planar unwrap of a gently curved
sheet), one Markdown row: quads, the texture size the texels are counted in,
the largest uv error (Q101's reading over every quad, in texels), the Q101
findings by level, the other error-level findings, and the exit code of
``affinity check`` with the defaults (no configuration file). The defaults
should exit 0 where the largest uv error is under the visibility threshold
(2 texels) and nothing else is an error, 1 where it is over.

    python benchmarks/calibration.py [--small] [--out DIR] [--meshes FOLDER]

writes ``DIR/calibration.md`` (default ``reports/bench``) and the raw rows as
``calibration.json`` beside it. ``--small`` checks only the generated meshes,
at small sizes (a few seconds).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from affinity.lint import quad_scores, texture_grid
from affinity.loaders import load
from affinity.rules import RULES
from affinity.settings import Settings

ROOT = Path(__file__).resolve().parents[1]
MESHES = ROOT.parent / "shared" / "meshes"
HEAD = ["mesh", "quads", "texture", "largest uv error", "Q101 warning", "Q101 error", "other errors", "exit"]


def quad_grid_obj(positions: np.ndarray, uv: np.ndarray, per_face_uv: bool = False) -> str:
    """An OBJ of the (n+1, m+1) grid of ``positions`` (n+1, m+1, 3) as n*m quads; ``uv`` (n+1, m+1, 2)
    per vertex, or with ``per_face_uv`` the unit square on every quad (``uv`` unused)."""
    rows, cols = positions.shape[:2]
    index = np.arange(rows * cols).reshape(rows, cols) + 1
    corners = np.stack([index[:-1, :-1], index[:-1, 1:], index[1:, 1:], index[1:, :-1]], axis=-1).reshape(-1, 4)
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in positions.reshape(-1, 3)]
    if per_face_uv:
        lines += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
        lines += [f"f {a}/1 {b}/2 {c}/3 {d}/4" for a, b, c, d in corners]
    else:
        lines += [f"vt {u:.9g} {v:.9g}" for u, v in uv.reshape(-1, 2)]
        lines += [f"f {a}/{a} {b}/{b} {c}/{c} {d}/{d}" for a, b, c, d in corners]
    return "\n".join(lines) + "\n"


def subdivided_trapezoid(k: int) -> str:
    """The paper's trapezoid (bottom 2, top 1 wide) cut into k x k quads, its unit-square uv interpolated
    bilinearly: every sub-quad is a small trapezoid, so the error falls like 1/k^2."""
    s, t = np.meshgrid(np.linspace(0, 1, k + 1), np.linspace(0, 1, k + 1))
    half = 1 - 0.5 * t  # half width at height t
    positions = np.stack([(2 * s - 1) * half, t, np.zeros_like(s)], axis=-1)
    return quad_grid_obj(positions, np.stack([s, t], axis=-1))


def jittered_unit_uv(n: int) -> str:
    """An n x n grid with its vertices jittered by up to a fifth of a cell and the unit square as every
    quad's uv (a per-face unwrap): each quad is a random quadrilateral under a square of texture."""
    rng = np.random.default_rng(7)
    x, y = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0))
    positions = np.stack([x, y, np.zeros_like(x)], axis=-1)
    positions[..., :2] += rng.uniform(-0.2, 0.2, (n + 1, n + 1, 2))
    return quad_grid_obj(positions, positions[..., :2], per_face_uv=True)


def planar_unwrap(n: int) -> str:
    """A gently curved sheet (height 0.02 sin) over an n x n grid, uv its planar projection scaled to the
    unit square: an artist's clean unwrap, nearly affine on every quad."""
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    z = 0.02 * np.sin(2 * np.pi * x) * np.cos(2 * np.pi * y)
    return quad_grid_obj(np.stack([x, y, z], axis=-1), np.stack([x, y], axis=-1))


def generated(small: bool) -> dict[str, str]:
    """Name -> OBJ text of the generated calibration meshes."""
    n = 16 if small else 64
    return {
        "gen_trapezoid_sub8.obj": subdivided_trapezoid(8),
        "gen_trapezoid_sub16.obj": subdivided_trapezoid(16),
        "gen_trapezoid_sub32.obj": subdivided_trapezoid(32),
        f"gen_jittered_unit_uv_{n}.obj": jittered_unit_uv(n),
        f"gen_planar_unwrap_{n}.obj": planar_unwrap(n),
    }


def measure(path: Path) -> dict:
    """One mesh's row: quads, texture, largest Q101 value, finding counts and the default gate's exit."""
    mesh = load(str(path))
    settings = Settings()
    largest = None
    if mesh.texcoords is not None:
        values = quad_scores(mesh, settings, "Q101").values
        largest = float(values.max()) if len(values) else None
    (width, height), assumed = texture_grid(mesh, settings)
    result = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--isolated", "--no-cache",
                             "--format", "json", str(path)], capture_output=True, text=True, check=False)
    doc = json.loads(result.stdout)
    levels = [f["level"] for f in doc["findings"] if f["code"] == "Q101"]
    others = sum(f["level"] == "error" and f["code"] != "Q101" for f in doc["findings"])
    return {
        "mesh": path.name, "quads": int((mesh.face_sizes == 4).sum()),
        "texture": "-" if mesh.texcoords is None else f"{width}x{height}" + (" assumed" if assumed else ""),
        "largest": largest, "warning": levels.count("warning"), "error": levels.count("error"),
        "others": int(others), "exit": result.returncode,
    }


def table(rows: list[dict]) -> str:
    unit = RULES["Q101"].unit
    lines = ["| " + " | ".join(HEAD) + " |", "|---|---:|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        largest = "-" if r["largest"] is None else f"{r['largest']:.3g} {unit}"
        lines.append(f"| {r['mesh']} | {r['quads']:,} | {r['texture']} | {largest} | {r['warning']:,} "
                     f"| {r['error']:,} | {r['others']:,} | {r['exit']} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", action="store_true", help="generated meshes only, small sizes")
    parser.add_argument("--out", type=Path, default=ROOT / "reports" / "bench", help="folder for the table")
    parser.add_argument("--meshes", type=Path, default=MESHES, help="folder with MANIFEST.json")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    paths = []
    if not args.small and (args.meshes / "MANIFEST.json").is_file():
        manifest = json.loads((args.meshes / "MANIFEST.json").read_text())
        paths = [args.meshes / entry["file"] for entry in manifest]
    with tempfile.TemporaryDirectory() as folder:
        for name, text in generated(args.small).items():
            (Path(folder) / name).write_text(text)
            paths.append(Path(folder) / name)
        rows = [measure(path) for path in paths]
    (args.out / "calibration.json").write_text(json.dumps(rows, indent=1) + "\n")
    (args.out / "calibration.md").write_text(table(rows))
    sys.stdout.write(table(rows))


if __name__ == "__main__":
    main()
