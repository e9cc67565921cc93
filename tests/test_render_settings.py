"""Every consumer of the lint takes the file's resolved settings: the hybrid's lint route and the uv
routing read the configuration ``affinity check`` reads (issue 27)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.cli import TRAPEZOID, run

from affinity.draw import RenderOptions, render_mesh

# TRAPEZOID carries the unit square's uv: 176 texels of split error, far above Q101's 0.5.
LINT_ROUTE = {"method": "hybrid", "route": "lint", "show": "uv", "width": 64, "height": 64,
              "camera": ((0.0, 0.5, 3.0), (0.0, 0.5, 0.0), 60.0)}


@pytest.fixture
def configured(tmp_path):
    """The trapezoid under an affinity.toml that sets Q101's threshold above its 256 texels."""
    (tmp_path / "affinity.toml").write_text("[thresholds]\nQ101 = 1000\n")
    (tmp_path / "models").mkdir()
    path = tmp_path / "models" / "trapezoid.obj"
    path.write_text(TRAPEZOID)
    return path


def test_lint_route_without_configuration_sends_the_trapezoid_to_mvc(tmp_path):
    path = tmp_path / "trapezoid.obj"
    path.write_text(TRAPEZOID)
    assert list(render_mesh(str(path), RenderOptions(**LINT_ROUTE)).methods) == ["mvc"]


def test_configured_threshold_is_the_lint_routes_threshold(configured):
    check = run("check", str(configured), cwd=configured.parent)
    assert check.returncode == 0 and "Q101" not in check.stdout, check.stdout + check.stderr
    result = render_mesh(str(configured), RenderOptions(**LINT_ROUTE))
    assert list(result.methods) == ["split"]
    assert result.settings.threshold("Q101") == 1000


def test_render_command_with_the_configuration_routes_nothing_to_mvc(configured):
    done = run("render", str(configured), "-o", str(configured.with_suffix(".png")), "--route", "lint",
               cwd=configured.parent)
    assert done.returncode == 0, done.stderr
    assert "hybrid: 0 of 1 quads to mvc" in done.stderr


def test_explicit_settings_win_over_the_configuration(configured):
    from affinity.settings import Settings

    result = render_mesh(str(configured), RenderOptions(**LINT_ROUTE, settings=Settings()))
    assert list(result.methods) == ["mvc"]


def test_ignoring_the_rule_in_the_configuration_routes_nothing_to_mvc(tmp_path):
    (tmp_path / "pyproject.toml").write_text('[tool.affinity]\nignore = ["Q101"]\n')
    path = tmp_path / "trapezoid.obj"
    path.write_text(TRAPEZOID)
    assert list(render_mesh(str(path), RenderOptions(**LINT_ROUTE)).methods) == ["split"]


def test_configured_q301_threshold_decides_which_uv_quads_are_degenerate(tmp_path):
    """A uv quad of relative area 1e-6: not degenerate at Q301's default 1e-9, degenerate at 1e-3 (then the
    lint's uv error and the screen scale route it, not the displacement)."""
    from affinity.draw.drawing import uv_routing_inputs
    from affinity.loaders import load
    from affinity.settings import Settings

    thin = TRAPEZOID.replace("vt 1 1\nvt 0 1", "vt 1 1e-6\nvt 0 1e-6")
    path = tmp_path / "thin.obj"
    path.write_text(thin)
    mesh = load(str(path))
    uv = np.array([[[0, 0], [1, 0], [1, 1e-6], [0, 1e-6]]], dtype=float)
    default, _ = uv_routing_inputs(mesh, np.array([0]), uv, Settings())
    configured, uv_error = uv_routing_inputs(mesh, np.array([0]), uv, Settings(thresholds={"Q301": 1e-3}))
    assert not default.degenerate[0]
    assert configured.degenerate[0] and uv_error is not None and uv_error[0] > 0


def test_render_result_carries_its_camera_clip_corners_and_tinted_layer(tmp_path):
    """The clip corners are the camera's matrix applied to the corners (checked against a projection written
    here), ``tinted`` differs from ``image`` exactly on the mvc pixels, and ``overlay`` returns it as ``image``."""
    path = tmp_path / "trapezoid.obj"
    path.write_text(TRAPEZOID)
    result = render_mesh(str(path), RenderOptions(**LINT_ROUTE))
    corners = np.array([[-1, 0, 0], [1, 0, 0], [0.5, 1, 0], [-0.5, 1, 0]], dtype=float)
    homogeneous = np.c_[corners, np.ones(4)] @ np.asarray(result.camera.matrix).T
    np.testing.assert_allclose(result.clip[0], homogeneous)
    assert result.clip.shape == (1, 4, 4) and result.inputs.attrs.shape == (1, 4, 2)
    changed = (result.tinted != result.image).any(axis=2)
    assert result.mvc_pixels.any()
    np.testing.assert_array_equal(changed, result.mvc_pixels)
    overlaid = render_mesh(str(path), RenderOptions(**LINT_ROUTE, overlay=True))
    np.testing.assert_array_equal(overlaid.image, result.tinted)
