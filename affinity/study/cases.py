"""The scenes of the study and how each is seen.

Built in: the figures of Bloomenthal 2022 rebuilt from their captions
(``affinity.scenes``) with a view that shows what the figure shows, and the
nonplanar quad strip. Real meshes: every mesh of ``../shared/meshes`` when the
folder is there (or the paths given), framed whole by the renderer's default
camera, z up where the corpus manifest says so.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .. import scenes
from ..mesh import Mesh

#: The shared corpus, beside the project's checkout (absent in an installed package).
SHARED_MESHES = Path(__file__).resolve().parents[2].parent / "shared" / "meshes"

#: Views (eye, target, vertical field of view in degrees).
FRONT_OF_TRAPEZOID = ((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), 12.0)  # straight on: every corner has the same w
TILTED_TRAPEZOID = ((0.9, -2.2, 1.6), (0.0, 0.0, 0.0), 40.0)
SPHERE_FROM_ABOVE_EQUATOR = ((0.0, -2.9, 2.1), (0.0, 0.0, 0.05), 40.0)  # the pole rows in view
NORTH_POLE_CLOSE_UP = ((0.0, -0.75, 1.55), (0.0, 0.0, 0.92), 40.0)
STRIP_IN_PERSPECTIVE = ((1.2, 1.5, 3.0), (0.0, 0.0, 0.0), 45.0)


@dataclass(frozen=True)
class Case:
    """One scene of the study: a name, what it rebuilds, the mesh, and the view.

    ``camera`` is ``RenderOptions.camera`` (None frames the whole mesh), ``up``
    its up axis (None: y).
    """

    name: str
    source: str
    mesh: Callable[[], Mesh]
    camera: tuple | None = None
    up: str | None = None


def builtin_cases(quick: bool = False) -> list[Case]:
    """The paper's figures; ``quick`` keeps one of each kind (trapezoid, sphere, strip)."""
    cases = [
        Case("trapezoid front", "Bloomenthal Fig. 3", scenes.trapezoid, FRONT_OF_TRAPEZOID, "y"),
        Case("trapezoid tilted", "Bloomenthal Fig. 3, in perspective", scenes.trapezoid, TILTED_TRAPEZOID, "z"),
        Case("sphere 8x16", "Bloomenthal Fig. 9", lambda: scenes.latlong_sphere(8, 16), SPHERE_FROM_ABOVE_EQUATOR, "z"),
        Case("sphere 30x20", "Bloomenthal Fig. 12 top", lambda: scenes.latlong_sphere(30, 20),
             SPHERE_FROM_ABOVE_EQUATOR, "z"),
        Case("sphere 100x40", "Bloomenthal Fig. 12 bottom", lambda: scenes.latlong_sphere(100, 40),
             SPHERE_FROM_ABOVE_EQUATOR, "z"),
        Case("sphere 100x40 pole", "Bloomenthal Fig. 13 top", lambda: scenes.latlong_sphere(100, 40),
             NORTH_POLE_CLOSE_UP, "z"),
        Case("sphere 100x40 dense poles", "Bloomenthal Fig. 13 bottom",
             lambda: scenes.latlong_sphere(100, 40, dense_poles=True), NORTH_POLE_CLOSE_UP, "z"),
        Case("quad strip", "nonplanar quads (HT04 Fig. 10)", scenes.quad_strip, STRIP_IN_PERSPECTIVE, "y"),
    ]
    if quick:
        return [case for case in cases if case.name in ("trapezoid front", "sphere 8x16", "quad strip")]
    return cases


def shared_mesh_paths(folder: Path = SHARED_MESHES) -> list[str]:
    """The OBJ files of the shared corpus, sorted; empty when the folder is absent."""
    return sorted(str(path) for path in folder.glob("*.obj")) if folder.is_dir() else []


def mesh_cases(paths: list[str]) -> list[Case]:
    """One case per mesh file, framed whole; z up where the corpus manifest's notes say "z-up"."""
    from ..loaders import load

    cases = []
    for path in paths:
        name = os.path.basename(path)
        cases.append(Case(name, "mesh file", lambda path=path: load(path), None, _manifest_up_axis(path)))
    return cases


def _manifest_up_axis(path: str) -> str | None:
    manifest = Path(path).parent / "MANIFEST.json"
    try:
        entries = json.loads(manifest.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    for entry in entries:
        if isinstance(entry, dict) and entry.get("file") == os.path.basename(path):
            return "z" if "z-up" in str(entry.get("notes", "")) else None
    return None
