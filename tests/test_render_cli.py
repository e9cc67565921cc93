"""`affinity render` end to end, and the hybrid's defining property."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from helpers.cli import run as run_affinity
from PIL import Image

from affinity.draw.drawing import RenderOptions, render_mesh
from affinity.loaders.objwriter import write_obj
from affinity.scenes import color_squares, latlong_sphere, trapezoid


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return run_affinity("render", *args, cwd=cwd)


def test_demo_render_with_no_mesh(tmp_path):
    out = tmp_path / "demo.png"
    result = run("-o", str(out), "--size", "320x240")
    assert result.returncode == 0, result.stderr
    assert "quads to mvc" in result.stderr
    image = np.asarray(Image.open(out))
    assert image.shape == (240, 320, 3)
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 50  # a textured sphere, not a blank frame


def test_hybrid_equals_mvc_on_routed_quads_and_split_elsewhere():
    options = dict(width=200, height=160)
    hybrid = render_mesh(None, RenderOptions(method="hybrid", **options))
    mvc = render_mesh(None, RenderOptions(method="mvc", **options))
    split = render_mesh(None, RenderOptions(method="split", **options))
    routed = hybrid.methods == "mvc"
    assert 0 < routed.sum() < len(routed)
    face = hybrid.frame.face
    covered = face >= 0
    on_mvc = covered & routed[np.maximum(face, 0)]
    on_split = covered & ~routed[np.maximum(face, 0)]
    np.testing.assert_array_equal(face[on_mvc], mvc.frame.face[on_mvc])
    np.testing.assert_allclose(hybrid.frame.attrs[on_mvc], mvc.frame.attrs[on_mvc], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(face[on_split], split.frame.face[on_split])
    np.testing.assert_allclose(hybrid.frame.attrs[on_split], split.frame.attrs[on_split], rtol=0, atol=1e-12)
    # The split is visibly different from mvc on the routed quads: that is why they were routed.
    assert np.abs(split.frame.attrs[on_mvc] - mvc.frame.attrs[on_mvc]).max() > 1e-3


def test_affine_and_tiny_quads_stay_split(tmp_path):
    # A fine sphere seen whole at a small size: the split error is below half a pixel everywhere.
    path = tmp_path / "fine.obj"
    write_obj(latlong_sphere(200, 100), path)
    result = render_mesh(str(path), RenderOptions(width=64, height=64, up="z"))
    assert (result.methods == "mvc").mean() < 0.05
    # An affine quad (a square with square uv) is never routed, however close.
    square = tmp_path / "square.obj"
    square.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
    near = render_mesh(str(square), RenderOptions(width=400, height=400, camera=((0, -0.5, 1.2), (0, 0, 0), 90)))
    assert (near.frame.face >= 0).mean() > 0.5 and list(near.methods) == ["split"]


def test_route_lint_and_overlay(tmp_path):
    path = tmp_path / "trapezoid.obj"
    write_obj(trapezoid(), path)
    out = tmp_path / "t.png"
    result = run(str(path), "-o", str(out), "--route", "lint", "--overlay", "flags", "--size", "64x64",
                 "--camera", "0,0,3,0,0,0,60", "--up", "y")
    assert result.returncode == 0, result.stderr
    assert "1 of 1 quads to mvc" in result.stderr
    pixels = np.asarray(Image.open(out)).reshape(-1, 3).astype(int)
    assert ((pixels[:, 0] > 200) & (pixels[:, 1] < 150)).sum() > 100  # the magenta tint


def test_show_color_renders_vertex_colours(tmp_path):
    path = tmp_path / "colours.obj"
    write_obj(color_squares(), path)
    out = tmp_path / "c.png"
    assert run(str(path), "-o", str(out), "--size", "120x60", "--camera", "1.25,0.5,2.2,1.25,0.5,0,60").returncode == 0
    image = np.asarray(Image.open(out)).astype(int)
    assert image[..., 2].max() > 200 and image[..., 0].max() > 200  # blue and red corners


@pytest.mark.parametrize(
    "args, message",
    [
        (["--size", "0x10"], "at least 1x1"),
        (["--camera", "0,0,0,0,0,0,40"], "coincide"),
        (["--camera", "0,0,-5,0,0,-10,40", "--up", "y"], "behind the camera"),
        (["--texture", "missing.png"], "no such texture"),
        (["--texture", "junk.png"], "not a readable image"),
    ],
)
def test_bad_render_input_is_exit_2_and_writes_nothing(tmp_path, args, message):
    path = tmp_path / "trapezoid.obj"
    write_obj(trapezoid(), path)
    (tmp_path / "junk.png").write_bytes(b"not a png")
    out = tmp_path / "out.png"
    result = run(str(path), "-o", str(out), *args, cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_unrenderable_meshes_are_exit_2(tmp_path):
    cases = {
        "points.obj": ("v 0 0 0\nv 1 0 0\n", "no faces"),
        "nan.obj": ("v 0 0 0\nv 1 nan 0\nv 1 1 0\nf 1 2 3\n", "nan.obj:2"),
    }
    for name, (text, message) in cases.items():
        (tmp_path / name).write_text(text)
        result = run(str(tmp_path / name), "-o", str(tmp_path / "out.png"))
        assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "out.png").exists()
    missing_dir = run("-o", str(tmp_path / "no" / "such" / "dir.png"))
    assert missing_dir.returncode == 2 and "cannot write" in missing_dir.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(cases)  # no output, no temporary left over


def test_missing_map_kd_warns_and_falls_back_to_the_checker(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl skin\nmap_Kd missing_texture.png\n")
    (tmp_path / "q.obj").write_text(
        "mtllib m.mtl\nusemtl skin\nv -1 -1 0\nv 1 -1 0\nv 0.5 1 0\nv -0.5 1 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"
    )
    result = run(str(tmp_path / "q.obj"), "-o", str(tmp_path / "q.png"), "--size", "32x32", "--up", "y")
    assert result.returncode == 0, result.stderr
    assert "warning" in result.stderr and "missing_texture.png" in result.stderr
    assert (tmp_path / "q.png").exists()


def test_quads_crossing_the_eye_plane_render_without_nan():
    # The eye sits on the demo sphere's equator (a vertex): quads around it cross the eye plane w = 0.
    eye_on_sphere = (1.0, 0.0, 0.0)
    result = render_mesh(None, RenderOptions(width=64, height=64, camera=(eye_on_sphere, (0.0, 0.0, 0.0), 90.0)))
    covered = result.frame.face >= 0
    assert covered.any() and not np.isnan(result.frame.attrs[covered]).any()
