"""OpenSubdiv's uniform refinement of small meshes, committed as fixtures (tests/data/subdivision/, written
by tests/oracle/make_fixtures.py from Far and Bfr): reading them, and the mesh and options each was made from."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .corpus import SHARED_MESHES

FIXTURES = Path(__file__).resolve().parents[1] / "data" / "subdivision"
FVAR_RULES = ("none", "cornersOnly", "cornersPlus1", "cornersPlus2", "boundaries", "all")
#: Fixture -> the mesh it refines.
MESHES = {
    "spot_control_mesh": SHARED_MESHES / "spot_control_mesh.obj",
    "osd_catmark_torus": SHARED_MESHES / "osd_catmark_torus.obj",
    "osd_catmark_nonquads": SHARED_MESHES / "osd_catmark_nonquads.obj",
    "osd_catmark_car": SHARED_MESHES / "osd_catmark_car.obj",
    "osd_catmark_bishop": SHARED_MESHES / "osd_catmark_bishop.obj",
    "nonquads_bilinear": SHARED_MESHES / "osd_catmark_nonquads.obj",
    "creased_cube": FIXTURES / "creased_cube.obj",
    "holed_grid": FIXTURES / "holed_grid.obj",
    "seamed_grid": FIXTURES / "seamed_grid.obj",
}


def load_fixture(name: str) -> dict:
    """The arrays of fixture ``name``, aliases resolved: key -> array (keys in make_fixtures.py's docstring)."""
    with np.load(FIXTURES / f"{name}.npz") as stored:
        arrays = {key: stored[key] for key in stored.files}
    for alias in arrays.pop("aliases", ()):
        key, _, target = str(alias).partition("=")
        arrays[key] = arrays[target]
    return arrays


def scheme_options(arrays: dict) -> dict:
    """The oracle's extra arguments of a fixture (its ``options``) as keyword arguments of
    ``affinity.subdivision.Scheme``: scheme, crease_edges and crease_sharpness, corner_vertices and
    corner_sharpness, holes."""
    words = str(arrays["options"]).split()
    found = {"crease_edges": [], "crease_sharpness": [], "corner_vertices": [], "corner_sharpness": [], "holes": []}
    scheme, i = "catmullClark", 0
    while i < len(words):
        if words[i] == "--crease":
            found["crease_edges"].append((int(words[i + 1]), int(words[i + 2])))
            found["crease_sharpness"].append(float(words[i + 3]))
            i += 4
        elif words[i] == "--corner":
            found["corner_vertices"].append(int(words[i + 1]))
            found["corner_sharpness"].append(float(words[i + 2]))
            i += 3
        elif words[i] == "--hole":
            found["holes"].append(int(words[i + 1]))
            i += 2
        else:  # --scheme NAME
            scheme = {"bilinear": "bilinear"}.get(words[i + 1], "catmullClark")
            i += 2
    return {"scheme": scheme, "crease_edges": np.array(found["crease_edges"], dtype=np.int64).reshape(-1, 2),
            "crease_sharpness": np.array(found["crease_sharpness"]),
            "corner_vertices": np.array(found["corner_vertices"], dtype=np.int64),
            "corner_sharpness": np.array(found["corner_sharpness"]), "holes": np.array(found["holes"], dtype=np.int64)}


def refinements(arrays: dict) -> list[tuple[int, str]]:
    """(level, boundary rule) of every refinement a fixture holds."""
    keys = {key.rsplit("_", 1)[0] for key in arrays if key.endswith("_positions")}
    return sorted((int(key[1:key.index("_")]), key.split("_", 1)[1]) for key in keys)
