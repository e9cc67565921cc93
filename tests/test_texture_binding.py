"""Which texture, role and size each face reads (design.md, "Textures by role" and "Texture size for the texel
unit"): OBJ/MTL maps with -s/-o, USD UsdPreviewSurface, a MaterialX document referenced from USD, UDIM tiles."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run
from helpers.usd_stages import looks, usd_quads

from affinity.loaders import load
from affinity.textures.binding import bound_textures, texel_grid

#: A trapezoid with the unit square of uv: the split shifts the texture (1 - r) / (1 + sqrt r)^2 of its width
#: at worst, r = 1/2 (Q101's page).
TRAPEZOID_SHIFT = 0.5 / (1 + np.sqrt(0.5)) ** 2


def picture(path: Path, size, colour=(200, 120, 40)) -> None:
    from PIL import Image

    Image.new("RGB", size, colour).save(path)


def preview_material(name: str, textures: dict[str, str], varname: str = "st") -> str:
    """A UsdPreviewSurface material whose inputs (``diffuseColor``, ``normal``, ``roughness``...) read files."""
    connections = "".join(f"            {'color3f' if i == 'diffuseColor' else 'float3'} inputs:{i}.connect = "
                          f"</Looks/{name}/Tex_{i}.outputs:rgb>\n" for i in textures)
    shaders = "".join(
        f'        def Shader "Tex_{i}"\n        {{\n            uniform token info:id = "UsdUVTexture"\n'
        f"            asset inputs:file = @{f}@\n"
        f"            float2 inputs:st.connect = </Looks/{name}/Reader.outputs:result>\n"
        "            float3 outputs:rgb\n        }\n" for i, f in textures.items())
    return (f'    def Material "{name}"\n    {{\n'
            f"        token outputs:surface.connect = </Looks/{name}/Surface.outputs:surface>\n"
            '        def Shader "Surface"\n        {\n            uniform token info:id = "UsdPreviewSurface"\n'
            f"{connections}            token outputs:surface\n        }}\n{shaders}"
            '        def Shader "Reader"\n        {\n            uniform token info:id = "UsdPrimvarReader_float2"\n'
            f'            string inputs:varname = "{varname}"\n            float2 outputs:result\n        }}\n'
            "    }\n")


def per_face(mesh) -> dict[int, list[tuple[str, str]]]:
    """face -> [(role, file name)] of every texture it reads."""
    faces = np.flatnonzero(mesh.face_sizes == 4)
    found: dict[int, list] = {int(f): [] for f in faces}
    for bound in bound_textures(mesh, faces):
        for face in bound.faces.tolist():
            found[face].append((bound.map.role, Path(bound.path).name))
    return found


def test_usd_preview_surface_textures_by_role_and_size(tmp_path):
    pytest.importorskip("pxr")
    picture(tmp_path / "wood.png", (512, 256))
    picture(tmp_path / "wood_n.png", (128, 128), (128, 128, 255))
    picture(tmp_path / "stone.jpg", (2048, 1024))
    picture(tmp_path / "rough.png", (64, 64))
    stage = tmp_path / "scene.usda"
    stage.write_text(usd_quads(["Wood", "Stone", None, "Other"]) + looks(
        preview_material("Wood", {"diffuseColor": "wood.png", "normal": "wood_n.png"}),
        preview_material("Stone", {"roughness": "rough.png", "diffuseColor": "stone.jpg"}),
        preview_material("Other", {"diffuseColor": "rough.png"}, varname="st1")))  # another uv set: not ours
    mesh = load(str(stage))
    assert per_face(mesh) == {0: [("base colour", "wood.png"), ("normal", "wood_n.png")],
                              1: [("base colour", "stone.jpg"), ("scalar", "rough.png")],
                              2: [("base colour", "wood.png"), ("normal", "wood_n.png")],  # unbound: the first
                              3: []}
    grid = texel_grid(mesh, 1024)
    assert grid.of(np.arange(4)).tolist() == [[512, 256], [2048, 1024], [512, 256], [1024, 1024]]
    assert grid.assumed.tolist() == [False, False, False, True]


MTLX = """<?xml version="1.0"?>
<materialx version="1.38" fileprefix="maps/">
  <nodegraph name="NG_wood">
    <tiledimage name="base_tex" type="color3">
      <input name="file" type="filename" value="wood_base.png" />
      <input name="uvtiling" type="vector2" value="2.0, 2.0" />
    </tiledimage>
    <image name="normal_tex" type="vector3" fileprefix="normals/">
      <input name="file" type="filename" value="wood_normal.png" />
    </image>
    <normalmap name="nmap" type="vector3">
      <input name="in" type="vector3" nodename="normal_tex" />
    </normalmap>
    <output name="base_out" type="color3" nodename="base_tex" />
    <output name="normal_out" type="vector3" nodename="nmap" />
  </nodegraph>
  <standard_surface name="SR_wood" type="surfaceshader">
    <input name="base_color" type="color3" nodegraph="NG_wood" output="base_out" />
    <input name="normal" type="vector3" nodegraph="NG_wood" output="normal_out" />
  </standard_surface>
  <surfacematerial name="M_wood" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR_wood" />
  </surfacematerial>
  <standard_surface name="SR_other" type="surfaceshader" />
  <surfacematerial name="M_other" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR_other" />
  </surfacematerial>
</materialx>
"""


def test_a_materialx_document_referenced_from_usd(tmp_path):
    pytest.importorskip("pxr")
    (tmp_path / "maps" / "normals").mkdir(parents=True)
    picture(tmp_path / "maps" / "wood_base.png", (300, 200))
    picture(tmp_path / "maps" / "normals" / "wood_normal.png", (64, 32), (128, 128, 255))
    (tmp_path / "look.mtlx").write_text(MTLX)
    stage = tmp_path / "scene.usda"
    material = '    def Material "Mx" (\n        references = @look.mtlx@</MaterialX/Materials/M_wood>\n    )\n    {}\n'
    stage.write_text(usd_quads(["Mx"]) + looks(material))
    mesh = load(str(stage))
    assert per_face(mesh) == {0: [("base colour", "wood_base.png"), ("normal", "wood_normal.png")]}
    [base, _] = mesh.material_maps["/Looks/Mx"]
    assert base.scale == (2.0, 2.0) and base.source.startswith("MaterialX tiledimage base_tex")
    assert texel_grid(mesh, 1024).of(np.arange(1)).tolist() == [300, 200]


def udim_tiles(folder: Path) -> None:
    """Tile 1001 at 64 x 64, tile 1002 at 256 x 128."""
    picture(folder / "paint.1001.png", (64, 64))
    picture(folder / "paint.1002.png", (256, 128))


def test_usd_udim_tiles_of_two_sizes(tmp_path):
    pytest.importorskip("pxr")
    udim_tiles(tmp_path)
    stage = tmp_path / "scene.usda"
    stage.write_text(usd_quads(["Paint", "Paint", "Paint"], [(0, 0), (1, 0), (2, 0)])
                     + looks(preview_material("Paint", {"diffuseColor": "paint.<UDIM>.png"})))
    mesh = load(str(stage))
    assert per_face(mesh) == {0: [("base colour", "paint.1001.png")], 1: [("base colour", "paint.1002.png")],
                              2: [("base colour", "paint.1003.png")]}  # 1003 is missing: named, not read
    grid = texel_grid(mesh, 1024)
    assert grid.of(np.arange(3)).tolist() == [[64, 64], [256, 128], [1024, 1024]]
    doc = check(stage)
    by_prim = {f["prim"]: f for f in doc["findings"] if f["code"] == "Q101"}
    assert by_prim["/Quad1"]["texture"] == "paint.1002.png" and by_prim["/Quad1"]["role"] == "base colour"
    assert by_prim["/Quad0"]["shift"] == pytest.approx(TRAPEZOID_SHIFT * 64, rel=1e-6)
    assert by_prim["/Quad1"]["shift"] == pytest.approx(TRAPEZOID_SHIFT * 256, rel=1e-6)
    assert by_prim["/Quad2"]["unit"] == "texels" and "shift" not in by_prim["/Quad2"]
    assert "paint.1003.png" in by_prim["/Quad2"]["message"] and "missing" in by_prim["/Quad2"]["message"]


def test_obj_udim_scale_and_offset(tmp_path):
    udim_tiles(tmp_path)
    picture(tmp_path / "grain.png", (32, 16))
    (tmp_path / "look.mtl").write_text("newmtl paint\nmap_Kd paint.<UDIM>.png\n"
                                       "newmtl grain\nmap_Kd -s 4 2 1 -o 0.5 grain.png\nmap_Ks grain.png\n")
    vt = "".join(f"vt {u + du} {v}\n" for du in (0, 1) for u, v in [(0, 0), (1, 0), (1, 1), (0, 1)])
    corners = "f 1/1 2/2 3/3 4/4\n"
    (tmp_path / "mesh.obj").write_text(
        "mtllib look.mtl\nv -1 0 0\nv 1 0 0\nv 0.5 1 0\nv -0.5 1 0\n" + vt
        + "usemtl paint\n" + corners + "f 1/5 2/6 3/7 4/8\nusemtl grain\n" + corners)
    mesh = load(str(tmp_path / "mesh.obj"))
    assert per_face(mesh) == {0: [("base colour", "paint.1001.png")], 1: [("base colour", "paint.1002.png")],
                              2: [("base colour", "grain.png"), ("scalar", "grain.png")]}
    [diffuse, specular] = mesh.material_maps["grain"]
    assert (diffuse.scale, diffuse.offset, specular.scale) == ((4.0, 2.0), (0.5, 0.0), (1.0, 1.0))
    assert texel_grid(mesh, 1024).of(np.arange(3)).tolist() == [[64, 64], [256, 128], [32, 16]]


def check(path: Path) -> dict:
    result = run("check", "--no-cache", "--format", "json", "--select", "Q101", str(path))
    assert result.returncode in (0, 1), result.stderr
    return json.loads(result.stdout)


def test_a_normal_map_reads_in_degrees_and_the_worst_role_decides(tmp_path):
    """A flat base colour hides the crease; a normal map with a sharp edge down the middle shows it: C is the
    angle between its two normals, in degrees, and the finding names the normal map."""
    from PIL import Image

    left, right = np.array([0.0, 0.0, 1.0]), np.array([0.6, 0.0, 0.8])
    encode = lambda n: tuple(round(float(c)) for c in (n + 1) * 127.5)
    image = np.zeros((64, 64, 3), dtype=np.uint8)
    image[:, :32], image[:, 32:] = encode(left), encode(right)
    Image.fromarray(image).save(tmp_path / "bumps.png")
    picture(tmp_path / "flat.png", (64, 64))
    (tmp_path / "look.mtl").write_text("newmtl m\nmap_Kd flat.png\nbump bumps.png\n")
    (tmp_path / "mesh.obj").write_text("mtllib look.mtl\nusemtl m\nv -1 0 0\nv 1 0 0\nv 0.5 1 0\nv -0.5 1 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
    [finding] = check(tmp_path / "mesh.obj")["findings"]
    decoded = [np.array(encode(n)) / 127.5 - 1 for n in (left, right)]
    angle = np.degrees(np.arccos(np.dot(*decoded) / np.linalg.norm(decoded[0]) / np.linalg.norm(decoded[1])))
    assert finding["unit"] == "degrees" and finding["role"] == "normal (bump)" and finding["texture"] == "bumps.png"
    assert finding["value"] == pytest.approx(angle, abs=0.05) and finding["level"] == "error"


def test_the_result_cache_follows_usd_and_materialx_textures(tmp_path):
    """A texture changed behind a cached report gives the new C (the cache hashes what the stage, its
    UsdUVTexture files, its MaterialX documents and their images, and UDIM tiles name)."""
    pytest.importorskip("pxr")
    from PIL import Image

    from affinity.loaders.references import named_files

    udim_tiles(tmp_path)
    (tmp_path / "maps" / "normals").mkdir(parents=True)
    picture(tmp_path / "maps" / "wood_base.png", (300, 200))
    (tmp_path / "look.mtlx").write_text(MTLX)
    stage = tmp_path / "scene.usda"
    stage.write_text(usd_quads(["Paint"]) + looks(preview_material("Paint", {"diffuseColor": "paint.<UDIM>.png"})))
    assert [Path(p).name for p in named_files(str(stage))] == ["paint.1001.png", "paint.1002.png"]
    assert [Path(p).name for p in named_files(str(tmp_path / "look.mtlx"))] == ["wood_base.png",
                                                                                  "wood_normal.png"]
    def value() -> float:
        with pytest.MonkeyPatch.context() as patch:
            patch.setenv("AFFINITY_CACHE_DIR", str(tmp_path / "cache"))
            result = run("check", "--format", "json", "--select", "Q101", str(stage))
        return json.loads(result.stdout)["findings"][0]["value"]

    assert value() == pytest.approx(0.0, abs=0.01)  # a flat tile hides the crease
    checker = (np.indices((64, 64)).sum(axis=0) // 4 % 2 * 255).astype(np.uint8)
    Image.fromarray(np.repeat(checker[..., None], 3, axis=2)).save(tmp_path / "paint.1001.png")
    assert value() > 8  # the same stage, a new texture: checked again, not served from the cache
