"""Regenerate the OpenSubdiv fixtures in tests/data/subdivision/ (run from the repository root).

    make -C tests/oracle && /work/venv/bin/python tests/oracle/make_fixtures.py

For each mesh: Far's uniform refinement (tests/oracle/osd_refine.cpp) at levels 1-3 under every
face-varying linear-interpolation rule, and under the three boundary rules where the mesh has a boundary;
Spot's control mesh also gets Bfr's limit uv against the cage's bilinear uv (UV drift). One compressed
``NAME.npz`` a mesh; keys ``L{level}_{boundary}_{what}``:

- ``positions`` (V, 3) float64, ``faces`` (F, n) int32 (every refined face has n corners), ``base`` (F,) int32
  (the base face), ``hole`` (F,) bool; ``{fvar}_uv`` (T, 2) float64 and ``{fvar}_uv_faces`` (F, n) int32;
- ``drift_{fvar}`` (S, 7) float64: base face, u, v, limit uv, cage uv (Bfr), for ``--limit-samples``;
- ``options``: the oracle's extra arguments (creases, corners, holes, scheme) as one string;
- ``aliases``: ``KEY=OTHER`` strings, for arrays equal to one stored under another key (the boundary rule
  rarely changes the uv, nor the face-varying rule the refined topology); tests/helpers/osd_fixtures.py
  resolves them.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))
from helpers.corpus import SHARED_MESHES as SHARED  # noqa: E402  (the one spelling of the folder)

ORACLE = ROOT / "tests" / "oracle" / "osd_refine"
OUT = ROOT / "tests" / "data" / "subdivision"
FVAR_RULES = ("none", "cornersOnly", "cornersPlus1", "cornersPlus2", "boundaries", "all")
BOUNDARY_RULES = ("none", "edgeOnly", "edgeAndCorner")
#: Mesh -> (path, levels, whether it has a boundary, the oracle's extra options, limit samples a face).
MESHES = {
    "spot_control_mesh": (SHARED / "spot_control_mesh.obj", (1, 2, 3), False, [], 8),
    "osd_catmark_torus": (SHARED / "osd_catmark_torus.obj", (1, 2, 3), False, [], 0),
    "osd_catmark_nonquads": (SHARED / "osd_catmark_nonquads.obj", (1, 2, 3), True, [], 0),
    "osd_catmark_car": (SHARED / "osd_catmark_car.obj", (1, 2, 3), True, [], 0),
    "osd_catmark_bishop": (SHARED / "osd_catmark_bishop.obj", (1, 2, 3), True, [], 0),
    "creased_cube": (OUT / "creased_cube.obj", (1, 2, 3), False,
                     ["--crease", "0", "1", "1.5", "--crease", "1", "2", "1.5", "--crease", "4", "5", "10",
                      "--corner", "6", "2.5"], 0),
    "holed_grid": (OUT / "holed_grid.obj", (1, 2, 3), True, ["--hole", "5"], 0),
    # vertices 10-14 are the row y = 2; vertex 12 sits on the seam
    "seamed_grid": (OUT / "seamed_grid.obj", (1, 2, 3), True,
                    ["--crease", "10", "11", "0.7", "--crease", "11", "12", "1.5", "--crease", "12", "13", "2.5",
                     "--crease", "13", "14", "1.5", "--corner", "12", "1.2", "--corner", "18", "0.4"], 0),
    "nonquads_bilinear": (SHARED / "osd_catmark_nonquads.obj", (1, 2), True, ["--scheme", "bilinear"], 0),
}


def refine(path: Path, level: int, boundary: str, fvar: str, extra: list[str], samples: int = 0) -> dict:
    """Run the oracle and parse its records (osd_refine.cpp's header) into arrays."""
    text = subprocess.run([str(ORACLE), str(path), "--level", str(level), "--boundary", boundary, "--fvar", fvar,
                           "--limit-samples", str(samples), *extra],
                          check=True, capture_output=True, text=True).stdout
    rows = {"v": [], "t": [], "f": [], "d": []}
    for line in text.splitlines():
        tag, _, rest = line.partition(" ")
        if tag in rows:
            rows[tag].append(rest)
    faces = np.array([r.split() for r in rows["f"]], dtype=np.int64)
    n = int(faces[0, 2])
    if not (faces[:, 2] == n).all():
        raise SystemExit(f"{path}: refined faces of different sizes at level {level}")
    out = {"positions": np.array([r.split() for r in rows["v"]], dtype=np.float64),
           "uv": np.array([r.split() for r in rows["t"]], dtype=np.float64),
           "base": faces[:, 0].astype(np.int32), "hole": faces[:, 1].astype(bool),
           "faces": faces[:, 3:3 + n].astype(np.int32), "uv_faces": faces[:, 3 + n:].astype(np.int32)}
    if rows["d"]:
        d = np.array([r.split() for r in rows["d"]], dtype=np.float64)
        out["drift"] = np.delete(d, 1, axis=1)  # the sample's number is its row
    return out


#: The face-varying rules whose limit uv (UV drift) is sampled.
DRIFT_RULES = ("none", "cornersPlus1", "all")


def _store(arrays: dict, aliases: list, key: str, array: np.ndarray) -> None:
    """Put ``array`` under ``key``, or an alias when an equal array of the same kind (the key's last word:
    ``positions``, ``faces``, ``uv``, ...) is stored already."""
    kind = key.rsplit("_", 1)[-1]
    for other, stored in arrays.items():
        if other.rsplit("_", 1)[-1] == kind and stored.shape == array.shape and np.array_equal(stored, array):
            aliases.append(f"{key}={other}")
            return
    arrays[key] = array


def fixture(name: str) -> dict:
    path, levels, has_boundary, extra, samples = MESHES[name]
    arrays, aliases = {"options": np.array(" ".join(extra))}, []
    for level in levels:
        for boundary in BOUNDARY_RULES if has_boundary else ("edgeAndCorner",):
            key = f"L{level}_{boundary}"
            for fvar in FVAR_RULES:
                sampled = level == 1 and boundary == "edgeAndCorner" and fvar in DRIFT_RULES
                found = refine(path, level, boundary, fvar, extra, samples if sampled else 0)
                if fvar == FVAR_RULES[0]:
                    for what in ("positions", "faces", "base", "hole"):
                        _store(arrays, aliases, f"{key}_{what}", found[what])
                _store(arrays, aliases, f"{key}_{fvar}_uv", found["uv"])
                _store(arrays, aliases, f"{key}_{fvar}_uv_faces", found["uv_faces"])
                if "drift" in found:
                    arrays[f"drift_{fvar}"] = found["drift"]
    arrays["aliases"] = np.array(aliases)
    return arrays


def main(names: list[str]) -> None:
    if not ORACLE.exists():
        raise SystemExit(f"build the oracle first: make -C {ORACLE.parent}")
    for name in names or MESHES:
        target = OUT / f"{name}.npz"
        np.savez_compressed(target, **fixture(name))
        print(f"{target.relative_to(ROOT)}: {target.stat().st_size / 1e6:.2f} MB")


if __name__ == "__main__":
    main(sys.argv[1:])
