"""Framing: where the camera stands when the user names none, and which way is up.

The up axis of a mesh is ``--up`` when given, else the file's (USD ``upAxis``),
else a guess from its bounding box and normals (:func:`guess_up_axis`): OBJ, PLY
and OFF files do not say which way is up.
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh

UP_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: Default view direction (from the target toward the eye) for each up axis: in front, to the right, above.
VIEW_DIRECTIONS = {"x": (1.0, 0.6, 0.5), "y": (0.6, 0.5, 1.0), "z": (0.6, -1.0, 0.5)}
#: Two bounding-box extents within this relative difference count as equal in :func:`guess_up_axis`.
EQUAL_EXTENT = 0.01
#: ... and their axis-facing area fractions within this much.
EQUAL_FACING = 0.01
#: The third extent must differ from the two equal ones by more than this (relative).
DISTINCT_EXTENT = 0.05
#: A lying shape (a vehicle on its wheels, a heightfield terrain) is thinnest along up, and the faces facing
#: along that axis (roof, hood, ground) carry at least this many times the area of those facing either other axis.
LYING_FACING = 1.8
#: An overview looks down on the mesh from this far above the horizon (tan of the elevation).
OVERVIEW_ELEVATION = 0.45


def used_points(mesh: Mesh) -> np.ndarray:
    """(U, 3) float64: the positions some face uses, in vertex order (a mask, not ``np.unique``: linear, and
    a face of a million corners made it most of a render's time)."""
    used = np.zeros(len(mesh.positions), dtype=bool)
    used[mesh.corner_vertex] = True
    return mesh.positions[used]


def guess_up_axis(mesh: Mesh) -> str:
    """The up axis of a file that does not name one: ``"z"`` for a shape standing or lying on z, else ``"y"``.

    A surface of revolution (a vase, a chess piece, a torus) stands on its axis:
    when two of the bounding box's extents agree within ``EQUAL_EXTENT`` and the
    area of faces facing along those two axes (normal within ~25 degrees of the
    axis) agrees within ``EQUAL_FACING``, while the third extent differs by more
    than ``DISTINCT_EXTENT``, the third axis is up. A lying shape (a car on its
    wheels, a heightfield terrain) is thinnest along z and its faces face mostly
    along z (``LYING_FACING`` times the area facing x or y): z is up. Everything
    else gets y, the OBJ convention (Maya, Blender's OBJ export, MakeHuman: a
    standing figure faces front and back more than up, but not by that margin).
    """
    from ..geometry import quad_normals
    from .quads import render_corners

    if mesh.n_faces == 0:
        return "y"
    extent = np.ptp(used_points(mesh), axis=0)
    _, corners = render_corners(mesh)
    normals = quad_normals(mesh.positions[mesh.corner_vertex[corners]])
    area = np.linalg.norm(normals, axis=1)
    unit = normals / np.maximum(area, 1e-300)[:, None]
    facing = (area[:, None] * (np.abs(unit) > 0.9)).sum(axis=0) / max(float(area.sum()), 1e-300)
    for up in range(3):
        a, b = [k for k in range(3) if k != up]
        scale = max(extent[a], extent[b], 1e-300)
        if (abs(extent[a] - extent[b]) <= EQUAL_EXTENT * scale and abs(facing[a] - facing[b]) <= EQUAL_FACING
                and abs(extent[up] - scale) > DISTINCT_EXTENT * scale):
            return "xyz"[up]
    along = np.abs(normals).sum(axis=0)  # the area facing along each axis, both ways
    if int(np.argmin(extent)) == 2 and along[2] >= LYING_FACING * max(along[0], along[1]):
        return "z"
    return "y"


def up_axis_of(mesh: Mesh, up: str | None = None) -> str:
    """The up axis to draw ``mesh`` with: ``up`` when given, else the file's (USD ``upAxis``), else
    :func:`guess_up_axis`."""
    return up or (mesh.up_axis.lower() if mesh.up_axis else guess_up_axis(mesh))


def working_up(forward: np.ndarray, up_axis: str) -> tuple[float, float, float]:
    """The up vector for a camera looking along unit ``forward`` (3,): the ``up_axis``, or, when
    the camera looks along it (top-down), the other world axis most across the view (z, then y, then x)."""
    up = UP_AXES[up_axis]
    if np.linalg.norm(np.cross(forward, up)) > 1e-6:
        return up
    others = [axis for axis in ("z", "y", "x") if axis != up_axis]
    return UP_AXES[min(others, key=lambda axis: abs(float(np.dot(forward, UP_AXES[axis]))))]


def overview_direction(mesh: Mesh, up: str) -> tuple[float, float, float]:
    """A view direction (target toward eye) that shows ``mesh`` from its broad side, a little from above.

    Of the two horizontal axes, the eye looks along the one the mesh is thinner
    in (a car is seen from the side, a person from the front), turned a third of
    the way toward the other so depth shows, and raised by ``OVERVIEW_ELEVATION``.
    """
    k = "xyz".index(up)
    a, b = [axis for axis in range(3) if axis != k]
    extent = np.ptp(used_points(mesh), axis=0) if mesh.n_faces else np.ones(3)
    thin, broad = (a, b) if extent[a] <= extent[b] else (b, a)
    direction = np.zeros(3)
    direction[thin], direction[broad], direction[k] = 1.0, 0.35, OVERVIEW_ELEVATION
    return tuple(direction.tolist())


def camera_for(mesh: Mesh, width: int, height: int, camera: tuple | None = None, up: str | None = None,
               direction: tuple | None = None):
    """A ``render.camera.Camera`` for an image of ``width`` x ``height`` pixels.

    ``camera`` is ``(eye, target, vertical fov in degrees)``; None frames the
    mesh's used vertices from ``direction`` (default: the fixed direction of its
    up axis, :data:`VIEW_DIRECTIONS`; the up axis from :func:`up_axis_of`); a
    camera looking straight along the up axis gets another up (:func:`working_up`).
    Raises ValueError when the eye and the target coincide or the field of view is
    not in (0, 180).
    """
    from render.camera import Camera, frame_bounds

    aspect = width / height
    up_axis = up_axis_of(mesh, up)
    up = UP_AXES[up_axis]
    chosen = camera
    if chosen is None:
        points = used_points(mesh)
        return frame_bounds(points.min(axis=0), points.max(axis=0), aspect=aspect, up=up,
                            direction=direction or VIEW_DIRECTIONS[up_axis])
    eye, target, fov = chosen
    distance = float(np.linalg.norm(np.subtract(eye, target)))
    if not distance > 0:
        raise ValueError("--camera: the eye and the target coincide")
    if not 0 < fov < 180:
        raise ValueError(f"--camera: the field of view must lie between 0 and 180 degrees, got {fov:g}")
    up = working_up(np.subtract(target, eye) / distance, up_axis)
    extent = float(np.ptp(used_points(mesh), axis=0).max()) if mesh.n_faces else 1.0  # the drawn vertices only
    far = distance + 2.0 * max(extent, distance)
    return Camera(eye=tuple(eye), target=tuple(target), up=up, fov_y=fov, aspect=aspect,
                  near=far * 1e-4, far=far)


def overview_camera(mesh: Mesh, width: int, height: int, up: str | None = None) -> tuple:
    """``(eye, target, fov)`` of the overview: the whole mesh from :func:`overview_direction`."""
    up_axis = up_axis_of(mesh, up)
    chosen = camera_for(mesh, width, height, None, up_axis, overview_direction(mesh, up_axis))
    return tuple(chosen.eye), tuple(chosen.target), chosen.fov_y
