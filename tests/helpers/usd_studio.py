"""A USD asset tree laid out as studios ship one (the Open Chess Set's layout in miniature).

``set.usda`` references ``assets/Piece/Piece.usd`` twice (/Set/A with ``shadingVariant = "Black"``,
/Set/B with ``"White"``). ``Piece.usd`` is the asset's entry: a payload to ``Piece_payload.usd``, which
sublayers ``Piece_look.usd`` and ``Piece_geom.usd``. The look puts the ``.mtlx`` reference on a parent scope
(``def Scope "Materials" (references = @./Piece_mat.mtlx@</MaterialX/Materials>)``) and binds
``/Piece/Materials/M_Piece_B`` or ``M_Piece_W`` inside the ``shadingVariant`` variants, so the bound prims do
not exist on the stage (usd-core cannot compose ``.mtlx``). The geometry is the flagged trapezoid of
:mod:`helpers.usd_stages`; ``black.png`` has stripes across u (a crease shows), ``white.png`` is flat.

:func:`obj_twin` writes the same mesh as an OBJ whose MTL names a texture: the independent reading of C.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from helpers.usd_stages import COUNTS, INDICES, POINTS, ST

SIZE = 512  # texels: face 0's uv square (1/16) spans 32

PIECE = """#usda 1.0
(
    defaultPrim = "Piece"
)

def Xform "Piece" (
    kind = "component"
    payload = @./Piece_payload.usd@</Piece>
    variants = {
        string shadingVariant = "Black"
    }
    add variantSets = "shadingVariant"
)
{
    variantSet "shadingVariant" = {
        "Black" {
        }
        "White" {
        }
    }
}
"""

PAYLOAD = """#usda 1.0
(
    defaultPrim = "Piece"
    subLayers = [
        @./Piece_look.usd@,
        @./Piece_geom.usd@
    ]
)
"""

LOOK = """#usda 1.0
(
    defaultPrim = "Piece"
)

over "Piece" (
    variants = {
        string shadingVariant = "Black"
    }
    add variantSets = "shadingVariant"
)
{
    def Scope "Materials" (
        prepend references = @./Piece_mat.mtlx@</MaterialX/Materials>
    )
    {
    }
    variantSet "shadingVariant" = {
        "Black" {
            over "Geom"
            {
                over "Render" (
                    apiSchemas = ["MaterialBindingAPI"]
                )
                {
                    rel material:binding = </Piece/Materials/M_Piece_B>
                }
            }
        }
        "White" {
            over "Geom"
            {
                over "Render" (
                    apiSchemas = ["MaterialBindingAPI"]
                )
                {
                    rel material:binding = </Piece/Materials/M_Piece_W>
                }
            }
        }
    }
}
"""

MATERIALX = '<?xml version="1.0"?>\n<materialx version="1.38">\n{}</materialx>\n'
MATERIAL = """  <nodegraph name="NG_{name}">
    <image name="diffuse_{name}" type="color3">
      <input name="file" type="filename" value="tex/{texture}" colorspace="srgb_texture" />
    </image>
    <output name="base_color_output" type="color3" nodename="diffuse_{name}" />
  </nodegraph>
  <standard_surface name="{name}" type="surfaceshader">
    <input name="base_color" type="color3" nodegraph="NG_{name}" output="base_color_output" />
  </standard_surface>
  <surfacematerial name="M_{name}" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="{name}" />
  </surfacematerial>
"""

SET = """#usda 1.0
(
    defaultPrim = "Set"
)

def Xform "Set"
{
    def Xform "A" (
        add references = @./assets/Piece/Piece.usd@
        variants = {
            string shadingVariant = "Black"
        }
    )
    {
    }

    def Xform "B" (
        add references = @./assets/Piece/Piece.usd@
        variants = {
            string shadingVariant = "White"
        }
    )
    {
        double3 xformOp:translate = (10, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
}
"""

#: Composed prim paths of the set, and the authored mesh prim.
PRIMS = ["/Set/A/Geom/Render", "/Set/B/Geom/Render"]
AUTHORED = "/Piece/Geom/Render"


def stripes(size: int = SIZE) -> np.ndarray:
    """(size, size, 3) uint8: a sine across u, period 8 texels: any uv shift along u shows."""
    u = np.arange(size)
    row = (127.5 + 127 * np.sin(2 * np.pi * u / 8)).astype(np.uint8)
    return np.repeat(np.broadcast_to(row[None, :, None], (size, size, 1)), 3, axis=2).copy()


def studio_asset(folder: Path) -> Path:
    """Write the asset tree under ``folder`` (see the module docstring); returns ``set.usda``'s path."""
    from PIL import Image
    from pxr import Sdf, Usd, UsdGeom

    piece = folder / "assets" / "Piece"
    (piece / "tex").mkdir(parents=True)
    Image.fromarray(stripes()).save(piece / "tex" / "black.png")
    Image.fromarray(np.full((SIZE, SIZE, 3), 200, dtype=np.uint8)).save(piece / "tex" / "white.png")
    (piece / "Piece_mat.mtlx").write_text(MATERIALX.format(
        MATERIAL.format(name="Piece_B", texture="black.png") + MATERIAL.format(name="Piece_W", texture="white.png")))
    (piece / "Piece.usd").write_text(PIECE)
    (piece / "Piece_payload.usd").write_text(PAYLOAD)
    (piece / "Piece_look.usd").write_text(LOOK)
    geometry = Usd.Stage.Open(Sdf.Layer.CreateNew(str(piece / "Piece_geom.usd"), {"format": "usda"}))
    UsdGeom.Xform.Define(geometry, "/Piece")
    UsdGeom.Scope.Define(geometry, "/Piece/Geom")
    mesh = UsdGeom.Mesh.Define(geometry, AUTHORED)
    mesh.GetPointsAttr().Set(POINTS)
    mesh.GetFaceVertexCountsAttr().Set(COUNTS)
    mesh.GetFaceVertexIndicesAttr().Set(INDICES)
    mesh.GetSubdivisionSchemeAttr().Set("none")
    UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                            UsdGeom.Tokens.faceVarying).Set(ST)
    geometry.SetDefaultPrim(geometry.GetPrimAtPath("/Piece"))
    geometry.GetRootLayer().Save()
    (folder / "set.usda").write_text(SET)
    return folder / "set.usda"


def obj_twin(folder: Path, texture: Path) -> Path:
    """The piece's mesh as ``twin.obj`` with ``twin.mtl`` naming ``texture`` as ``map_Kd``."""
    (folder / "twin.mtl").write_text(f"newmtl m\nmap_Kd {texture}\n")
    lines = ["mtllib twin.mtl", "usemtl m"]
    lines += [f"v {x} {y} {z}" for x, y, z in POINTS]
    lines += [f"vt {u!r} {v!r}" for u, v in ST]
    corner, faces = 0, []
    for n in COUNTS:
        faces.append("f " + " ".join(f"{INDICES[corner + k] + 1}/{corner + k + 1}" for k in range(n)))
        corner += n
    (folder / "twin.obj").write_text("\n".join(lines + faces) + "\n")
    return folder / "twin.obj"
