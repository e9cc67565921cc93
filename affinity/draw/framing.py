"""Framing: where the camera stands when the user names none, and which way is up."""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh

UP_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: Default view direction (from the target toward the eye) for each up axis: in front, to the right, above.
VIEW_DIRECTIONS = {"x": (1.0, 0.6, 0.5), "y": (0.6, 0.5, 1.0), "z": (0.6, -1.0, 0.5)}


def up_axis_of(mesh: Mesh, up: str | None = None) -> str:
    """The up axis to draw ``mesh`` with: ``up`` when given, else the file's (USD ``upAxis``), else y."""
    return up or (mesh.up_axis or "y").lower()


def working_up(forward: np.ndarray, up_axis: str) -> tuple[float, float, float]:
    """The up vector for a camera looking along unit ``forward`` (3,): the ``up_axis``, or, when
    the camera looks along it (top-down), the other world axis most across the view (z, then y, then x)."""
    up = UP_AXES[up_axis]
    if np.linalg.norm(np.cross(forward, up)) > 1e-6:
        return up
    others = [axis for axis in ("z", "y", "x") if axis != up_axis]
    return UP_AXES[min(others, key=lambda axis: abs(float(np.dot(forward, UP_AXES[axis]))))]


def camera_for(mesh: Mesh, width: int, height: int, camera: tuple | None = None, up: str | None = None):
    """A ``render.camera.Camera`` for an image of ``width`` x ``height`` pixels.

    ``camera`` is ``(eye, target, vertical fov in degrees)``; None frames the
    mesh's used vertices from the default direction of its up axis
    (:func:`up_axis_of`); a camera looking straight along the up axis gets another
    up (:func:`working_up`). Raises ValueError when the eye and the target coincide
    or the field of view is not in (0, 180).
    """
    from render.camera import Camera, frame_bounds

    aspect = width / height
    up_axis = up_axis_of(mesh, up)
    up = UP_AXES[up_axis]
    chosen = camera
    if chosen is None:
        used = np.unique(mesh.corner_vertex)
        points = mesh.positions[used]
        return frame_bounds(points.min(axis=0), points.max(axis=0), aspect=aspect, up=up,
                            direction=VIEW_DIRECTIONS[up_axis])
    eye, target, fov = chosen
    distance = float(np.linalg.norm(np.subtract(eye, target)))
    if not distance > 0:
        raise ValueError("--camera: the eye and the target coincide")
    if not 0 < fov < 180:
        raise ValueError(f"--camera: the field of view must lie between 0 and 180 degrees, got {fov:g}")
    up = working_up(np.subtract(target, eye) / distance, up_axis)
    extent = float(np.ptp(mesh.positions, axis=0).max()) if len(mesh.positions) else 1.0
    far = distance + 2.0 * max(extent, distance)
    return Camera(eye=tuple(eye), target=tuple(target), up=up, fov_y=fov, aspect=aspect,
                  near=far * 1e-4, far=far)
