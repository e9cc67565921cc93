"""render.camera: view and projection matrices against their defining properties."""

import itertools

import numpy as np
import pytest

from render import Camera, frame_bounds, look_at, orthographic, perspective, to_clip


def ndc(points, matrix):
    clip = to_clip(points, matrix)
    return clip[:, :3] / clip[:, 3:]


def test_look_at_puts_eye_at_origin_and_target_on_minus_z():
    eye, target = np.array([1.0, 2.0, 3.0]), np.array([-2.0, 0.5, -1.0])
    view = look_at(eye, target, up=(0, 1, 0))
    moved = to_clip(np.array([eye, target, eye + [0, 1, 0]]), view)
    assert np.allclose(moved[0], [0, 0, 0, 1])
    assert np.allclose(moved[1, :2], 0) and moved[1, 2] == pytest.approx(-np.linalg.norm(target - eye))
    assert moved[2, 1] > 0  # world up stays up
    assert np.allclose(view[:3, :3] @ view[:3, :3].T, np.eye(3))  # a rigid motion
    with pytest.raises(ValueError):
        look_at(eye, eye + [0, 1, 0], up=(0, 1, 0))


def test_perspective_maps_near_far_and_field_of_view():
    near, far, fov, aspect = 0.5, 20.0, 60.0, 1.5
    proj = perspective(fov, aspect, near, far)
    top = np.tan(np.radians(fov / 2))
    points = np.array([[0, 0, -near], [0, 0, -far], [0, top * 7, -7], [aspect * top * 3, 0, -3], [0, 0, 2.0]])
    clip = to_clip(points, proj)
    z = clip[:, 2] / clip[:, 3]
    assert z[0] == pytest.approx(-1) and z[1] == pytest.approx(1)
    assert clip[2, 1] / clip[2, 3] == pytest.approx(1)
    assert clip[3, 0] / clip[3, 3] == pytest.approx(1)
    assert np.allclose(clip[:4, 3], [near, far, 7, 3])  # w is the distance in front of the eye
    assert clip[4, 3] < 0  # behind the eye
    with pytest.raises(ValueError):
        perspective(60, 1, 0.0, 1.0)


def test_orthographic_maps_its_box_to_the_ndc_cube():
    proj = orthographic(2.0, 0.5, 1.0, 9.0)
    corners = np.array(list(itertools.product([-1.0, 1.0], [-2.0, 2.0], [-1.0, -9.0])))
    result = ndc(corners, proj)
    assert np.allclose(np.abs(result), 1)
    assert np.allclose(to_clip(corners, proj)[:, 3], 1)
    assert ndc(np.array([[0, 0, -1.0]]), proj)[0, 2] == pytest.approx(-1)


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
@pytest.mark.parametrize("aspect", [1.0, 2.0, 0.5])
def test_frame_bounds_sees_the_whole_box(projection, aspect):
    lower, upper = np.array([-3.0, 0.5, 10.0]), np.array([5.0, 2.0, 12.0])
    camera = frame_bounds(lower, upper, aspect=aspect, projection=projection)
    corners = np.array(list(itertools.product(*zip(lower, upper))))
    clip = to_clip(corners, camera.matrix)
    assert (clip[:, 3] > 0).all()
    assert (np.abs(clip[:, :3] / clip[:, 3:]) <= 1).all()
    # ... and fills a fair part of the view.
    assert np.abs(clip[:, :2] / clip[:, 3:]).max() > 0.4


def test_camera_projects_points_where_the_pinhole_puts_them():
    """Closed form of a pinhole camera, from the eye's own axes (forward f, right r = f x up, up u = r x f):
    a point at depth d = (p - eye).f lands at NDC x = (p - eye).r / (d tan(fov/2) aspect),
    y = (p - eye).u / (d tan(fov/2)), z = (far + near) / (far - near) - 2 far near / ((far - near) d), w = d."""
    eye, target, fov, aspect, near, far = np.array([0.0, 1.0, 5.0]), np.zeros(3), 45.0, 4 / 3, 0.1, 50.0
    camera = Camera(eye=tuple(eye), target=tuple(target), fov_y=fov, aspect=aspect, near=near, far=far)
    f = (target - eye) / np.linalg.norm(target - eye)
    r = np.cross(f, [0.0, 1.0, 0.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    half = np.tan(np.radians(fov / 2))
    d = np.linalg.norm(target - eye)
    named = {  # where a point lands, by construction
        "target": (target, (0, 0)),
        "top edge": (target + u * d * half, (0, 1)),
        "right edge": (target + r * d * half * aspect, (1, 0)),
        "bottom-left corner": (target - u * d * half - r * d * half * aspect, (-1, -1)),
    }
    for name, (point, (x, y)) in named.items():
        clip = to_clip(point[None], camera.matrix)[0]
        np.testing.assert_allclose(clip[:2] / clip[3], (x, y), atol=1e-12, err_msg=name)
        assert clip[3] == pytest.approx(d)
    np.testing.assert_allclose(ndc(np.array([eye + near * f, eye + far * f]), camera.matrix)[:, 2], [-1, 1])
    points = np.random.default_rng(0).normal(size=(10, 3))
    offset = points - eye
    depth = offset @ f
    expected = np.column_stack([
        offset @ r / (depth * half * aspect),
        offset @ u / (depth * half),
        (far + near) / (far - near) - 2 * far * near / ((far - near) * depth),
    ])
    clip = to_clip(points, camera.matrix)
    assert clip.dtype == np.float64
    np.testing.assert_allclose(clip[:, 3], depth, rtol=1e-12)
    np.testing.assert_allclose(clip[:, :3] / clip[:, 3:], expected, rtol=1e-10, atol=1e-12)
    with pytest.raises(ValueError):
        _ = Camera(eye=(0, 0, 1), target=(0, 0, 0), projection="fisheye").matrix
