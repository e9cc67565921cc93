"""Small USD stages written with pxr for the USD tests: a flagged trapezoid and a geometry layer
that several prims reference (the Open Chess Set's knights in miniature)."""

from __future__ import annotations

from pathlib import Path

#: A trapezoid of two quads and a square, positions (x, y, 0). The uv of each trapezoid quad is a
#: square, not an affine image of it: face 0 a square 1/16 wide (an error of 11 texels at 1024, which
#: ``affinity fix`` removes within its cap), face 1 one 1/128 wide (1.4 texels: a warning); the
#: square's uv is affine (clean).
POINTS = [(-2, 0, 0), (0, 0, 0), (2, 0, 0), (1, 1, 0), (0, 1, 0), (-1, 1, 0), (3, 0, 0), (4, 0, 0), (4, 1, 0),
          (3, 1, 0)]
COUNTS = [4, 4, 4]
INDICES = [0, 1, 4, 5, 1, 2, 3, 4, 6, 7, 8, 9]
UNIT = [(0, 0), (1, 0), (1, 1), (0, 1)]
BIG = [(u / 16, v / 16) for u, v in UNIT]
SMALL = [(0.5 + u / 128, 0.5 + v / 128) for u, v in UNIT]
ST = [*BIG, *SMALL, (0.75, 0), (1, 0), (1, 0.25), (0.75, 0.25)]


def define_mesh(stage, path: str, st=ST, scheme: str | None = None):
    """A UsdGeom.Mesh at ``path`` with the trapezoid and the square, faceVarying ``st``."""
    from pxr import Sdf, UsdGeom

    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.GetPointsAttr().Set(POINTS)
    mesh.GetFaceVertexCountsAttr().Set(COUNTS)
    mesh.GetFaceVertexIndicesAttr().Set(INDICES)
    if scheme is not None:
        mesh.GetSubdivisionSchemeAttr().Set(scheme)
    UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                            UsdGeom.Tokens.faceVarying).Set(st)
    return mesh


def flagged_stage(folder: Path, name: str = "flagged.usda") -> Path:
    """One mesh prim /World/Panel: an error (face 0), a warning (face 1) and a clean quad (face 2)."""
    from pxr import Usd, UsdGeom

    path = folder / name
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.Xform.Define(stage, "/World")
    define_mesh(stage, "/World/Panel", scheme="none")
    stage.SetDefaultPrim(stage.GetPrimAtPath("/World"))
    stage.GetRootLayer().Save()
    return path


def referenced_stage(folder: Path, prims=("A", "B", "C", "D"), override_st: dict | None = None) -> Path:
    """``set.usda``: prims /Set/<name>/Knight, each referencing ``knight.usda`` (the mesh, authored once),
    moved apart; ``override_st`` maps a name to uv that prim authors over the referenced ones."""
    from pxr import Usd, UsdGeom

    geometry = Usd.Stage.CreateNew(str(folder / "knight.usda"))
    define_mesh(geometry, "/Knight", scheme="none")
    geometry.SetDefaultPrim(geometry.GetPrimAtPath("/Knight"))
    geometry.GetRootLayer().Save()
    stage = Usd.Stage.CreateNew(str(folder / "set.usda"))
    for i, name in enumerate(prims):
        UsdGeom.Xform.Define(stage, f"/Set/{name}").AddTranslateOp().Set((10.0 * i, 0, 0))
        knight = stage.DefinePrim(f"/Set/{name}/Knight")
        knight.GetReferences().AddReference("knight.usda")
        if override_st and name in override_st:
            UsdGeom.PrimvarsAPI(knight).GetPrimvar("st").Set(override_st[name])
    stage.GetRootLayer().Save()
    return folder / "set.usda"


def usd_quads(materials: list[str | None], uv_offsets: list[tuple[float, float]] | None = None) -> str:
    """usda text of one trapezoid mesh prim per entry, bound to ``/Looks/<name>`` (None: unbound), its uv the
    unit square moved by ``uv_offsets``."""
    prims = []
    for k, material in enumerate(materials):
        du, dv = (uv_offsets or [(0, 0)] * len(materials))[k]
        uv = ", ".join(f"({u + du}, {v + dv})" for u, v in [(0, 0), (1, 0), (1, 1), (0, 1)])
        binding = f"    rel material:binding = </Looks/{material}>\n" if material else ""
        prims.append(
            f'def Mesh "Quad{k}" (\n    prepend apiSchemas = ["MaterialBindingAPI"]\n)\n{{\n'
            "    int[] faceVertexCounts = [4]\n    int[] faceVertexIndices = [0, 1, 2, 3]\n"
            f"    point3f[] points = [({-1 + 3 * k}, 0, 0), ({1 + 3 * k}, 0, 0), ({0.5 + 3 * k}, 1, 0), "
            f"({-0.5 + 3 * k}, 1, 0)]\n"
            f'    texCoord2f[] primvars:st = [{uv}] (interpolation = "faceVarying")\n{binding}}}\n')
    return "#usda 1.0\n" + "".join(prims)


def looks(*materials: str) -> str:
    return 'def Scope "Looks"\n{\n' + "".join(materials) + "}\n"
