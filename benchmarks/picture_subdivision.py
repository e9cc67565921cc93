"""The picture of docs/measure.md's "Subdivision" section: Spot's crease at levels 0, 1 and 2 side by side.

Spot's control mesh with its texture (``../shared/meshes/textured/``) drawn with the split (two triangles a quad,
as every rasterizer draws a quad), close up on the base face whose Q101 is worst at
level 2, as the cage (L0) and refined once and twice (cornersPlus1, level points: what Blender's Subdivision
Surface draws with use_limit_surface off). Each panel is 360 x 360 pixels; the camera looks along the face's
normal from 3 of its sizes away.

    python benchmarks/picture_subdivision.py [--out reports/subdivision]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPOT = ROOT.parent / "shared" / "meshes" / "textured" / "spot_control_mesh_textured.obj"


def main(argv=None) -> None:
    from PIL import Image

    from affinity import RenderOptions, render_mesh
    from affinity.lint import lint_pass
    from affinity.loaders import load
    from affinity.settings import Settings
    from affinity.subdivision import Scheme
    from affinity.subdivision.measured import Piece, refined_mesh

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "reports" / "subdivision")
    args = parser.parse_args(argv)
    mesh = load(str(SPOT))
    [worst] = lint_pass(mesh, Settings(select=["Q101"], subdivision="level:2")).hits
    face = int(worst.faces[np.argmax(worst.values)])
    corners = mesh.positions[mesh.corner_vertex[mesh.face_start[face]:mesh.face_start[face + 1]]]
    centre = corners.mean(axis=0)
    normal = np.cross(corners[2] - corners[0], corners[3] - corners[1])
    normal /= np.linalg.norm(normal)
    size = np.linalg.norm(corners - centre, axis=1).max()
    camera = (tuple(centre + 3 * size * normal), tuple(centre), 30.0)
    panels = []
    for level in (0, 1, 2):
        drawn = mesh if level == 0 else refined_mesh(mesh, [Piece(np.arange(mesh.n_faces), Scheme(), level)])[0]
        result = render_mesh(drawn, RenderOptions(method="split", width=360, height=360, camera=camera, show="uv"))
        panels.append(np.clip(result.image, 0, 1))
    args.out.mkdir(parents=True, exist_ok=True)
    picture = np.concatenate([np.pad(p, ((0, 0), (0, 8), (0, 0)), constant_values=1) for p in panels], axis=1)
    Image.fromarray((picture * 255).astype(np.uint8)).save(args.out / "spot_crease_levels.png")
    print(f"face {face}: {worst.values.max():.1f} texels at L2; {args.out / 'spot_crease_levels.png'}")


if __name__ == "__main__":
    main()
