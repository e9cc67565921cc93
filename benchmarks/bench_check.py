"""``affinity check`` end to end against ``pyvista.read`` (and trimesh) on one big OBJ.

The goal of issue 28: ``affinity check`` on a 1,000,000-quad OBJ with uv and
normals (about 166 MB), as a user runs it (interpreter start, imports, load,
every lint rule, JSON output, the result cache off so every round checks),
takes at most half the time of ``pyvista.read`` alone; its peak resident memory
is stated beside it. The table gives the ratio of the median rounds.

Every case runs in a fresh process, with its bytecode cached as after a pip install
(an editable checkout run under PYTHONDONTWRITEBYTECODE would compile every
module of ``affinity`` from source on every start, while pyvista's come compiled;
see ``bench_startup.installed_env``): one untimed run of every case first fills the
cache. The cases then take turns, round after round,
so that whatever else the machine is doing weighs on all of them alike; for
each the fastest and the median round are reported, with the CPU time (user +
system) and peak memory of that process. One more child times the phases of
``affinity check`` inside one process (load, lint, output, best of the rounds).
The load average before and after tells how quiet the machine was.

    python benchmarks/bench_check.py                     # 1M quads in a temp dir, 5 rounds
    python benchmarks/bench_check.py --path /tmp/grid.obj --rounds 9 --trimesh
    python benchmarks/bench_check.py --small --out /tmp/bench   # 2,000 quads, 1 round (the test's case)

The table goes to ``<out>/bench_check.md`` (default ``reports/bench/``), the
figures beside it as ``bench_check.json``.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from bench_load import write_grid_obj
from bench_startup import installed_env
from common import parse_with_output, write_table

#: name -> (module that must be importable, Python statement run in the child)
READERS = {
    "pyvista.read": ("pyvista", "import pyvista, sys; pyvista.read(sys.argv[1])"),
    "trimesh.load(process=False)": ("trimesh", "import trimesh, sys; trimesh.load(sys.argv[1], process=False)"),
}

#: The phases of ``affinity check`` in one process, as ``affinity.pipeline.check_file`` and
#: the JSON writer run them; prints seconds (wall, CPU) per phase.
PHASES = """
import io, sys, time
from affinity.commands.allocator import keep_freed_memory
keep_freed_memory()
from affinity.pipeline.check import check_file, whole_source
from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.output import CheckRun
from affinity.output.json import write
from affinity.settings import Settings

def timed(step):
    wall, cpu = time.perf_counter(), time.process_time()
    result = step()
    return result, time.perf_counter() - wall, time.process_time() - cpu

settings = Settings()
mesh, *load_times = timed(lambda: load(sys.argv[1], None, whole_source(sys.argv[1])))  # read as the check reads it
_, *lint_times = timed(lambda: lint_mesh(mesh, settings))
del mesh
report = check_file(sys.argv[1], settings)
_, *output_times = timed(lambda: write(CheckRun([report], settings), io.StringIO()))
print(*load_times, *lint_times, *output_times)
"""


def machine() -> str:
    """CPU model, CPUs this process may use, NumPy version."""
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            model = next(line.split(":", 1)[1].strip() for line in fh if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    import numpy

    return f"{model}, {cpus} CPUs, Python {platform.python_version()}, NumPy {numpy.__version__}"


#: The checkout this benchmark belongs to: its children import ``affinity`` from here (a
#: git worktree measures itself, not the checkout the environment has installed).
CHECKOUT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def revision() -> str:
    """The commit of :data:`CHECKOUT` (``unknown`` outside git)."""
    try:
        found = subprocess.run(["git", "-C", CHECKOUT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    except OSError:
        return "unknown"
    return found.stdout.strip() or "unknown"


def run(command: list[str], pycache: str) -> tuple[float, float, float, str, int]:
    """Run a child, its bytecode cached in the folder ``pycache``; return (wall s, CPU s = user + system,
    peak RSS MiB, stdout, exit code)."""
    env = dict(installed_env(pycache),
               PYTHONPATH=os.pathsep.join(filter(None, [CHECKOUT, os.environ.get("PYTHONPATH")])))
    start = time.perf_counter()
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
    out = child.stdout.read()
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024, out, os.waitstatus_to_exitcode(status)


def check_command() -> list[str] | None:
    script = shutil.which("affinity", path=os.path.dirname(sys.executable)) or shutil.which("affinity")
    if script is None and importlib.util.find_spec("affinity.cli") is None:
        return None
    return [script] if script else [sys.executable, "-m", "affinity.cli"]


CHECK = "affinity check --no-cache --format json"
REFERENCE = "pyvista.read"


def table(results: dict, phases: list, header: list[str]) -> list[str]:
    """The Markdown lines: the header notes, one row per case, the ratio of check to pyvista.read, the phases."""
    lines = [*header, "", "| case | best s | median s | CPU s (best run) | peak RSS MiB |", "|---|---:|---:|---:|---:|"]
    medians = {}
    for name, rows in results.items():
        ok = [r for r in rows if r[3] in (0, 1)]  # check: 0 clean, 1 findings
        if not ok:
            lines.append(f"| {name} | failed (exit {rows[0][3]}) | | | |")
            continue
        best = min(ok)
        medians[name] = statistics.median(r[0] for r in ok)
        lines.append(f"| {name} | {best[0]:.2f} | {medians[name]:.2f} | {best[1]:.2f} | {max(r[2] for r in ok):.0f} |")
    if CHECK in medians and REFERENCE in medians:
        lines += ["", f"`{CHECK}` / `{REFERENCE}` (medians): {medians[CHECK] / medians[REFERENCE]:.2f} "
                      f"(goal: at most 0.5)"]
    if phases:
        best = [min(p[i] for p in phases) for i in range(6)]
        lines += ["", "Inside one `affinity check` process (best of the rounds; wall s / CPU s): "
                      f"load {best[0]:.2f} / {best[1]:.2f}, lint {best[2]:.2f} / {best[3]:.2f}, "
                      f"JSON output {best[4]:.3f} / {best[5]:.3f}"]
    return lines


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quads", type=int, default=1_000_000, help="quads in the generated OBJ (default 1,000,000)")
    parser.add_argument("--path", help="OBJ to use; generated there when missing (default: a temp file)")
    parser.add_argument("--rounds", type=int, default=5, help="runs of every case, taking turns (default 5)")
    parser.add_argument("--trimesh", action="store_true", help="also time trimesh.load (slow: about 10 s a run)")
    args = parse_with_output(parser, "2,000 quads, one round: the test's case",
                             "folder of bench_check.md and .json (reports/bench)", argv)
    if args.small:
        args.quads, args.rounds = 2_000, 1

    with tempfile.TemporaryDirectory() as folder:
        path = args.path or os.path.join(folder, f"grid_{args.quads}.obj")
        if not os.path.exists(path):
            write_grid_obj(path, args.quads)
        cases = {}
        command = check_command()
        if command is not None:
            cases[CHECK] = command + ["check", path, "--no-cache", "--format", "json"]
        for name, (module, statement) in READERS.items():
            if importlib.util.find_spec(module) is not None and (args.trimesh or module != "trimesh"):
                cases[name] = [sys.executable, "-c", statement, path]

        header = [f"Measured {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} on {machine()}, "
                  f"affinity at {revision()}.",
                  f"{os.path.getsize(path) / 1e6:.1f} MB OBJ, {args.quads:,} quads with vt and vn; "
                  f"{args.rounds} rounds, every case a fresh process (bytecode cached), taking turns.",
                  f"Load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} "
                  "(a shared machine: figures are noisy; compare the cases of one run)."]
        results = {name: [] for name in cases}
        phases = []
        pycache = os.path.join(folder, "pycache")
        for argv_ in cases.values():  # untimed: compiles the bytecode, reads the file into the page cache
            run(argv_, pycache)
        for _ in range(args.rounds):
            for name, argv_ in cases.items():
                wall, cpu, peak, _, code = run(argv_, pycache)
                results[name].append((wall, cpu, peak, code))
            if command is not None:
                _, _, _, out, code = run([sys.executable, "-c", PHASES, path], pycache)
                if code == 0:
                    phases.append([float(x) for x in out.split()])
        header[-1] += f" After: {' '.join(f'{x:.2f}' for x in os.getloadavg())}."
        lines = table(results, phases, header)
    write_table(lines, args.out, "bench_check.md")
    (args.out / "bench_check.json").write_text(json.dumps(
        {"quads": args.quads, "rounds": args.rounds, "cases": results, "phases": phases}, indent=1) + "\n")


if __name__ == "__main__":
    main()
