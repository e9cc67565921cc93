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

A second table gives the visible reading (design.md, "The visible reading") on
textured meshes: ``../shared/meshes/textured`` (Spot with its own texture) and a
generated lat-long sphere under three generated 1024 x 1024 textures, a flat
colour, a checker and text. Per mesh: Q101's findings (quads whose shift is at or
over the flag threshold), their levels on the texel reading (error over 2 texels)
and on the visible reading (C through the texture), how many of the visible
values are lower bounds (``at least``), and the exit code.

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

from affinity.lint import quad_scores, quad_texel_grid
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
    quads = np.flatnonzero(mesh.face_sizes == 4)
    grid = quad_texel_grid(mesh, settings)  # each quad's texture, as the lint binds it; one here
    width, height = (int(side) for side in np.asarray(grid.of(quads), dtype=float).reshape(-1, 2)[0])
    assumed = bool(grid.assumed[quads].all())
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


VISIBLE_HEAD = ["textured mesh", "texture", "Q101 findings", "texel reading: warning / error",
                "visible reading: info / warning / error", "at least", "exit"]
TEXTURE_SIZE = 1024


def lat_long_sphere(columns: int = 64, rows: int = 32) -> str:
    """A unit sphere of ``columns`` x ``rows`` quads, uv its longitude and latitude (each row of quads a
    trapezoid under a rectangle of texture, narrower towards the poles)."""
    u, v = np.meshgrid(np.linspace(0, 1, columns + 1), np.linspace(0, 1, rows + 1))
    longitude, latitude = 2 * np.pi * u, np.pi * (v - 0.5)
    positions = np.stack([np.cos(latitude) * np.cos(longitude), np.cos(latitude) * np.sin(longitude),
                          np.sin(latitude)], axis=-1)
    return quad_grid_obj(positions, np.stack([u, v], axis=-1))


def generated_textures(folder: Path) -> dict[str, str]:
    """Name -> what it is, of three 1024 x 1024 PNG textures written to ``folder``: a flat colour, a checker
    of 32 squares across, and lines of text."""
    from PIL import Image, ImageDraw

    Image.new("RGB", (TEXTURE_SIZE, TEXTURE_SIZE), (180, 140, 90)).save(folder / "flat.png")
    cells = (np.arange(TEXTURE_SIZE) * 32) // TEXTURE_SIZE
    checker = np.where(((cells[:, None] + cells[None, :]) % 2)[..., None] == 0, 235, 40).astype(np.uint8)
    Image.fromarray(np.repeat(checker, 3, axis=2)).save(folder / "checker.png")
    text = Image.new("RGB", (TEXTURE_SIZE, TEXTURE_SIZE), "white")
    draw = ImageDraw.Draw(text)
    for row in range(0, TEXTURE_SIZE, 14):
        draw.text((4, row), "quad affinity: the split shifts the texture where uv is not affine " * 2, fill="black")
    text.save(folder / "text.png")
    return {"flat.png": "flat colour", "checker.png": "checker", "text.png": "text"}


def textured(folder: Path, meshes: Path) -> list[tuple[Path, str]]:
    """(OBJ, texture label) of the textured calibration meshes: the shared textured Spot when present, and the
    generated sphere under each generated texture (an OBJ and MTL per texture, in ``folder``)."""
    cases = []
    spot = meshes / "textured" / "spot_control_mesh_textured.obj"
    if spot.is_file():
        cases.append((spot, "spot_texture.png (its own)"))
    sphere = lat_long_sphere()
    for name, label in generated_textures(folder).items():
        stem = f"gen_uv_sphere_64x32_{Path(name).stem}"
        (folder / f"{stem}.mtl").write_text(f"newmtl m\nmap_Kd {name}\n")
        (folder / f"{stem}.obj").write_text(f"mtllib {stem}.mtl\nusemtl m\n" + sphere)
        cases.append((folder / f"{stem}.obj", f"{name} ({label})"))
    return cases


def measure_visible(path: Path, texture: str) -> dict:
    """One textured mesh's row: Q101's findings by level on the texel and the visible reading."""
    result = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--isolated", "--no-cache",
                             "--format", "json", "--select", "Q101", str(path)], capture_output=True, text=True,
                            check=False)
    findings = json.loads(result.stdout)["findings"]
    shifts = [f.get("shift", f["value"]) for f in findings]
    visible = [f["level"] for f in findings]
    return {"mesh": path.name, "texture": texture, "findings": len(findings),
            "texel": [sum(s <= 2 for s in shifts), sum(s > 2 for s in shifts)],
            "visible": [visible.count(level) for level in ("info", "warning", "error")],
            "at_least": sum(f.get("bound") == "at least" for f in findings), "exit": result.returncode}


def visible_table(rows: list[dict]) -> str:
    lines = ["| " + " | ".join(VISIBLE_HEAD) + " |", "|---|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['mesh']} | {r['texture']} | {r['findings']:,} | {r['texel'][0]:,} / {r['texel'][1]:,} "
                     f"| {' / '.join(f'{n:,}' for n in r['visible'])} | {r['at_least']:,} | {r['exit']} |")
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
        visible_rows = [measure_visible(path, texture) for path, texture in textured(Path(folder), args.meshes)]
    (args.out / "calibration.json").write_text(json.dumps(rows, indent=1) + "\n")
    (args.out / "calibration_visible.json").write_text(json.dumps(visible_rows, indent=1) + "\n")
    text = table(rows) + "\n" + visible_table(visible_rows)
    (args.out / "calibration.md").write_text(text)
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
