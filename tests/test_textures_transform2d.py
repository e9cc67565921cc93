"""UsdPreviewSurface texture transforms: a ``UsdTransform2d`` between a ``UsdUVTexture``'s ``st`` and its
primvar reader moves where the texture is read (scale, then rotate counter-clockwise in degrees, then
translate: the UsdPreviewSurface specification), on hand-built stages."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run

pytest.importorskip("pxr")

#: A trapezoid (side ratio 1/2) carrying the unit square of uv: Q101 flags it (its page's example).
POINTS = "(-1, 0, 0), (1, 0, 0), (0.5, 1, 0), (-0.5, 1, 0)"
UNIT_SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def stage_text(uv: np.ndarray, transform: dict | None) -> str:
    """A usda stage: the trapezoid with ``uv`` (4, 2) as its st primvar, bound to a UsdPreviewSurface whose
    diffuseColor reads ``ramp.png`` through ``st``, with a UsdTransform2d of ``transform`` (scale, rotation,
    translation) between the texture and the primvar reader, or none."""
    st = ", ".join(f"({u!r}, {v!r})" for u, v in uv.tolist())
    reader = "</Looks/M/Transform.outputs:result>" if transform else "</Looks/M/Reader.outputs:result>"
    transform_shader = "" if not transform else (
        '        def Shader "Transform"\n        {\n            uniform token info:id = "UsdTransform2d"\n'
        "            float2 inputs:in.connect = </Looks/M/Reader.outputs:result>\n"
        + "".join(f"            {'float' if name == 'rotation' else 'float2'} inputs:{name} = {value}\n"
                  for name, value in transform.items())
        + "            float2 outputs:result\n        }\n")
    return ("#usda 1.0\n"
            'def Mesh "Quad" (\n    prepend apiSchemas = ["MaterialBindingAPI"]\n)\n{\n'
            "    int[] faceVertexCounts = [4]\n    int[] faceVertexIndices = [0, 1, 2, 3]\n"
            f"    point3f[] points = [{POINTS}]\n"
            f'    texCoord2f[] primvars:st = [{st}] (interpolation = "faceVarying")\n'
            "    rel material:binding = </Looks/M>\n}\n"
            'def Scope "Looks"\n{\n    def Material "M"\n    {\n'
            "        token outputs:surface.connect = </Looks/M/Surface.outputs:surface>\n"
            '        def Shader "Surface"\n        {\n            uniform token info:id = "UsdPreviewSurface"\n'
            "            color3f inputs:diffuseColor.connect = </Looks/M/Tex.outputs:rgb>\n"
            "            token outputs:surface\n        }\n"
            '        def Shader "Tex"\n        {\n            uniform token info:id = "UsdUVTexture"\n'
            "            asset inputs:file = @ramp.png@\n"
            f"            float2 inputs:st.connect = {reader}\n            float3 outputs:rgb\n        }}\n"
            f"{transform_shader}"
            '        def Shader "Reader"\n        {\n            uniform token info:id = "UsdPrimvarReader_float2"\n'
            '            string inputs:varname = "st"\n            float2 outputs:result\n        }\n'
            "    }\n}\n")


def by_the_specification(uv: np.ndarray, scale, rotation: float, translation) -> np.ndarray:
    """UsdTransform2d's result for ``uv`` (n, 2), written out here from the specification."""
    scaled = uv * np.asarray(scale)
    angle = np.radians(rotation)
    rotated = scaled @ np.array([[np.cos(angle), np.sin(angle)], [-np.sin(angle), np.cos(angle)]])
    return rotated + np.asarray(translation)


def ramp_texture(path: Path) -> None:
    """64 x 64: red climbs 0 -> 255 across the columns, green 0 -> 100 down the rows: the crease's colour
    difference depends on which way the split's shift runs through the texture."""
    from PIL import Image

    ramp = np.arange(64) / 63
    image = np.zeros((64, 64, 3), dtype=np.uint8)
    image[..., 0] = np.round(255 * ramp)[None, :]
    image[..., 1] = np.round(100 * ramp)[:, None]
    Image.fromarray(image).save(path)


def test_a_transform2d_is_read_into_the_map_and_moves_the_uv_as_the_specification_says(tmp_path):
    from affinity.loaders import load
    from affinity.textures.binding import bound_textures

    ramp_texture(tmp_path / "ramp.png")
    stage = tmp_path / "scene.usda"
    stage.write_text(stage_text(UNIT_SQUARE, {"scale": "(2, 0.5)", "rotation": "90", "translation": "(0.25, 0.1)"}))
    mesh = load(str(stage))
    [bound] = bound_textures(mesh, np.array([0]))
    assert (bound.map.scale, bound.map.rotation) == ((2.0, 0.5), 90.0)
    assert bound.map.offset == pytest.approx((0.25, 0.1))  # float2: single precision
    uv = np.random.default_rng(9).random((20, 2))
    np.testing.assert_allclose(bound.map.texture_uv(uv), by_the_specification(uv, (2, 0.5), 90, (0.25, 0.1)),
                               atol=1e-6)  # float2 inputs are single precision
    stage.write_text(stage_text(UNIT_SQUARE, {"rotation": "30"}))  # unauthored inputs: their fallbacks
    [bound] = bound_textures(load(str(stage)), np.array([0]))
    assert (bound.map.scale, bound.map.rotation, bound.map.offset) == ((1.0, 1.0), 30.0, (0.0, 0.0))


def visible_finding(stage: Path) -> dict:
    """Q101's finding on ``stage``, its C measured to the end (``visible-error`` past any colour difference, so
    no value is a lower bound)."""
    (stage.parent / "affinity.toml").write_text("visible-error = 300\n")
    result = run("check", "--no-cache", "--format", "json", "--select", "Q101", str(stage), cwd=stage.parent)
    assert result.returncode in (0, 1), result.stderr
    [finding] = json.loads(result.stdout)["findings"]
    return finding


def test_the_visible_reading_reads_the_texture_where_the_transform_puts_the_uv(tmp_path):
    """The crease read through a scaled, rotated and moved texture equals the crease read through the same
    texture with the mesh's uv moved by the specification's formula beforehand (a second way to the same
    texel positions), and differs from reading it without the transform: the quarter turn runs the shift
    down the texture's gentler green ramp instead of across its red one."""
    ramp_texture(tmp_path / "ramp.png")
    scale, rotation, translation = (0.8, 0.9), 90.0, (1.0, 0.0)  # the uv stays inside the texture
    transformed = tmp_path / "transformed.usda"
    transformed.write_text(stage_text(UNIT_SQUARE, {"scale": "(0.8, 0.9)", "rotation": "90",
                                                    "translation": "(1, 0)"}))
    baked = tmp_path / "baked.usda"
    baked.write_text(stage_text(by_the_specification(UNIT_SQUARE, scale, rotation, translation), None))
    plain = tmp_path / "plain.usda"
    plain.write_text(stage_text(UNIT_SQUARE, None))
    through_transform, through_baked, untransformed = (visible_finding(s) for s in (transformed, baked, plain))
    assert through_transform["texture"] == "ramp.png" and through_transform["unit"] == "1/255"
    assert "bound" not in through_transform and "bound" not in through_baked
    assert through_transform["value"] == pytest.approx(through_baked["value"], abs=0.5)
    assert through_transform["value"] < untransformed["value"] - 8
