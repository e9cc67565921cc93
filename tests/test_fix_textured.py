"""affinity.fix on textured meshes (issue 51): the level comes from the split's shift in texels, never from the
visible reading C (1/255 steps), and a refined quad's pieces are measured in the texture of its own material.

Independent truths: the check's JSON of the input (its ``shift`` column) and of the written output, and the
same mesh planned without a decodable texture (texels of the same size, no visible reading).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run

from affinity.fix import FixSettings, plan_fix
from affinity.loaders import load
from affinity.settings import Settings

pytest.importorskip("PIL")


def checker_png(path, size: int, squares: int = 8) -> None:
    from PIL import Image

    cells = (np.arange(size)[:, None] * squares // size + np.arange(size)[None, :] * squares // size) % 2
    Image.fromarray((cells * 255).astype(np.uint8)).convert("RGB").save(path)


def twisted_grid_obj(size: int = 6, twist: float = 1.0, materials: tuple[str, ...] = ("checker",)) -> str:
    """A flat size x size grid of unit quads whose uv is the grid sheared by an amount growing along y (a
    bilinear twist: every quad is a trapezoid in uv); with two materials the right half uses the second."""
    lines = ["mtllib grid.mtl"]
    lines += [f"v {x} {y} 0" for y in range(size + 1) for x in range(size + 1)]
    lines += [f"vt {(x + twist * x * y / size) / size} {y / size}"
              for y in range(size + 1) for x in range(size + 1)]
    for half, material in enumerate(materials):
        lines.append(f"usemtl {material}")
        columns = range(size) if len(materials) == 1 else range(half * size // 2, (half + 1) * size // 2)
        for j in range(size):
            for i in columns:
                v = [j * (size + 1) + i + 1, j * (size + 1) + i + 2, (j + 1) * (size + 1) + i + 2,
                     (j + 1) * (size + 1) + i + 1]
                lines.append("f " + " ".join(f"{a}/{a}" for a in v))
    return "\n".join(lines) + "\n"


def write_textured_grid(folder, textures: dict[str, int], twist: float = 1.0):
    """The grid, its MTL and a checker PNG per material (name -> pixels); returns the OBJ's path."""
    mtl = []
    for name, pixels in textures.items():
        checker_png(folder / f"{name}.png", pixels)
        mtl += [f"newmtl {name}", f"map_Kd {name}.png"]
    (folder / "grid.mtl").write_text("\n".join(mtl) + "\n")
    path = folder / "grid.obj"
    path.write_text(twisted_grid_obj(twist=twist, materials=tuple(textures)))
    return path


def test_a_textured_sheared_grid_is_refined_by_its_shift_with_the_minimal_level(tmp_path):
    path = write_textured_grid(tmp_path, {"checker": 256})
    checked = json.loads(run("check", "--format", "json", "--isolated", str(path)).stdout)["findings"]
    q101 = {f["face"]: f for f in checked if f["code"] == "Q101"}
    assert q101 and all(f["unit"] == "1/255" for f in q101.values())  # read through the texture: C
    mesh = load(path)
    plan = plan_fix(mesh)
    assert sorted(plan.refine_faces.tolist()) == sorted(q101)  # every quad flagged at warning or above
    # the plan's value is the split's shift in texels, the check's `shift` column, not C
    np.testing.assert_allclose(plan.before, [q101[f]["shift"] for f in plan.refine_faces.tolist()], rtol=1e-9)
    assert set(plan.units.tolist()) == {"texels"}
    # and its levels those of the same mesh read without a texture, in texels of the same size
    mesh.material_textures, mesh.material_maps = {}, {}
    untextured = plan_fix(mesh, FixSettings(lint=Settings(texture_size=256)))
    assert plan.refine_n.tolist() == untextured.refine_n.tolist()
    assert set(plan.refine_n.tolist()) == {3}  # the smallest odd level (n = 2 before levels were odd)
    assert plan.faces_added == untextured.faces_added


def test_a_two_material_grid_is_fixed_clean_at_the_fix_level(tmp_path):
    """The left half binds a 64 px texture, the right half a 2048 px one: each refined quad's pieces are
    measured in its own material's texels (32 times as many on the right: a shift of about 36 texels there,
    under the threshold at n = 9 and over it at n = 8), so the written result lints clean at the fix level."""
    path = write_textured_grid(tmp_path, {"small": 64, "large": 2048}, twist=2.5)
    result = run("fix", "--fix-level", "info", "--format", "json", "--isolated", str(path))
    entry = json.loads(result.stdout)["files"][0]
    assert entry["refine"], result.stderr
    left = {r["face"] for r in entry["left"]}
    mesh = load(path)
    large = np.flatnonzero(np.array(mesh.material_names)[mesh.face_material] == "large")
    refined_large = [r for r in entry["refine"] if r["face"] in set(large.tolist())]
    assert refined_large  # the large texture's quads are refined
    out = tmp_path / "grid.fixed.obj"
    after = json.loads(run("check", "--format", "json", "--isolated", str(out)).stdout)["findings"]
    replaced = {r["face"] for r in entry["refine"]} | set(entry["transitions"])
    kept = [f for f in range(mesh.n_faces) if f not in replaced]
    scored = [f for f in after if f["code"] == "Q101"]
    assert all(f["face"] < len(kept) and kept[f["face"]] in left for f in scored), scored
    assert {r["n"] for r in refined_large} == {9}  # 36 texels need 9 x 9 pieces in the large texture
