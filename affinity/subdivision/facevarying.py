"""Face-varying channels (uv, per-corner normals) through uniform refinement, as OpenSubdiv's Vtr and Far
refine them: a value where the channel's topology matches the vertices' follows the vertex masks; along
the channel's own boundaries (seams) a value is a smooth boundary ("crease": 3/4 of itself and 1/8 of the
two values along the seam) or a sharp corner (kept), by the channel's linear-interpolation rule:

| rule | sharp (kept) values |
|---|---|
| ``none`` | none: seams and boundaries smooth, corners included |
| ``cornersOnly`` | values spanning one face (corners of an island) |
| ``cornersPlus1`` | also every value of a vertex where three or more islands meet |
| ``cornersPlus2`` | also both values of a vertex where one is a corner, and darts |
| ``boundaries`` | every value on a seam or boundary (seams and boundaries linear) |
| ``all`` | everything: the channel is refined bilinearly |

A channel's values are kept one per vertex and island ("sibling", OpenSubdiv's vertex value), so a value
the file shares between vertices (an OBJ ``vt`` on several ``v``) becomes one per vertex. The tags are
classified once on the base level and inherited by the refined values, as Vtr does.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .catmark import VertexMasks, edge_masks, face_points, fractional_weight
from .topology import INFINITE, Topology, decay, sum_by

RULES = ("none", "cornersOnly", "cornersPlus1", "cornersPlus2", "boundaries", "all")


@dataclass(frozen=True)
class Channel:
    """One face-varying channel on one level.

    Attributes
    ----------
    values : (T, K) float64, one row per vertex value
    corner_value : (C,) int64 the value at each corner
    value_vertex : (T,) int64 the vertex of each value
    mismatch, crease, semi, dep : (T,) bool
        Value tags (Vtr's ValueTag): the value's topology differs from its vertex's (a seam or a sharpened
        boundary runs through it); of those, a smooth boundary, a semi-sharp one (kept until its sharpness
        runs out), one kept because its sibling is semi-sharp. A mismatched value that is none of the three
        is a sharp corner.
    edge_mismatch, edge_linear : (E,) bool
        The channel is discontinuous across the edge; the edge is interpolated linearly.
    rule : one of :data:`RULES`
    """

    values: np.ndarray
    corner_value: np.ndarray
    value_vertex: np.ndarray
    mismatch: np.ndarray
    crease: np.ndarray
    semi: np.ndarray
    dep: np.ndarray
    edge_mismatch: np.ndarray
    edge_linear: np.ndarray
    rule: str

    @property
    def linear(self) -> bool:
        return self.rule == "all"

    @property
    def linear_boundaries(self) -> bool:
        return self.rule in ("boundaries", "all")


def _discontinuity(topology: Topology, corner_value: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(E,) bool each, per edge: the faces on the edge disagree on the value at its lower vertex, at its
    higher vertex."""
    here, there = corner_value, corner_value[topology.next]
    at_low = topology.corner_vertex == topology.edge_vertices[topology.corner_edge, 0]
    low, high = np.where(at_low, here, there), np.where(at_low, there, here)
    first = topology.edge_first_corner[topology.corner_edge]
    differs_low = low != low[first]
    differs_high = high != high[first]
    E = topology.n_edges
    return (np.bincount(topology.corner_edge, differs_low, minlength=E) > 0,
            np.bincount(topology.corner_edge, differs_high, minlength=E) > 0)


def _side_tables(topology: Topology, channel_corner_value: np.ndarray, disc_low, disc_high):
    """Per corner, for its two sides at its vertex (to the next corner, from the previous one): the edge,
    whether the edge is discontinuous at this vertex, and the value at the edge's far end in this face."""
    v = topology.corner_vertex
    sides = []
    for edge, far in ((topology.corner_edge, channel_corner_value[topology.next]),
                      (topology.corner_edge[topology.prev], channel_corner_value[topology.prev])):
        at_low = topology.edge_vertices[edge, 0] == v
        sides.append((edge, np.where(at_low, disc_low[edge], disc_high[edge]), far))
    return sides


def _repeated_run(topology: Topology, corner_value: np.ndarray) -> np.ndarray:
    """(C,) bool the corners Vtr gives a value of their own although their vertex has it elsewhere.

    Walking a vertex's ring (:attr:`Topology.ring_position`), FVarLevel::completeTopologyFromFaceValues
    numbers the distinct values as they appear, but while it knows only two it takes a value that differs
    from the previous face's and from the first value for a new one: so where the second value's faces are
    interrupted by the first's (a, b, a, b around the vertex, as on a mesh whose faces share four uv), its
    next run becomes a value of its own, until a third value appears. That run's corners are marked."""
    cv = topology.corner_vertex
    order = np.lexsort((topology.ring_position, cv))
    vertex, value = cv[order], corner_value[order]
    n = len(order)
    first = np.searchsorted(vertex, vertex)  # the ring's first face, for every corner
    position = np.arange(n) - first
    a = value[first]
    big = np.int64(n)

    def first_where(mask: np.ndarray) -> np.ndarray:
        """(n,) per corner, the ring position of its vertex's first corner where ``mask``, else n."""
        found = np.full(topology.n_vertices, big)
        np.minimum.at(found, vertex[mask], position[mask])
        return found[vertex]

    p_b = first_where(value != a)
    b = value[first + np.minimum(p_b, np.bincount(vertex, minlength=topology.n_vertices)[vertex] - 1)]
    p_c = first_where((value != a) & (value != b))
    previous = np.concatenate([[-1], value[:-1]])
    entering = (position > p_b) & (value == b) & (previous != b) & (position < p_c)
    start = first_where(entering)
    end = first_where((position > start) & (value != b))
    marked = np.zeros(n, dtype=bool)
    marked[order] = (position >= start) & (position < end)
    return marked


def base_channel(topology: Topology, values: np.ndarray, corner_value: np.ndarray, rule: str,
                 edge_sharpness: np.ndarray, vertex_sharpness: np.ndarray, boundary: str) -> Channel:
    """The base level's channel from a mesh's ``values`` (T0, K) float64 and ``corner_value`` (C,) int64, the
    tags classified as Vtr's FVarLevel::completeTopologyFromFaceValues does. ``edge_sharpness`` and
    ``vertex_sharpness`` are the level's after the boundary rule (:func:`catmark.sharpen_boundaries`)."""
    V = topology.n_vertices
    T0 = np.int64(len(values))
    pair = (topology.corner_vertex * T0 + corner_value) * 2 + _repeated_run(topology, corner_value)
    unique, corner_sibling = np.unique(pair, return_inverse=True)
    corner_sibling = corner_sibling.ravel()
    value_vertex, T = unique // 2 // T0, len(unique)
    disc_low, disc_high = _discontinuity(topology, corner_sibling)
    edge_mismatch = disc_low | disc_high
    linear_boundaries = rule in ("boundaries", "all")
    dependent = rule in ("cornersPlus1", "cornersPlus2")
    low, high = topology.edge_vertices[:, 0], topology.edge_vertices[:, 1]

    mismatched = np.zeros(V, dtype=bool)
    mismatched[topology.edge_vertices[edge_mismatch].ravel()] = True
    # Vtr visits the vertices in order: a seam found at the lower vertex marks the higher one before the
    # higher one's boundary is looked at, not the other way round.
    marked_before = np.zeros(V, dtype=bool)
    marked_before[low[disc_low]] = True
    marked_before[high[edge_mismatch]] = True
    open_vertex = topology.boundary_vertex & (topology.vertex_face_count > 0) & ~marked_before
    edge_linear = edge_mismatch & linear_boundaries
    if linear_boundaries:
        mismatched |= open_vertex
        open_edge = topology.edge_face_count < 2
        edge_linear |= open_edge & (open_vertex[low] | open_vertex[high])
    elif rule != "none" and boundary != "edgeAndCorner":
        mismatched |= open_vertex & (topology.vertex_face_count == 1)

    n_values = np.bincount(value_vertex, minlength=V)
    inf_edge = edge_sharpness >= INFINITE
    semi_edge = (edge_sharpness > 0) & ~inf_edge
    boundary_vertex = topology.boundary_vertex
    all_sharp = (linear_boundaries | (vertex_sharpness >= INFINITE) | (dependent & (n_values > 2))
                 | ((rule in ("cornersPlus2", "boundaries", "all")) & (n_values == 1) & ~boundary_vertex))

    # Spans: the faces around a vertex holding one of its values.
    size = np.bincount(corner_sibling, minlength=T)
    interior = np.zeros(T)
    breaks = np.zeros(T, dtype=bool)
    semi_count = np.zeros(T)
    for edge, discontinuous, _ in _side_tables(topology, corner_sibling, disc_low, disc_high):
        inside = (topology.edge_face_count[edge] == 2) & ~discontinuous
        interior += np.bincount(corner_sibling, inside, minlength=T)
        breaks |= np.bincount(corner_sibling, inside & (edge_mismatch[edge] | inf_edge[edge]), minlength=T) > 0
        semi_count += np.bincount(corner_sibling, inside & ~edge_mismatch[edge] & semi_edge[edge], minlength=T)
    disjoint = breaks | (size - interior / 2 > 1)
    # A vertex with one value (a dart, or a sharpened boundary): its span is broken by a second seam edge or by
    # any infinitely sharp edge that is not a seam.
    ends = topology.edge_vertices.ravel()
    seams = np.bincount(ends, np.repeat(edge_mismatch, 2), minlength=V)
    sharp_other = np.bincount(ends, np.repeat(inf_edge & ~edge_mismatch, 2), minlength=V) > 0
    single = n_values[value_vertex] == 1
    single_semi = np.bincount(ends, np.repeat(semi_edge & ~edge_mismatch, 2), minlength=V)
    disjoint = np.where(single, (seams[value_vertex] >= 2) | sharp_other[value_vertex], disjoint)
    size = np.where(single, np.where(seams[value_vertex] >= 1, size, 0), size)
    semi_count = np.where(single, single_semi[value_vertex], semi_count / 2)

    two = dependent & (n_values == 2)
    vertex_sharp_two = np.bincount(value_vertex, disjoint, minlength=V) > 0
    if rule == "cornersPlus2":
        vertex_sharp_two |= np.bincount(value_vertex, size == 1, minlength=V) > 0
    semi_values = np.bincount(value_vertex, semi_count > 0, minlength=V)
    has_dep = two & (semi_values == 1)
    corner = (all_sharp | (two & vertex_sharp_two))[value_vertex] | disjoint | ((size == 1) & (rule != "none"))
    vertex_semi = (vertex_sharpness > 0) & (vertex_sharpness < INFINITE)
    mismatch = mismatched[value_vertex]
    semi = mismatch & ~corner & ((semi_count > 0) | vertex_semi[value_vertex])
    dep = mismatch & ~corner & ~semi & has_dep[value_vertex]
    crease = mismatch & ~corner & ~semi & ~dep
    return Channel(values=np.asarray(values, dtype=np.float64)[unique // 2 % T0], corner_value=corner_sibling,
                   value_vertex=value_vertex, mismatch=mismatch, crease=crease, semi=semi | dep, dep=dep,
                   edge_mismatch=edge_mismatch, edge_linear=edge_linear, rule=rule)


def _span_sides(topology: Topology, channel: Channel):
    """Per corner side (:func:`_side_tables`), with the channel's own discontinuity, its edge and whether it
    bounds the span of the corner's value (a boundary edge or a seam)."""
    disc_low, disc_high = _discontinuity(topology, channel.corner_value)
    for edge, discontinuous, far in _side_tables(topology, channel.corner_value, disc_low, disc_high):
        bounding = (topology.edge_face_count[edge] < 2) | channel.edge_mismatch[edge]
        inside = (topology.edge_face_count[edge] == 2) & ~discontinuous
        yield edge, bounding, inside, far


def refine_channel(topology: Topology, channel: Channel, masks: VertexMasks | None, edge_sharpness: np.ndarray,
                   vertex_sharpness: np.ndarray, child_edge_parent: np.ndarray) -> tuple[Channel, np.ndarray]:
    """One level of ``channel`` (Far's PrimvarRefiner::InterpolateFaceVarying). ``masks`` None: bilinear.
    ``child_edge_parent`` (E',) int64 is the parent edge of each child edge (-1 inside a face).

    Returns the child channel (its corners those of the child faces, one quad per parent corner) and
    (C, 4) int64 the child values at each child quad's corners in slot order vertex, next edge, face,
    previous edge (the caller rotates them into the quad's order)."""
    F, E = topology.n_faces, topology.n_edges
    linear = channel.linear or masks is None
    values, cv = channel.values, channel.corner_value
    faces = face_points(topology, values[cv])

    # Edge values: one where the channel is continuous across the edge, one per face where it is not.
    single = ~channel.edge_mismatch
    count = np.where(single, 1, topology.edge_face_count)
    edge_start = np.concatenate([[0], np.cumsum(count)])
    first = topology.edge_first_corner
    a, b = values[cv[first]], values[cv[topology.next[first]]]
    matched_edge = single & ~channel.edge_linear
    edge_values = np.empty((edge_start[-1], values.shape[1]))
    mid = (a + b) / 2
    if linear:
        smooth_edges = mid
    else:
        w_ends, w_faces = edge_masks(edge_sharpness, topology.edge_face_count)
        face_sum = sum_by(topology.corner_edge, faces[topology.corner_face], E)
        smooth_edges = (a + b) * w_ends[:, None] + face_sum * w_faces[:, None]
    edge_values[edge_start[:-1][single]] = np.where(matched_edge[:, None], smooth_edges, mid)[single]
    split = ~single[topology.corner_edge]
    corner_edge_value = edge_start[topology.corner_edge] + np.where(split, topology.corner_rank, 0)
    edge_values[corner_edge_value[split]] = ((values[cv] + values[cv[topology.next]]) / 2)[split]

    # Vertex values: tags inherited, semi-sharp ones reclassified where their sharpness has run out.
    child = _reclassify(topology, channel, edge_sharpness, vertex_sharpness)
    vertex_values = values.copy()
    if not linear:
        vertex_values = _vertex_values(topology, channel, child, masks, faces, edge_sharpness, vertex_sharpness)

    n_edge_values = edge_start[-1]
    edge_value_edge = np.repeat(np.arange(E), count)
    smooth_boundaries = not channel.linear_boundaries
    edge_tag = (~single | channel.edge_linear)[edge_value_edge]
    inherited = np.where(child_edge_parent >= 0, child_edge_parent, 0)
    refined = Channel(
        values=np.concatenate([faces, edge_values, vertex_values]),
        corner_value=np.zeros(0, dtype=np.int64),
        value_vertex=np.concatenate([np.arange(F), F + edge_value_edge, F + E + channel.value_vertex]),
        mismatch=np.concatenate([np.zeros(F, bool), edge_tag, child.mismatch]),
        crease=np.concatenate([np.zeros(F, bool), edge_tag & smooth_boundaries, child.crease]),
        semi=np.concatenate([np.zeros(F + n_edge_values, bool), child.semi]),
        dep=np.concatenate([np.zeros(F + n_edge_values, bool), child.dep]),
        edge_mismatch=(child_edge_parent >= 0) & channel.edge_mismatch[inherited],
        edge_linear=(child_edge_parent >= 0) & channel.edge_linear[inherited], rule=channel.rule)
    offset = F + n_edge_values
    slots = np.stack([offset + cv, F + corner_edge_value, topology.corner_face,
                      F + corner_edge_value[topology.prev]], axis=1)
    return refined, slots


def _reclassify(topology: Topology, channel: Channel, edge_sharpness, vertex_sharpness) -> Channel:
    """The vertex values' tags a level down (FVarRefinement::reclassifySemisharpValues): a semi-sharp value
    whose vertex and span edges are no longer semi-sharp becomes a smooth boundary."""
    if not channel.semi.any():
        return channel
    V = topology.n_vertices
    child_vertex = decay(vertex_sharpness)
    child_edge = decay(edge_sharpness)
    semi_child_edge = (child_edge > 0) & (child_edge < INFINITE)
    ends = topology.edge_vertices.ravel()
    keeps_vertex = child_vertex > 0
    any_semi_edge = np.bincount(ends, np.repeat(semi_child_edge, 2), minlength=V) > 0
    still = np.zeros(len(channel.values), dtype=bool)
    for edge, _, inside, _ in _span_sides(topology, channel):
        still |= np.bincount(channel.corner_value, inside & semi_child_edge[edge], minlength=len(still)) > 0
    v = channel.value_vertex
    semi, dep = channel.semi.copy(), channel.dep.copy()
    clear = semi & ~keeps_vertex[v] & (~any_semi_edge[v] | (~dep & ~still))
    semi &= ~clear
    dep &= ~clear
    # A dependent value whose sibling is no longer semi-sharp stops depending on it (it stays semi-sharp).
    n_values = np.bincount(v, minlength=V)
    sibling_semi = np.bincount(v, semi, minlength=V)[v] - semi
    dep &= ~((n_values[v] == 2) & (sibling_semi == 0))
    return replace(channel, crease=channel.crease | clear, semi=semi, dep=dep)


def _vertex_values(topology: Topology, channel: Channel, child: Channel, masks: VertexMasks, faces: np.ndarray,
                   edge_sharpness: np.ndarray, vertex_sharpness: np.ndarray) -> np.ndarray:
    """(T, K) float64 the child value of every vertex value (Far's interpFVarFromVerts)."""
    values, cv, v = channel.values, channel.corner_value, channel.value_vertex
    T, V = len(values), topology.n_vertices
    out = values.copy()
    # Matched values follow the vertex mask, on the channel's own values around the vertex.
    first = topology.edge_first_corner
    at_low = topology.corner_vertex[first] == topology.edge_vertices[:, 0]
    low = np.where(at_low[:, None], values[cv[first]], values[cv[topology.next[first]]])
    high = np.where(at_low[:, None], values[cv[topology.next[first]]], values[cv[first]])

    def around(edges):
        e = np.flatnonzero(edges)
        ends = topology.edge_vertices[e]
        return sum_by(np.concatenate([ends[:, 0], ends[:, 1]]), np.concatenate([high[e], low[e]]), V)

    vertex_value = np.zeros(V, dtype=np.int64)
    vertex_value[v] = np.arange(T)
    x = values[vertex_value]
    everything = np.ones(topology.n_edges, dtype=bool)
    smooth = masks.apply(x, around(everything), sum_by(topology.corner_vertex, faces[topology.corner_face], V),
                         around(masks.sharp_edges), around(masks.child_sharp_edges))
    matched = ~channel.mismatch
    out[matched] = smooth[v[matched]]
    # Mismatched values: kept where the child is a corner, else the seam's crease rule, blended while a
    # semi-sharp value's sharpness runs out.
    crease = channel.mismatch & child.crease
    if crease.any():
        end_sum = np.zeros_like(values)
        interior_sharpness, interior_index = [], []
        for side, (edge, bounding, inside, far) in enumerate(_span_sides(topology, channel)):
            end_sum += sum_by(cv, np.where(bounding[:, None], values[far], 0.0), T)
            if side == 0:  # each interior edge of a span once: from the face it leaves
                interior_sharpness.append(edge_sharpness[edge][inside])
                interior_index.append(cv[inside])
        corner_weight = fractional_weight(np.concatenate([vertex_sharpness[v], *interior_sharpness]),
                                          np.concatenate([np.arange(T), *interior_index]), T)
        sibling = _sibling(v, V)
        corner_weight = np.where(channel.dep, corner_weight[sibling], corner_weight)
        w = np.where(channel.semi, corner_weight, 0.0)
        blended = values * ((1 - w) * 0.75 + w)[:, None] + end_sum * ((1 - w) * 0.125)[:, None]
        out[crease] = blended[crease]
    return out


def _sibling(value_vertex: np.ndarray, n_vertices: int) -> np.ndarray:
    """(T,) int64 for a vertex with two values, each one's other value (else itself)."""
    T = len(value_vertex)
    start = np.searchsorted(value_vertex, np.arange(n_vertices))
    count = np.bincount(value_vertex, minlength=n_vertices)
    index = np.arange(T)
    local = index - start[value_vertex]
    return np.where(count[value_vertex] == 2, start[value_vertex] + 1 - local, index)


def limit_values(topology: Topology, channel: Channel, edge_sharpness: np.ndarray,
                 vertex_sharpness: np.ndarray) -> np.ndarray:
    """(T, K) float64 each value's limit (Far's PrimvarRefiner::LimitFaceVarying) on a level whose faces are
    all quads: a matched value by its vertex's limit mask (smooth: n/(n+5) of itself, 4/(n(n+5)) of each
    edge neighbour and 1/(n(n+5)) of each diagonal one; crease: 2/3 of itself and 1/6 of each sharp edge's
    other end; corner: itself), a value on a seam 2/3 of itself and 1/6 of each seam neighbour (a smooth
    boundary) or itself (a sharp corner). The linear rule ``all`` keeps every value."""
    from .catmark import CORNER, CREASE, vertex_rule

    values, cv, v = channel.values, channel.corner_value, channel.value_vertex
    if channel.linear:
        return values.copy()
    T, V = len(values), topology.n_vertices
    first = topology.edge_first_corner
    at_low = topology.corner_vertex[first] == topology.edge_vertices[:, 0]
    low = np.where(at_low[:, None], values[cv[first]], values[cv[topology.next[first]]])
    high = np.where(at_low[:, None], values[cv[topology.next[first]]], values[cv[first]])

    def around(edges):
        ends = topology.edge_vertices[edges]
        return sum_by(np.concatenate([ends[:, 0], ends[:, 1]]), np.concatenate([high[edges], low[edges]]), V)

    sharp = edge_sharpness > 0
    ends = topology.edge_vertices.ravel()
    rule = vertex_rule(vertex_sharpness, np.bincount(ends, np.repeat(sharp, 2), minlength=V).astype(int))
    n = topology.vertex_face_count.astype(np.float64)
    n[n == 0] = 1.0
    vertex_value = np.zeros(V, dtype=np.int64)
    vertex_value[v] = np.arange(T)
    x = values[vertex_value]
    diagonal = sum_by(topology.corner_vertex, values[cv[topology.next[topology.next]]], V)
    smooth = x * (n / (n + 5))[:, None] + (4 * around(np.arange(topology.n_edges)) + diagonal) / (n * (n + 5))[:, None]
    crease = (4 * x + around(np.flatnonzero(sharp))) / 6
    limit = np.where((rule == CORNER)[:, None], x, np.where((rule == CREASE)[:, None], crease, smooth))
    out = values.copy()
    matched = ~channel.mismatch
    out[matched] = limit[v[matched]]
    seam = channel.mismatch & channel.crease
    if seam.any():
        end_sum = np.zeros_like(values)
        for _, bounding, _, far in _span_sides(topology, channel):
            end_sum += sum_by(cv, np.where(bounding[:, None], values[far], 0.0), T)
        out[seam] = ((4 * values + end_sum) / 6)[seam]
    return out
