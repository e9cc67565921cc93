"""Before/after wireframes of ``affinity fix`` at the shared car's worst place, for docs/fix.md.

The worst place is the refined quad with the largest value before the fix; the pictures show it and the
faces within two rings of it that face the same way (within 60 degrees), in the plane of that quad,
before (the input) and after (the fix): refined
quads' pieces blue, the neighbours cut to meet them green, faces the fix leaves red, the rest grey.

    python benchmarks/fix_wireframe.py            # writes reports/fix/car_before_wire.png, car_after_wire.png
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

SHARED = Path(__file__).resolve().parents[2] / "shared" / "meshes"
OUT = Path(__file__).resolve().parents[1] / "reports" / "fix"


def rings_around(mesh, face: int, rings: int = 2) -> np.ndarray:
    """(k,) int64 the faces sharing a position with ``face``, ``rings`` times over."""
    from affinity.fix.layout import welded_vertices

    welded = welded_vertices(mesh.positions)[mesh.corner_vertex]
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes)
    chosen = np.array([face])
    for _ in range(rings):
        touching = np.isin(welded, welded[np.isin(face_of, chosen)])
        chosen = np.unique(face_of[touching])
    return chosen


def draw(mesh, faces: np.ndarray, colours: list, frame: tuple, path: Path, title: str) -> None:
    """The edges of ``faces`` projected by ``frame`` (origin, two axes), one colour per face."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    origin, axes = frame
    figure, ax = plt.subplots(figsize=(5, 5), dpi=120)
    for face, colour in zip(faces.tolist(), colours):
        corners = mesh.positions[mesh.corner_vertex[mesh.face_start[face]:mesh.face_start[face + 1]]]
        xy = (corners - origin) @ axes.T
        ax.fill(xy[:, 0], xy[:, 1], facecolor="none", edgecolor=colour, linewidth=0.6)
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)


def main() -> None:
    from affinity.fix import plan_fix, refine_mesh
    from affinity.loaders import load

    car = SHARED / "osd_catmark_car.obj"
    if not car.exists():
        sys.exit(f"{car} is absent")
    mesh = load(car)
    plan = plan_fix(mesh)
    refined = refine_mesh(mesh, plan)
    worst = int(plan.refine_faces[np.argmax(plan.before)])
    corners = mesh.positions[mesh.corner_vertex[mesh.face_start[worst] + np.arange(4)]]
    normal = np.cross(corners[2] - corners[0], corners[3] - corners[1])
    around = rings_around(mesh, worst)
    quad = mesh.positions[mesh.corner_vertex[mesh.face_start[around, None] + np.arange(4)]]
    facing = np.cross(quad[:, 2] - quad[:, 0], quad[:, 3] - quad[:, 1])
    around = around[facing @ normal > 0.5 * np.linalg.norm(facing, axis=1) * np.linalg.norm(normal)]
    first = corners[1] - corners[0]
    first -= normal * (first @ normal) / (normal @ normal)
    axes = np.array([first, np.cross(normal, first)])
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    frame = (corners.mean(axis=0), axes)
    kind = {**{f: "tab:red" for f in plan.left_faces.tolist()},
            **{f: "tab:green" for f in plan.transition_faces.tolist()},
            **{f: "tab:blue" for f in plan.refine_faces.tolist()}}
    OUT.mkdir(parents=True, exist_ok=True)
    draw(mesh, around, [kind.get(f, "0.6") for f in around.tolist()], frame, OUT / "car_before_wire.png",
         f"before: face {worst} and the faces around it ({len(around)} quads)")
    after = np.flatnonzero(np.isin(refined.source, around))
    level = int(plan.refine_n[plan.refine_faces == worst][0])
    draw(refined.mesh, after, [kind.get(int(refined.source[f]), "0.6") for f in after.tolist()], frame,
         OUT / "car_after_wire.png", f"after: {len(after)} quads (n = {level} at the centre)")
    print(worst, float(plan.before.max()), len(around), len(after))


if __name__ == "__main__":
    main()
