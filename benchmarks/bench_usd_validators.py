"""A stage whose prims reference one geometry layer: ``affinity check`` against the USD validators.

The stage holds P prims referencing one layer with a jittered grid of Q quads whose uv is
a square per quad, not an affine image of most of them. ``affinity check`` reports each finding
once, at the first prim (issue 43); the UsdValidation plug-in (``PXR_PLUGINPATH_NAME`` from
``affinity usd-plugin``) and the usd-validation-nvidia rules (its engine, our rule
classes enabled) report the same findings as one error or issue each. Every case is a
fresh process, the cases taking turns; one more process times the check's phases.

    python benchmarks/bench_usd_validators.py [--rounds 5] [--small] [--out reports/bench]

Not a test: run it and read it (``--small``: 4 prims of 400 quads, one round).
"""

from __future__ import annotations

import argparse
import datetime
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from bench_startup import affinity_command, installed_env
from common import ROOT, parse_with_output, write_table

#: Prints the number of errors the quad-affinity validators report on the stage argv[1].
USD_VALIDATION = textwrap.dedent('''
    import sys
    from pxr import Usd, UsdValidation
    errors = UsdValidation.ValidationContext(["quad-affinity"], True).Validate(Usd.Stage.Open(sys.argv[1]))
    print(sum(error.GetName() != "note" for error in errors))
''')
#: Prints the number of issues the quad-affinity rules report through usd-validation-nvidia's engine.
NVIDIA = textwrap.dedent('''
    import sys
    from usd_validation_nvidia import ValidationEngine
    from affinity.usd.nvidia import CHECKERS
    engine = ValidationEngine(init_rules=False)
    for checker in CHECKERS:
        engine.enable_rule(checker)
    print(sum(not issue.message.startswith("note:") for issue in engine.validate(sys.argv[1]).issues()))
''')
#: Prints the composed faces, the findings before and after sharing, and the phases' seconds.
PHASES = textwrap.dedent('''
    import sys, time
    from affinity.findings import settle, share_authored_geometry
    from affinity.lint import lint_mesh
    from affinity.loaders import load
    from affinity.settings import Settings
    start = time.perf_counter()
    mesh = load(sys.argv[1])
    loaded = time.perf_counter()
    settings = Settings()
    hits = settle(lint_mesh(mesh, settings), settings, list(mesh.group_names))
    linted = time.perf_counter()
    shared, _ = share_authored_geometry(hits, mesh)
    done = time.perf_counter()
    print(mesh.n_faces, sum(map(len, hits)), sum(map(len, shared)), loaded - start, linted - loaded, done - linted)
''')


def write_stage(folder: Path, prims: int, side: int) -> Path:
    """``set.usda``: ``prims`` prims referencing ``grid.usda``, a jittered side x side grid of quads, each
    quad's uv a square 1/64 wide (a crease of several texels at 1024)."""
    import numpy as np
    from pxr import Sdf, Usd, UsdGeom, Vt

    rng = np.random.default_rng(43)
    x, y = np.meshgrid(np.arange(side + 1.0), np.arange(side + 1.0))
    points = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    points[:, :2] += rng.uniform(-0.2, 0.2, (len(points), 2))
    first = (np.arange(side)[:, None] * (side + 1) + np.arange(side)[None]).ravel()
    quads = np.stack([first, first + 1, first + side + 2, first + side + 1], axis=1)
    uv = np.tile([[0, 0], [1, 0], [1, 1], [0, 1]], (len(quads), 1)) / 64
    grid = Usd.Stage.CreateNew(str(folder / "grid.usda"))
    mesh = UsdGeom.Mesh.Define(grid, "/Grid")
    mesh.GetPointsAttr().Set(Vt.Vec3fArray.FromNumpy(points.astype(np.float32)))
    mesh.GetFaceVertexCountsAttr().Set(Vt.IntArray.FromNumpy(np.full(len(quads), 4, dtype=np.int32)))
    mesh.GetFaceVertexIndicesAttr().Set(Vt.IntArray.FromNumpy(quads.ravel().astype(np.int32)))
    mesh.GetSubdivisionSchemeAttr().Set("none")
    UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, "faceVarying").Set(
        Vt.Vec2fArray.FromNumpy(uv.astype(np.float32)))
    grid.SetDefaultPrim(mesh.GetPrim())
    grid.GetRootLayer().Save()
    stage = Usd.Stage.CreateNew(str(folder / "set.usda"))
    for k in range(prims):
        stage.DefinePrim(f"/Set/Piece{k}/Grid").GetReferences().AddReference("grid.usda")
    stage.GetRootLayer().Save()
    return folder / "set.usda"


def run_rounds(commands: dict[str, list[str]], rounds: int, env: dict) -> tuple[dict, dict]:
    """Wall seconds of each command over ``rounds`` rounds, taking turns, and each one's last output."""
    times: dict[str, list[float]] = {name: [] for name in commands}
    outputs: dict[str, str] = {}
    for _ in range(rounds):
        for name, command in commands.items():
            start = time.perf_counter()
            result = subprocess.run(command, capture_output=True, text=True, env=env)
            times[name].append(time.perf_counter() - start)
            if result.returncode not in (0, 1):
                raise SystemExit(f"{name} failed:\n{result.stderr}")
            outputs[name] = result.stdout
    return times, outputs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--prims", type=int, default=32)
    parser.add_argument("--side", type=int, default=100, help="quads per side of the grid")
    args = parse_with_output(parser, "4 prims of 20 x 20 quads, one round, for a test",
                             "folder for bench_usd_validators.md")
    prims, side, rounds = (4, 20, 1) if args.small else (args.prims, args.side, args.rounds)

    with tempfile.TemporaryDirectory() as tmp:
        stage = str(write_stage(Path(tmp), prims, side))
        plugin = subprocess.run([*affinity_command(), "usd-plugin"], capture_output=True, text=True, check=True)
        env = {**installed_env(os.path.join(tmp, "pycache")), "PXR_PLUGINPATH_NAME": plugin.stdout.strip(),
               "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
        commands = {
            "`affinity check --no-cache --format json`": [*affinity_command(), "check", "--no-cache", "--format",
                                                          "json", "--jobs", "1", stage],
            "UsdValidation `ValidationContext([\"quad-affinity\"])`": [sys.executable, "-c", USD_VALIDATION, stage],
            "usd-validation-nvidia engine, quad-affinity rules": [sys.executable, "-c", NVIDIA, stage],
        }
        run_rounds(commands, 1, env)  # warm the file and bytecode caches
        times, outputs = run_rounds(commands, rounds, env)
        phases = subprocess.run([sys.executable, "-c", PHASES, stage], capture_output=True, text=True, env=env,
                                check=True).stdout.split()

    import json

    faces, before, after = map(int, phases[:3])
    load, lint, share = map(float, phases[3:])
    reported = {name: (len(json.loads(out)["findings"]) if name.startswith("`affinity") else int(out))
                for name, out in outputs.items()}
    base = statistics.median(next(iter(times.values())))
    lines = [
        f"{prims} prims referencing one layer of {side * side:,} jittered quads ({faces:,} faces as composed), uv a "
        f"square per quad; {rounds} round{'s' * (rounds != 1)} of fresh processes taking turns "
        f"({datetime.date.today().isoformat()}; {os.cpu_count()}-CPU machine shared with other jobs, load average "
        f"{os.getloadavg()[0]:.1f}).",
        "",
        "| case | findings reported | median s | best s | / affinity check |",
        "|---|---:|---:|---:|---:|",
        *(f"| {name} | {reported[name]:,} | {statistics.median(t):.2f} | {min(t):.2f} | "
          f"{statistics.median(t) / base:.2f} |" for name, t in times.items()),
        "",
        f"Inside one process: load {load:.2f} s, lint {lint:.2f} s, reporting shared geometry once {share:.3f} s "
        f"({before:,} findings over the prims to {after:,}).",
    ]
    write_table(lines, args.out, "bench_usd_validators.md")


if __name__ == "__main__":
    main()
