"""The issue-51 scene: a 6 x 6 grid of unit quads whose uv is sheared by a bilinear term, under a 256 px checker.

uv = (x / 6 + k x y / 36, y / 6) adds k / 36 s t to u in each quad's own (s, t), and the split of s t along
either diagonal misses it by at most 1/4 (at the centre), so every quad shifts by 256 k / 144 texels (SHIFT).
"""

from __future__ import annotations

import numpy as np

SIDE, TEXTURE = 6, 256
#: The shear: 1.0667 texels per quad, above the 0.5 texel threshold and above visible-min-shift (1.0).
SHEAR = 0.6
SHIFT = TEXTURE * SHEAR / 144


def grid_obj(folder, material: str | None = "checker", split_materials: bool = False, contrast: int = 255):
    """The sheared grid as an OBJ in ``folder``: with ``material`` a 256 px 8 x 8 checker of grey levels 0 and
    ``contrast`` bound by an MTL (none: no MTL); with ``split_materials`` the left half of the quads in a second
    material without a map."""
    from PIL import Image

    checks = (np.indices((TEXTURE, TEXTURE)) // (TEXTURE // 8)).sum(axis=0) % 2
    Image.fromarray((checks * contrast).astype(np.uint8)).convert("RGB").save(folder / "checker.png")
    (folder / "grid.mtl").write_text("newmtl checker\nmap_Kd checker.png\nnewmtl plain\nKd 1 1 1\n")
    lines = ["mtllib grid.mtl"] if material else []
    for y in range(SIDE + 1):
        for x in range(SIDE + 1):
            lines.append(f"v {x} {y} 0")
            lines.append(f"vt {x / SIDE + SHEAR * x * y / SIDE ** 2:.17g} {y / SIDE:.17g}")
    current = None
    for y in range(SIDE):
        for x in range(SIDE):
            wanted = "plain" if split_materials and x < SIDE // 2 else material
            if wanted and wanted != current:
                lines.append(f"usemtl {wanted}")
                current = wanted
            corners = [y * (SIDE + 1) + x + 1, y * (SIDE + 1) + x + 2, (y + 1) * (SIDE + 1) + x + 2,
                       (y + 1) * (SIDE + 1) + x + 1]
            lines.append("f " + " ".join(f"{c}/{c}" for c in corners))
    path = folder / "grid.obj"
    path.write_text("\n".join(lines) + "\n")
    return path
