"""The NumPy rasterizer against a second one: Mesa llvmpipe through OpenGL (``helpers.opengl_reference``).

split draws the two triangles with OpenGL's perspective-correct interpolation, mvc evaluates the
perspective mean value coordinates in a fragment shader; coverage and depth are the GPU's own.
llvmpipe works in float32, so frames must agree to float32 precision: the same face on all but
the pixels whose centres lie within rounding of an edge, attributes to ``ATTRIBUTE_TOLERANCE``.
Needs an EGL context (``apt-get install libegl1 libgl1-mesa-dri libegl-mesa0``, ``pip install
moderngl``; .ci/run installs both), and skips, with the reason, only when none can be created.
"""

import numpy as np
import pytest
from helpers.opengl_reference import create_context, render_opengl

from render import rasterize_quads
from render.camera import look_at, perspective, to_clip

ATTRIBUTE_TOLERANCE = 2e-5
FACE_SHARE = 1e-3  # of the covered pixels, centres within float32 rounding of an edge


@pytest.fixture(scope="module")
def gl():
    try:
        ctx = create_context()
    except Exception as error:  # moderngl missing, or no EGL device / driver
        pytest.skip(f"no OpenGL 4.3 context on EGL: {type(error).__name__}: {error}")
    yield ctx
    ctx.release()


def sphere_scene(n_lon=24, n_lat=12, eye=(0.4, 0.5, 1.6)):
    """A lat-long sphere in perspective: clip (Q, 4, 4), and uv with a colour-like third channel
    (Q, 4, 3). Its pole quads are far from affine, so mvc differs from split there."""
    lon, lat = np.meshgrid(np.linspace(0, 2 * np.pi, n_lon + 1), np.linspace(-1.5, 1.5, n_lat + 1), indexing="ij")
    points = np.stack([np.cos(lat) * np.cos(lon), np.sin(lat), np.cos(lat) * np.sin(lon)], axis=-1)
    values = np.stack([lon / (2 * np.pi), lat / 3 + 0.5, 0.5 + 0.5 * np.sin(3 * lon) * np.cos(lat)], axis=-1)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n_lon), np.arange(n_lat), indexing="ij"))
    ring = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)]
    corners = np.stack([points[a, b] for a, b in ring], axis=1)
    matrix = perspective(70, 1.25, 0.05, 10) @ look_at(eye, (0, 0, 0))
    clip = to_clip(corners.reshape(-1, 3), matrix).reshape(-1, 4, 4)
    return clip, np.stack([values[a, b] for a, b in ring], axis=1)


def trapezoids():
    """Screen-space trapezoids at w = 1 and in depth, overlapping: uv far from affine on them."""
    quads = np.array(
        [
            [[-0.9, -0.8], [0.7, -0.9], [0.3, 0.6], [-0.5, 0.8]],
            [[-0.2, -0.3], [0.95, -0.1], [0.9, 0.9], [0.1, 0.5]],
            [[-0.9, 0.7], [-0.2, 0.95], [-0.1, 0.0], [-0.95, 0.1]],  # clockwise: culled
        ]
    )
    w = np.array([[1.0, 1.3, 2.0, 1.6], [1.0, 1.0, 1.0, 1.0], [0.7, 1.1, 1.4, 0.9]])[..., None]
    z = np.array([0.1, -0.2, 0.3])[:, None, None] * np.ones((3, 4, 1))
    clip = np.concatenate([quads * w, z * w, w], axis=2)
    uv = np.array([[[0, 0], [1, 0], [1, 1], [0, 1]]] * 3, dtype=float)
    return clip, uv


SCENES = {
    "sphere": sphere_scene,
    # From inside, looking at the pole: quads cross the eye plane (corners with w < 0), both
    # renderers clip them in homogeneous space, and the far wall faces away from the eye.
    "inside sphere": lambda: sphere_scene(eye=(0.1, -0.3, 0.2)),
    "trapezoids": trapezoids,
}


def assert_frames_agree(frame, face, attrs):
    covered = (frame.face >= 0) | (face >= 0)
    same = (frame.face == face) & (face >= 0)
    assert np.count_nonzero(covered & ~same) <= FACE_SHARE * covered.sum()
    assert np.abs(frame.attrs[same] - attrs[same]).max(initial=0.0) < ATTRIBUTE_TOLERANCE
    return covered.sum()


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("method", ["split", "mvc"])
@pytest.mark.parametrize("cull", [False, True])
def test_numpy_frame_agrees_with_llvmpipe(gl, scene, method, cull):
    clip, attrs = SCENES[scene]()
    frame = rasterize_quads(clip, attrs, 160, 128, method, cull_backfaces=cull)
    face, gl_attrs = render_opengl(gl, clip, attrs, 160, 128, method, cull_backfaces=cull)
    covered = assert_frames_agree(frame, face, gl_attrs)
    if cull and scene == "inside sphere":
        assert covered == 0  # seen from inside, every face turns away from the eye
    else:
        assert covered > 10_000


def test_llvmpipe_tells_mvc_from_split(gl):
    # The agreement above would also hold if both renderers drew the same wrong method: on the
    # sphere's pole quads mvc and split differ by far more than the tolerance, in both renderers.
    clip, attrs = sphere_scene()
    frames = {m: render_opengl(gl, clip, attrs, 160, 128, m) for m in ("split", "mvc")}
    same = (frames["split"][0] == frames["mvc"][0]) & (frames["mvc"][0] >= 0)
    gap = np.abs(frames["split"][1][same] - frames["mvc"][1][same]).max()
    assert gap > 100 * ATTRIBUTE_TOLERANCE
    numpy_gap = np.abs(rasterize_quads(clip, attrs, 160, 128, "split").attrs - frames["mvc"][1])[same].max()
    assert numpy_gap > 100 * ATTRIBUTE_TOLERANCE
