"""Close-ups of the flagged places: split | hybrid | exact on the place, outlined, and the split's error map.

For each place chosen by :func:`affinity.report.places.choose_places`, a camera
is framed on it (:func:`affinity.draw.closeup.closeup_view`) and only the faces
around it are drawn, so a place the overview cannot see still gets its picture.
The texture is the mesh's own ``map_Kd`` when it can be read; otherwise a
procedural pattern of antialiased lines of constant u and v a few pixels
apart on screen (:func:`affinity.draw.texture.line_colours`), so the split's
crease shows as lines kinking at the diagonal whatever the atlas's scale. A
rule whose finding is mirroring (``Rule.mirroring``, Q302) gets an upright "F"
drawn in uv over the lines (:func:`affinity.draw.texture.glyph_ink`): it reads
mirrored on the mirrored faces, which a symmetric pattern cannot show.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..attributes import ATTRIBUTE_NAMES
from ..mesh import Mesh
from ..rules import RULES
from ..settings import Settings
from .places import Place

#: Methods of a close-up, left to right.
CLOSEUP_METHODS = ("split", "hybrid", "exact")
#: A close-up whose place covers fewer pixels than this fraction of the picture (300 pixels of 240 x 240) is
#: re-framed on its worst face, and dropped with a line saying why when that covers too few as well.
PLACE_FLOOR = 300 / 240**2
#: A place is framed whole when that frame is at most this many times as wide as its worst face's: a wider one
#: shrinks the worst face (and the kink of its lines at the split diagonal) below what an eye reads at page size,
#: so the close-up is framed on the worst face and its neighbours instead.
WHOLE_PLACE = 2.0
#: A place whose faces' area is below this fraction of its ring's is a sliver (a collapsed quad): it covers
#: no pixels from any side, so the floor does not apply and its outline's halo marks it.
SLIVER_AREA = 1e-3
PLAIN = np.ones((1, 1, 3), dtype=np.float32)
#: Attribute shown for each scored rule; the geometric rules show uv when the mesh has it.
SHOW_FOR = ATTRIBUTE_NAMES
#: A face covering at least this many pixels of a close-up's split panel is seen in it: a later place whose
#: worst face an earlier close-up shows gets no close-up of its own (it would show the same spot again).
SEEN_PIXELS = 24
#: Shown attributes whose close-up also gets the split's difference from exact amplified, when it is faint (a
#: colour or normal crease of a few 1/255, a uv error under a pixel): the largest channel change is brought to
#: about ``COLOUR_REACH`` (of 1), the largest uv displacement to about ``UV_REACH`` pixels on screen, by a gain
#: of ``GAIN_STEPS`` times a power of ten.
AMPLIFIED = ("color", "normal")
COLOUR_REACH = 0.5
UV_REACH = 3.0
GAIN_STEPS = (1, 2, 5)
#: A colour or normal crease whose largest change on the place is below this (of 1) is under one 8-bit step: the
#: PNGs round it away, and amplified they show rounding noise, so the close-up has no amplified panel and says why.
EIGHT_BIT_STEP = 1 / 255


@dataclass
class Closeup:
    """One close-up: the place, what is shown, the images and the split's error against exact.

    images : method -> (S, S, 3) float RGB, the place outlined in the flag colour
    error : (S, S) float64 split error against exact in ``unit`` (None without an attribute or exact)
    covered : (S, S) bool, the pixels where split and exact show the same face
    own : (S, S) bool, the pixels where the split picture shows the place's faces
    view : the :class:`affinity.draw.closeup.CloseupView` drawn (camera, up, drawn faces)
    seen : (K,) int64, the mesh faces covering at least ``SEEN_PIXELS`` pixels of the split picture
    amplified : (S, S, 3) float, the split with its difference from exact (colours, normals) or its uv error
        times ``gain``, where that is faint (a gain above 1), else None; ``amplified_label`` says which, and
        ``amplified_note`` why there is none where the difference is below one 8-bit step (``EIGHT_BIT_STEP``)
    dropped : why the close-up is not shown (its place covers too few pixels from every side), else None
    """

    place: Place
    show: str
    texture: str
    framed: str
    images: dict = field(default_factory=dict)
    error: np.ndarray | None = None
    covered: np.ndarray | None = None
    own: np.ndarray | None = None
    unit: str = ""
    view: object = None
    dropped: str | None = None
    amplified: np.ndarray | None = None
    gain: float = 1.0
    amplified_label: str = ""
    amplified_note: str = ""
    seen: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    @property
    def place_pixels(self) -> int:
        """The pixels the place's faces cover in the split picture (0 before it is drawn)."""
        return 0 if self.own is None else int(self.own.sum())


def _show_for(mesh: Mesh, code: str) -> str:
    if RULES[code].folding:
        return "fold"
    attribute = RULES[code].attribute if RULES[code].scored else None
    if attribute is not None:
        return SHOW_FOR[attribute]
    if mesh.texcoords is not None:
        return "uv"
    return "color" if mesh.colors is not None else "shaded"


def gain_for(change: float, reach: float = COLOUR_REACH) -> float:
    """The gain (1, 2, 5, 10, 20, ...) that brings a largest ``change`` to at most ``reach``; 1 for a change
    already that big, or none."""
    if not change > 0:
        return 1.0
    wanted = reach / change
    decade = 10.0 ** np.floor(np.log10(max(wanted, 1.0)))
    return float(max([decade * step for step in GAIN_STEPS if decade * step <= wanted], default=decade))


def _amplified(split: np.ndarray, exact: np.ndarray, same: np.ndarray, unit: np.ndarray | float, reach: float,
               place: np.ndarray | None) -> tuple[np.ndarray, float]:
    """``exact + gain * (split - exact)`` (S, S, K) where ``same`` (S, S) bool, ``exact`` elsewhere, and the gain:
    :func:`gain_for` of the largest finite change in ``unit`` (a scalar, or (S, S, K) with NaN where unknown)
    on the place's pixels ``place`` (S, S) bool that ``same`` keeps (all of ``same``'s when none or None)."""
    error = np.where(same[..., None], split - exact, 0.0)
    gain = gain_for(largest_change(split, exact, same, place, unit), reach)
    return exact + gain * error, gain


def largest_change(split: np.ndarray, exact: np.ndarray, same: np.ndarray, place: np.ndarray | None,
                   unit: np.ndarray | float = 1.0) -> float:
    """The largest finite ``|split - exact|`` (S, S, K) in ``unit`` (a scalar, or (S, S, K) with NaN where
    unknown) on the place's pixels ``place`` (S, S) bool that ``same`` (S, S) bool keeps (all of ``same``'s
    when none or None); 0 where there are none."""
    keep = same if place is None or not (same & place).any() else same & place
    with np.errstate(invalid="ignore", divide="ignore"):
        change = (np.abs(split - exact) / unit)[keep]
    return float(change[np.isfinite(change)].max(initial=0.0))


def amplified_difference(split: np.ndarray, exact: np.ndarray, same: np.ndarray,
                         place: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """The split's picture with its difference from exact amplified: ``exact + gain * (split - exact)``.

    Parameters
    ----------
    split, exact : (S, S, 3) float RGB in [0, 1], the two close-ups
    same : (S, S) bool, the pixels where both show the same face (elsewhere the exact picture is kept:
        a silhouette is no crease)
    place : (S, S) bool, the place's pixels, whose largest change sets the gain (default: all ``same``)

    Returns
    -------
    (S, S, 3) float32 in [0, 1], and the gain (:func:`gain_for` of the largest change on the place).
    """
    image, gain = _amplified(split, exact, same, 1.0, COLOUR_REACH, place)
    return np.clip(image, 0.0, 1.0).astype(np.float32), gain


def amplified_uv(split: np.ndarray, exact: np.ndarray, same: np.ndarray, local: np.ndarray,
                 place: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """The split's texture coordinates with their error amplified: ``exact + gain * (split - exact)``.

    Parameters
    ----------
    split, exact : (S, S, 2) float uv of the two close-ups
    same : (S, S) bool, the pixels where both show the same face
    local : (S, S, 2) float, each pixel's footprint in u and v (NaN where unknown)
    place : (S, S) bool, the place's pixels, whose largest displacement sets the gain (default: all ``same``)

    Returns
    -------
    (S, S, 2) float64 uv (exact where not ``same``), and the gain that brings the place's largest
    displacement, in pixels of the pixel's own footprint, to about ``UV_REACH`` pixels.
    """
    return _amplified(split, exact, same, np.where(local > 0, local, np.nan), UV_REACH, place)


def _map_kd(mesh: Mesh) -> str | None:
    """The mesh's map_Kd path when it is an image the core decodes (within the pixel budget), else None:
    the close-ups then draw the line pattern."""
    from ..textures.decode import why_not_decoded

    path = mesh.texture_path()
    return path if why_not_decoded(path) is None else None


def _unused_map_kd(mesh: Mesh) -> str:
    """The note for a close-up drawn with lines although the mesh names a map_Kd: which and why not."""
    import os

    from ..textures.decode import why_not_decoded

    path = mesh.texture_path()
    refused = why_not_decoded(path) if path else None
    return "" if refused is None else f" (map_Kd {os.path.basename(path)} is not drawn: {refused})"


def _area(mesh: Mesh, faces: np.ndarray) -> float:
    """The total area of ``faces`` (F,) int64."""
    from ..draw.closeup import vector_areas

    return float(np.linalg.norm(vector_areas(mesh, faces), axis=1).sum() / 2)


def _framed_view(mesh: Mesh, place: Place):
    """The view of ``place`` and the faces it is framed on (see :data:`WHOLE_PLACE`).

    The whole place when its frame is at most ``WHOLE_PLACE`` times as wide as its worst face's and, from the
    side that shows the worst face best, the place and its worst face each cover ``PLACE_FLOOR`` of the pre-pass
    (a close-up of a place whose worst face is hidden shows the wrong crease); else the worst face and its
    neighbours. When that covers less than the floor too (a sliver), the one of the two where the worst face is
    seen more, then the place.
    """
    from ..draw.closeup import closeup_view, frame_radius

    worst = np.array([place.worst])
    if len(place.faces) == 1:
        return closeup_view(mesh, worst), worst

    def whole_view():  # the side that shows the worst face, if one does
        return closeup_view(mesh, place.faces, focus=worst, focus_floor=PLACE_FLOOR)

    whole = None
    if frame_radius(mesh, place.faces) <= WHOLE_PLACE * frame_radius(mesh, worst):
        whole = whole_view()
        if min(whole.visible, whole.focus_visible) >= PLACE_FLOOR:
            return whole, place.faces
    near = closeup_view(mesh, worst, focus=place.faces)
    if near.visible >= PLACE_FLOOR:
        return near, worst
    if whole is None:
        whole = whole_view()
    # The one that shows the worst face more, then the place (a sliver shows in neither)
    if (whole.focus_visible, whole.visible) > (near.visible, near.focus_visible):
        return whole, place.faces
    return near, worst


def positions_as_colours(mesh: Mesh) -> Mesh:
    """``mesh`` with its positions, moved and scaled alike on every axis into [0, 1], as its vertex colours: the
    rasterizer then interpolates the surface point of every pixel (flat on a split triangle, on the bilinear
    patch for exact), and a uniform scale keeps the directions of its normals."""
    used = mesh.positions[np.unique(mesh.corner_vertex)]
    low, extent = used.min(axis=0), float(np.ptp(used, axis=0).max())
    return replace(mesh, colors=np.clip((mesh.positions - low) / (extent if extent > 0 else 1.0), 0.0, 1.0))


def _fold_picture(mesh: Mesh, place: Place, view, drawn, sub_face: np.ndarray) -> np.ndarray:
    """(S, S, 3) float32: the fold close-up of ``drawn`` (a render of :func:`positions_as_colours`), shaded by
    its surface's normals, lit across the worst face's fold (:func:`affinity.draw.fold.fold_light`), with the
    split diagonal of each of the place's quads drawn (``sub_face`` (S, S) int: the face of ``view.drawn``)."""
    from ..draw.closeup import face_vertices
    from ..draw.fold import draw_diagonals, fold_light, shade_fold, surface_normals, triangle_normals
    from ..draw.shading import BACKGROUND

    quads = place.faces[mesh.face_sizes[place.faces] == 4]
    corners = mesh.positions[face_vertices(mesh, quads)[0]].reshape(-1, 4, 3)
    eye, target, _ = view.camera
    toward_eye = np.subtract(eye, target) / np.linalg.norm(np.subtract(eye, target))
    worst = int(np.flatnonzero(quads == place.worst)[0]) if place.worst in quads else 0
    light = fold_light(triangle_normals(corners[worst:worst + 1])[0], toward_eye) if len(quads) else toward_eye
    normals = surface_normals(drawn.frame.attrs, drawn.frame.face)
    image = shade_fold(normals, drawn.frame.face >= 0, light, BACKGROUND)
    draw_diagonals(image, sub_face, corners[:, [0, 2]], np.searchsorted(view.drawn, quads), drawn.camera.matrix)
    return image


def closeup(mesh: Mesh, place: Place, settings: Settings, size: int, pixel_tolerance: float,
            texture: str | None = None) -> Closeup:
    """Draw one place (see the module docstring); ``texture`` is ``--texture``, overriding map_Kd."""
    import os

    from ..attributes import pixel_error
    from ..draw.closeup import face_subset, outline
    from ..draw.drawing import RenderOptions, render_mesh
    from ..draw.shading import OVERLAY_TINT
    from ..draw.texture import (
        GLYPH_SPACING,
        LINE_SPACING,
        glyph_footprints,
        line_colours,
        load_image,
        local_footprints,
        pixel_footprint,
        sample_bilinear,
    )
    from ..loaders.imagesize import image_size

    view, framed_faces = _framed_view(mesh, place)
    sub = face_subset(mesh, view.drawn)
    show = _show_for(mesh, place.code)
    image_file = texture or _map_kd(mesh)
    lines = show == "uv" and not image_file
    mirroring = lines and RULES[place.code].mirroring
    glyphs = None  # the glyphs' footprint per coordinate, measured on the split's place
    footprint = None
    if show == "uv" and image_file:
        label = f"texture {os.path.basename(image_file)}" + ("" if texture else " (map_Kd)")
    elif lines:
        label = f"lines of constant u (blue) and v (red) {LINE_SPACING:g} pixels apart" + (
            f", and an upright F every {GLYPH_SPACING:g} pixels in uv: where it reads mirrored, so is the texture"
            if mirroring else "") + _unused_map_kd(mesh)
    elif show == "fold":
        label = ("the surface shaded by its own normals, lit across the fold, with the split's diagonal (corners "
                 "0 to 2) in blue: the split draws two flat triangles meeting at it, exact the curved patch")
    else:
        label = {"color": "vertex colours", "normal": "normals as RGB", "shaded": "shading"}[show]
    framed = ("the place's faces and their neighbours" if len(framed_faces) > 1
              else f"face {place.worst} and its neighbours")
    result = Closeup(place, show, label, framed, view=view)
    in_place = np.isin(view.drawn, place.faces)
    frames, plain = {}, {}  # plain: the pictures before the outline
    for method in CLOSEUP_METHODS:
        # With the line pattern, the render's own texture is replaced pixel by pixel: a 1-texel one costs nothing.
        options = RenderOptions(method=method, show=show, width=size, height=size, camera=view.camera, up=view.up,
                                texture=PLAIN if lines else image_file, pixel_tolerance=pixel_tolerance)
        if show == "fold":  # the positions ride through the rasterizer as colours (scaled alike on every axis)
            options = replace(options, show="color", texture=None)
        drawn = render_mesh(positions_as_colours(sub) if show == "fold" else sub, options)
        image = drawn.image.copy()
        face = drawn.frame.face
        covered = face >= 0
        sub_face = np.where(covered, drawn.faces[np.maximum(face, 0)], -1)
        own = covered & in_place[np.maximum(sub_face, 0)]
        if show == "fold":
            image = _fold_picture(mesh, place, view, drawn, sub_face)
        edge = outline(own)
        if lines:  # at the place's scale: the split's footprint on the place's pixels, for every panel
            footprint = footprint or pixel_footprint(drawn.frame.attrs, own)
            if mirroring and glyphs is None:
                glyphs = glyph_footprints(drawn.frame.attrs, own, footprint)
            image[covered] = line_colours(drawn.frame.attrs[covered], footprint,
                                          local_footprints(drawn.frame.attrs)[covered], glyphs)
        if method == "split":
            result.own, split_outline = own, edge
            result.seen = view.drawn[np.bincount(sub_face[covered], minlength=len(view.drawn)) >= SEEN_PIXELS]
        plain[method] = image.copy()
        image[edge] = OVERLAY_TINT
        result.images[method] = image
        frames[method] = (drawn.frame, sub_face)
    if show in SHOW_FOR.values() and {"split", "exact"} <= frames.keys():
        (split, split_face), (exact, exact_face) = frames["split"], frames["exact"]
        covered = (split_face >= 0) & (split_face == exact_face)
        attribute = next(name for name, shown in SHOW_FOR.items() if shown == show)
        texture_size = (image_size(image_file) if image_file else None) or (settings.texture_size,) * 2
        error = np.zeros(covered.shape)
        error[covered] = pixel_error(split.attrs[covered], exact.attrs[covered], attribute, texture_size)
        code = next(code for code, rule in RULES.items() if rule.scored and rule.attribute == attribute)
        result.error, result.covered, result.unit = error, covered, RULES[code].unit_for(settings.measure)
        if show in AMPLIFIED:
            amplified, gain = amplified_difference(plain["split"], plain["exact"], covered, result.own)
            what = "its difference from exact"
            change = largest_change(plain["split"], plain["exact"], covered, result.own)
            if gain > 1 and change < EIGHT_BIT_STEP:
                result.amplified_note = (f"No amplified panel: split and exact differ by at most "
                                         f"{change * 255:.2g}/255 on the place, below one 8-bit step, so "
                                         "amplified it would show rounding noise.")
                gain = 1.0
        else:  # uv: the split's texture moved by gain times its error, drawn as the panels are
            local = local_footprints(exact.attrs)
            uv, gain = amplified_uv(split.attrs, exact.attrs, covered, local, result.own)
            what = "its uv error"
            if gain > 1:
                amplified = plain["exact"].copy()
                amplified[covered] = (line_colours(uv[covered], footprint, local[covered], glyphs) if lines
                                      else sample_bilinear(load_image(image_file), uv[covered]))
        if gain > 1:  # at a gain of 1 the panel would be the split's again
            amplified[split_outline] = OVERLAY_TINT
            result.amplified, result.gain, result.amplified_label = amplified, gain, f"split, {what} ×{gain:g}"
    sliver = _area(mesh, place.faces) < SLIVER_AREA * _area(mesh, view.ring)
    if "split" in result.images and result.place_pixels < PLACE_FLOOR * size * size and not sliver:
        result.dropped = (f"{place.code} at face {place.worst}: its faces cover {result.place_pixels} pixels of "
                          f"the close-up from every side tried (fewer than {PLACE_FLOOR * size * size:.0f}), "
                          "so it is not drawn")
    return result
