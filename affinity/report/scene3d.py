"""The data of the report's 3-D view: one mesh as typed arrays, its findings, its texture, as JSON for the page.

The page's script (``templates/view3d.js``) draws it with three.js. Everything
from the asset (group names, paths, findings) enters the page here, as JSON in
a non-executable ``<script type="application/json">`` with every ``<`` escaped,
and the script shows it with ``textContent``: never markup, never code. Arrays
travel as base64 of little-endian typed arrays.

Above :data:`VIEW_QUAD_BUDGET` render quads the view keeps the flagged faces
and rings of their neighbours, and says how many faces it left out.
"""

from __future__ import annotations

import base64
import io
import json
import math
from pathlib import Path

import numpy as np

from ..attributes import ATTRIBUTE_NAMES, ATTRIBUTES
from ..lint import scored_codes
from ..mesh import Mesh
from ..rules import LEVELS, RULES
from .build import MeshResult

#: Render quads the view embeds at most (about 100 bytes of page each, all attributes).
VIEW_QUAD_BUDGET = 250_000
#: Findings the view's table lists per rule (the worst); the lint's JSON has them all.
TABLE_ROWS_PER_RULE = 100
#: Largest side of the embedded texture, pixels.
TEXTURE_SIDE = 2048
TEMPLATES = Path(__file__).parent / "templates"
#: Stand-in for the view's style and scripts (three.js and ``templates/view3d.js``): the page puts them in after
#: folding its line breaks (:func:`affinity.report.page.compact`), which three.js's shader strings need kept.
VIEW_SCRIPTS = "\x00view scripts\x00"
#: Largest float32: attribute values beyond it (uv at 1e70, say) are drawn clipped to it.
_FLOAT32_MAX = float(np.finfo(np.float32).max)
#: Outline colour of a flagged face by its worst finding's level.
LEVEL_COLOURS = {"error": "#ff1a99", "warning": "#f59e0b", "info": "#3b82f6"}


def _b64(array: np.ndarray, dtype) -> str:
    return base64.b64encode(np.ascontiguousarray(array, dtype=np.dtype(dtype).newbyteorder("<")).tobytes()).decode()


def _view_scale(positions: np.ndarray) -> float:
    """A power of two (exact) that brings ``positions`` (V, 3) float64 within 2^100, so their float32 copy in the
    view is finite (the loaders allow magnitudes up to 1e75); 1.0 for a mesh already there.

    >>> _view_scale(np.array([[1e75, 0.0, 0.0]])) * 1e75 <= 2.0**100, _view_scale(np.ones((1, 3)))
    (True, 1.0)
    """
    largest = float(np.abs(positions).max(initial=0.0))
    return 1.0 if largest <= 2.0**100 else 2.0 ** (100 - math.frexp(largest)[1])


def kept_faces(mesh: Mesh, flagged: np.ndarray, budget: int) -> np.ndarray:
    """(F,) bool: the faces the view embeds.

    Every face when the mesh's render quads fit ``budget``; else the ``flagged``
    (F,) bool faces and rings of their vertex neighbours, grown while the next
    ring still fits (at least the flagged faces themselves).
    """
    sizes = mesh.face_sizes
    quads_of = np.where(sizes == 4, 1, np.maximum(sizes - 2, 1))  # render quads per face (fans for n-gons)
    if quads_of.sum() <= budget:
        return np.ones(mesh.n_faces, dtype=bool)
    owner = np.repeat(np.arange(mesh.n_faces), sizes)
    kept = flagged.copy()
    while True:
        touched = np.zeros(len(mesh.positions), dtype=bool)
        touched[mesh.corner_vertex[kept[owner]]] = True
        ring = np.zeros(mesh.n_faces, dtype=bool)
        np.logical_or.at(ring, owner, touched[mesh.corner_vertex])
        if quads_of[ring].sum() > budget or ring.sum() == kept.sum():
            return kept
        kept = ring


def _attribute_block(mesh: Mesh, corners: np.ndarray, field: str, settings) -> dict | None:
    """One attribute of the render quads: its corner values (R, 4, width) float32 as base64 and how to read a
    difference of it (the unit, the visibility threshold of its scored rule), or None when the mesh lacks it.
    Normals missing at a corner (or in the whole mesh) are the face's flat normal, as the renderer shades."""
    from ..draw import flat_normals

    values = mesh.corner_attribute(field, corners)
    if field == "normals":
        fallback = flat_normals(mesh.corner_attribute("positions", corners))
        values = fallback if values is None else np.where(np.isnan(values), fallback, values)
    if values is None:
        return None
    codes = scored_codes(attribute=ATTRIBUTE_NAMES[field])
    visible = (settings.error_above(codes[0]) or RULES[codes[0]].visible_threshold) if codes else None
    attribute = ATTRIBUTES[field]
    return {"name": attribute.name, "width": attribute.width, "unit": attribute.unit, "visible": visible,
            "values": _b64(np.nan_to_num(values, posinf=_FLOAT32_MAX, neginf=-_FLOAT32_MAX).clip(
                -_FLOAT32_MAX, _FLOAT32_MAX), np.float32)}


def drawn_fields(result: MeshResult) -> list[str]:
    """The attributes the view embeds, in :data:`ATTRIBUTES` order: the one the renders show and those of the
    flagged rules (normals cost 48 bytes a quad: only where a finding is about them), else the normals (shading)."""
    wanted = {RULES[code].attribute for code in (result.shown, *(hits.code for hits in result.file.hits)) if code}
    fields = [field for field in ATTRIBUTES if field in wanted and getattr(result.mesh, field) is not None]
    return fields or ["normals"]


def _texture(result: MeshResult) -> dict | None:
    """The mesh's own texture (map_Kd), downscaled to :data:`TEXTURE_SIDE`, as a data URI with its real size.

    Decoded by the core (:func:`affinity.textures.decode.decode`: regular files only, never over the pixel
    budget, once per run); a texture it refuses leaves the view to the uv line pattern."""
    from ..draw import painted_texture

    path = result.options.texture or painted_texture(result.mesh)
    if not path or result.mesh.texcoords is None:
        return None
    from PIL import Image

    from ..textures.decode import TextureUnusable, decode

    try:
        pixels = decode(path).pixels
    except TextureUnusable:
        return None
    image = Image.fromarray(pixels[..., 0] if pixels.shape[2] == 1 else pixels)
    size = image.size
    image.thumbnail((TEXTURE_SIDE, TEXTURE_SIDE), Image.Resampling.LANCZOS)
    buffer = io.BytesIO()
    image.save(buffer, format="PNG", optimize=False)
    import os

    return {"uri": "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode(),
            "width": size[0], "height": size[1], "name": os.path.basename(path)}


def _findings(result: MeshResult) -> tuple[list[dict], np.ndarray]:
    """The table's rows (worst first per rule, :data:`TABLE_ROWS_PER_RULE` per rule) and every face's worst
    level as an index into ``LEVELS`` plus one (F,) uint8 (0: not flagged)."""
    mesh, file = result.mesh, result.file
    unflagged = len(LEVELS) + 1
    rank = np.full(mesh.n_faces, unflagged, dtype=np.uint8)
    rows = []
    for hits in file.hits:
        rule = RULES[hits.code]
        levels = hits.levels()
        valid = hits.faces >= 0
        level_rank = np.select([levels == level for level in LEVELS], np.arange(1, len(LEVELS) + 1)).astype(np.uint8)
        np.minimum.at(rank, hits.faces[valid], level_rank[valid])
        units = hits.units()  # per finding: C's where Q101 read it through a texture
        for i in np.argsort(hits.worst_key(), kind="stable")[:TABLE_ROWS_PER_RULE]:
            if hits.faces[i] < 0:
                continue
            rows.append({"code": hits.code, "name": rule.name, "level": str(levels[i]), "face": int(hits.faces[i]),
                         "line": int(hits.lines[i]), "group": file.group_names[hits.groups[i]],
                         "value": float(hits.values[i]), "unit": str(units[i]),
                         "attribute": ATTRIBUTE_NAMES.get(rule.attribute), **_in_prim(file, hits, i)})
    return rows, np.where(rank == unflagged, 0, rank).astype(np.uint8)


def _in_prim(file, hits, i: int) -> dict:
    """A USD finding's place as ``affinity check`` names it: ``prim`` and ``prim_face``, the face within the prim
    (design.md, Clarifications); nothing for other formats, whose rows keep their source line."""
    if file.prim_face_start is None:
        return {}
    group = int(hits.groups[i])
    return {"prim": file.group_names[group], "prim_face": int(hits.faces[i] - file.prim_face_start[group])}


def view_data(result: MeshResult, budget: int = VIEW_QUAD_BUDGET) -> tuple[dict, list[str]]:
    """Everything the 3-D view draws for one mesh, JSON-ready, and notes on what it left out.

    The arrays: ``positions`` (V', 3) float32 of the used vertices, ``corners``
    (R, 4) uint32 into them (a triangle repeats its last corner, an n-gon is
    fanned), ``faces`` (R,) uint32 the mesh face of each render quad, ``levels``
    (R,) uint8 the worst finding level of its face (1 error, 2 warning, 3 info,
    0 none), and per attribute the corner values (R, 4, width) float32.
    """
    from ..draw import render_corners

    mesh = result.mesh
    rows, worst_level = _findings(result)
    kept = kept_faces(mesh, worst_level > 0, budget)
    faces, corners = render_corners(mesh)
    shown = kept[faces]
    faces, corners = faces[shown], corners[shown]
    vertices, vertex_of = np.unique(mesh.corner_vertex[corners], return_inverse=True)
    attributes = [block for field in drawn_fields(result)
                  if (block := _attribute_block(mesh, corners, field, result.settings))]
    notes = []
    left = int((~kept).sum())
    if left:
        notes.append(f"the 3-D view keeps the {int((worst_level > 0).sum()):,} flagged faces and their "
                     f"neighbourhoods: {left:,} of {mesh.n_faces:,} faces are left out of it to keep the page small")
    eye, target, fov = result.camera
    scale = _view_scale(mesh.positions[vertices])
    data = {
        "quads": len(faces),
        "positions": _b64(mesh.positions[vertices] * scale, np.float32),
        "corners": _b64(vertex_of.reshape(-1, 4), np.uint32),
        "faces": _b64(faces, np.uint32),
        "levels": _b64(worst_level[faces], np.uint8),
        "attributes": attributes,
        "texture": _texture(result) if any(a["name"] == "uv" for a in attributes) else None,
        "findings": rows,
        "counts": {hits.code: len(hits) for hits in result.file.hits},
        "rules": {code: {"name": rule.name, "attribute": ATTRIBUTE_NAMES.get(rule.attribute)}
                  for code, rule in RULES.items()},
        "levels_order": list(LEVELS),
        "level_colours": LEVEL_COLOURS,
        "camera": [*(float(x) * scale for x in (*eye, *target)), float(fov)],
        "up": result.up,
        "left_out": left,
        "prims": None if result.file.prim_face_start is None else  # USD: #prim=/A/B&face=F, F within the prim
        {"names": list(result.file.group_names), "starts": result.file.prim_face_start.tolist()},
    }
    return data, notes


def script_json(data: dict) -> str:
    """``data`` as JSON safe inside ``<script type="application/json">``: every ``<`` (so ``</script>`` and
    ``<!--``) escaped, and the line separators JavaScript once treated as line ends."""
    text = json.dumps(data, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace("\u2028", "\\u2028").replace("\u2029", "\\u2029")


def shown_text(data: dict) -> str:
    """What the view draws, for its caption."""
    names = [attribute["name"] for attribute in data["attributes"]]
    drawn = []
    if "uv" in names:
        texture = data["texture"]
        drawn.append(f"uv with the texture {texture['name']} (embedded)" if texture
                     else "uv as grid lines a few pixels apart at any zoom (the mesh names no readable texture)")
    if "color" in names:
        drawn.append("vertex colours")
    if "normal" in names:
        drawn.append("normals, shaded")
    return "It draws " + "; ".join(drawn) + "." if drawn else ""


def view_scripts() -> str:
    """The view's style and scripts, once per page: three.js as a classic script, then ``view3d.js``.

    The page carries the view's own style and script minified (rcssmin, rjsmin), as it carries three.js's
    minified build: a third smaller, and the page is an output, not a second copy of the sources.
    """
    from rcssmin import cssmin
    from rjsmin import jsmin

    from .threejs import three_script

    style = cssmin((TEMPLATES / "view3d.css").read_text(encoding="utf-8")) + "\n"
    script = jsmin((TEMPLATES / "view3d.js").read_text(encoding="utf-8")) + "\n"
    return f"<style>\n{style}</style>\n<script>\n{three_script()}\n</script>\n<script>\n{script}</script>\n"
