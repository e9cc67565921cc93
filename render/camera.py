"""Cameras: view and projection matrices in float64, and the model -> clip transform.

Conventions are OpenGL's: column vectors (clip = M @ [x, y, z, 1]), a
right-handed eye space looking down -z, and clip space whose NDC cube is
[-1, 1]^3 with the near plane at NDC z = -1 (so smaller depth is nearer, the
rasterizer's depth test is "less"). The renderer itself only sees clip-space
quads; this module is how callers get there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """View matrix (4, 4) float64 taking world points to eye space.

    The eye goes to the origin, ``target`` onto the -z axis, ``up`` into the
    upper half of the y-z plane. ``up`` must not be parallel to the view
    direction.
    """
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    forward = _unit(target - eye, "target - eye")
    right = _unit(np.cross(forward, up), "up x view direction")
    true_up = np.cross(right, forward)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, true_up, -forward
    view[:3, 3] = -view[:3, :3] @ eye
    return view


def perspective(fov_y, aspect, near, far) -> np.ndarray:
    """Perspective projection (4, 4) float64.

    Parameters
    ----------
    fov_y : float
        Vertical field of view in degrees.
    aspect : float
        Width / height of the image.
    near, far : float
        Distances of the clipping planes, 0 < near < far. Eye-space depth
        -near maps to NDC z = -1 and -far to +1; clip w is the distance in
        front of the eye (w = -z_eye), negative behind it.
    """
    if not 0 < near < far:
        raise ValueError(f"need 0 < near < far, got near={near}, far={far}")
    f = 1.0 / np.tan(np.radians(fov_y) / 2)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = f
    m[2, 2] = (far + near) / (near - far)
    m[2, 3] = 2 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def orthographic(half_height, aspect, near, far) -> np.ndarray:
    """Orthographic projection (4, 4) float64 of the box |y| <= half_height,
    |x| <= half_height * aspect, -far <= z_eye <= -near; clip w is always 1."""
    if not near < far:
        raise ValueError(f"need near < far, got near={near}, far={far}")
    m = np.eye(4)
    m[0, 0] = 1.0 / (half_height * aspect)
    m[1, 1] = 1.0 / half_height
    m[2, 2] = -2.0 / (far - near)
    m[2, 3] = -(far + near) / (far - near)
    return m


def to_clip(points, matrix) -> np.ndarray:
    """Clip coordinates (..., 4) float64 of points (..., 3) under ``matrix`` (4, 4)."""
    points = np.asarray(points, dtype=np.float64)
    matrix = np.asarray(matrix, dtype=np.float64)
    return points @ matrix[:, :3].T + matrix[:, 3]


@dataclass(frozen=True)
class Camera:
    """A look-at camera with a perspective or orthographic projection.

    ``fov_y`` (degrees) is used by the perspective projection, ``half_height``
    by the orthographic one. ``matrix`` is projection @ view, ready for
    ``to_clip``.
    """

    eye: tuple
    target: tuple
    up: tuple = (0.0, 1.0, 0.0)
    fov_y: float = 40.0
    aspect: float = 1.0
    near: float = 0.1
    far: float = 100.0
    projection: str = "perspective"
    half_height: float = 1.0

    @property
    def view(self) -> np.ndarray:
        """World -> eye matrix (4, 4) float64."""
        return look_at(self.eye, self.target, self.up)

    @property
    def projection_matrix(self) -> np.ndarray:
        """Eye -> clip matrix (4, 4) float64."""
        if self.projection == "perspective":
            return perspective(self.fov_y, self.aspect, self.near, self.far)
        if self.projection == "orthographic":
            return orthographic(self.half_height, self.aspect, self.near, self.far)
        raise ValueError(f"unknown projection {self.projection!r} (perspective, orthographic)")

    @property
    def matrix(self) -> np.ndarray:
        """World -> clip matrix (4, 4) float64."""
        return self.projection_matrix @ self.view


def frame_bounds(
    lower,
    upper,
    aspect=1.0,
    fov_y=40.0,
    direction=(0.6, 0.5, 1.0),
    up=(0.0, 1.0, 0.0),
    projection="perspective",
) -> Camera:
    """A camera that sees the whole box [lower, upper] (each (3,)).

    The eye looks at the box centre from ``direction`` (world, need not be
    unit), far enough that the box's bounding sphere fits the narrower of the
    two fields of view; near and far planes enclose the sphere with a margin.
    A box of zero size is treated as a unit sphere around its point.
    """
    lower, upper = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)
    centre = (lower + upper) / 2
    radius = np.linalg.norm(upper - lower) / 2
    if not radius > 0:
        radius = 1.0
    half_fov = np.radians(fov_y) / 2
    narrow = min(half_fov, np.arctan(np.tan(half_fov) * aspect))
    distance = radius / np.sin(narrow)
    eye = centre + distance * _unit(np.asarray(direction, dtype=np.float64), "direction")
    return Camera(
        eye=tuple(eye),
        target=tuple(centre),
        up=tuple(up),
        fov_y=fov_y,
        aspect=aspect,
        near=max(distance - 1.05 * radius, 1e-3 * distance),
        far=distance + 1.05 * radius,
        projection=projection,
        half_height=1.05 * radius / min(1.0, aspect),
    )


def _unit(v, what) -> np.ndarray:
    n = np.linalg.norm(v)
    if not n > 0:
        raise ValueError(f"{what} has zero length")
    return v / n
