"""The cost of filtering texture lookups: trilinear mip-mapping against base-level bilinear, side by side.

For each shared mesh with uv (and Spot with its own texture), one split render at the report's size gives the
frame; then ``affinity.draw.shading.shade`` colours it with the lookups mip-mapped (what every render does) and
with the base level only (what it did before), alternating, ``--repeat`` rounds each; the table gives the
medians and their ratio, and the shading's share of the whole render. The mip pyramid is built on every call,
as a render does.

    python benchmarks/bench_texture_filter.py            # 800 x 600, 5 rounds
    python benchmarks/bench_texture_filter.py --small --out /tmp/bench   # 240 x 180, 2 rounds
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from unittest import mock

from common import parse_with_output, run_conditions, write_table

MESHES = ("osd_catmark_car.obj", "makehuman_base_hm08.obj", "osd_catmark_bishop.obj",
          "textured/spot_control_mesh_textured.obj")
SHARED = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "meshes")


def main(argv=None) -> None:
    import numpy as np

    from affinity import RenderOptions, render_mesh
    from affinity.draw import shading, texture

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parse_with_output(parser, "240 x 180, 2 rounds", "folder of the table")
    width, height, rounds = (240, 180, 2) if args.small else (800, 600, args.repeat)
    load = os.getloadavg()[0]
    lines = [f"Texture filtering at {width} x {height}: {run_conditions(load, rounds)}.", "",
             "| mesh | texture | shade, mip-mapped (s) | shade, base level (s) | ratio | render (s) |",
             "|---|---:|---:|---:|---:|---:|"]
    base_level = mock.patch.object(texture, "sample_mipmapped",
                                   lambda image, uv, footprint: texture.sample_bilinear(image, uv))
    for name in MESHES:
        path = os.path.join(SHARED, name)
        if not os.path.isfile(path):
            continue
        start = time.perf_counter()
        drawn = render_mesh(path, RenderOptions(method="split", show="uv", width=width, height=height))
        whole = time.perf_counter() - start
        covered = drawn.frame.face >= 0
        direction = np.subtract(drawn.camera.eye, drawn.camera.target)
        painted = texture.painted_texture(drawn.mesh)
        colour = texture.checker() if not painted else texture.load_image(painted)
        times = {"mip": [], "base": []}
        for _ in range(rounds):
            for kind in ("mip", "base"):
                start = time.perf_counter()
                if kind == "base":
                    with base_level:
                        shading.shade(drawn.frame.attrs, covered, drawn.inputs, "uv", colour, direction)
                else:
                    shading.shade(drawn.frame.attrs, covered, drawn.inputs, "uv", colour, direction)
                times[kind].append(time.perf_counter() - start)
        mip, base = statistics.median(times["mip"]), statistics.median(times["base"])
        lines.append(f"| {name} | {colour.shape[1]} x {colour.shape[0]} | {mip:.3f} | {base:.3f} | "
                     f"{mip / base:.2f} | {whole:.2f} |")
    write_table(lines, args.out, "bench_texture_filter.md")


if __name__ == "__main__":
    main()
