"""The built-in demo scenes of ``affinity report`` and the view each is shown from."""

from __future__ import annotations

from dataclasses import dataclass

from ..hybrid import DEMO_CAMERA
from ..scenes import DEMO, DEMO_DIR


@dataclass(frozen=True)
class View:
    """How the report looks at one mesh.

    ``camera`` is ``RenderOptions.camera`` (eye, target, vertical field of view
    in degrees) and ``up`` its up axis; None frames the mesh automatically.
    ``checks``: draw the texture as a checker with this many squares across
    instead of the mesh's own texture or the default fine checker.
    """

    camera: tuple | None = None
    up: str | None = None
    checks: int | None = None


@dataclass(frozen=True)
class MeshInput:
    """A mesh to report on: its path, the name the report gives it, and its view."""

    path: str
    label: str
    view: View = View()


#: Straight-on views of the flat scenes: the image plane is parallel to the mesh,
#: so the perspective is a similarity and the picture is the paper's front view.
#: The trapezoid (Bloomenthal Fig. 3) gets a 12-square checker: coarse enough for
#: the crease along its diagonal to read at 480 pixels, fine enough to see it bend.
DEMO_VIEWS = {
    "trapezoid.obj": View(camera=((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), 12.0), up="y", checks=12),
    "sphere.obj": View(camera=DEMO_CAMERA, up="z"),
    "color_squares.obj": View(camera=((1.25, 0.5, 10.0), (1.25, 0.5, 0.0), 12.0), up="y"),
}


def demo_inputs() -> list[MeshInput]:
    """Every bundled demo scene (``affinity.scenes.DEMO``), each with its view."""
    return [MeshInput(str(DEMO_DIR / name), f"{name} (built-in demo)", DEMO_VIEWS.get(name, View())) for name in DEMO]
