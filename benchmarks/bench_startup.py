"""Start-up of ``affinity check`` as a whole process, against ``python -c "import numpy"``.

A pre-commit hook pays the interpreter start, the imports and the check of a few
small files on every commit. Goal (issue 8): ``affinity check`` on a 1k-quad
file within 1.5x of a bare ``import numpy``. Not a test: run it and read it.

    python benchmarks/bench_startup.py [--runs 21] [--small] [--out reports/bench]

Runs alternate between the two commands; the median and the best run are reported, and the
table is written to ``OUT/bench_startup.md``. ``--small`` makes 3 runs.
Both run with a warm bytecode cache, as an installed package (and a pre-commit
hook's virtualenv) has.
"""

from __future__ import annotations

import argparse
import datetime
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import OUT, write_table


def affinity_command() -> list[str]:
    """The installed ``affinity`` console script beside this interpreter, else ``python -m affinity.cli``."""
    script = shutil.which("affinity", path=os.path.dirname(sys.executable))
    return [script] if script else [sys.executable, "-m", "affinity.cli"]


def installed_env(cache: str) -> dict[str, str]:
    """The environment with bytecode cached in ``cache``, as after a pip install.

    An editable install run with PYTHONDONTWRITEBYTECODE compiles every module of
    the package from source on every start, which no installed hook does.
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    return {**env, "PYTHONPYCACHEPREFIX": cache}


def timings(commands: dict[str, list[str]], runs: int, env: dict[str, str] | None = None) -> dict[str, list[float]]:
    """Wall times of ``runs`` runs of each command, interleaved so that load from other
    processes on the machine hits every command alike (output discarded, exit code ignored)."""
    times: dict[str, list[float]] = {name: [] for name in commands}
    for _ in range(runs):
        for name, command in commands.items():
            start = time.perf_counter()
            subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
            times[name].append(time.perf_counter() - start)
    return times


def comparison(times: dict[str, list[float]], label: str, note: str = "", goal: str = "") -> str:
    """A markdown table: median and best time of each command, then ``label``: the last command's
    time over the first's. Other load on the machine only ever adds time, so the best run is the cleanest."""
    runs = len(next(iter(times.values())))
    lines = [
        f"Whole processes, {runs} runs each taking turns ({datetime.date.today().isoformat()}; {os.cpu_count()}-CPU "
        f"machine shared with other jobs, load average {os.getloadavg()[0]:.1f}{note}).",
        "",
        "| command | median ms | best ms |",
        "|---|---:|---:|",
    ]
    lines += [
        f"| {name} | {statistics.median(seconds) * 1000:.1f} | {min(seconds) * 1000:.1f} |"
        for name, seconds in times.items()
    ]
    first, *_, last = times.values()
    lines.append(
        f"| **{label}** | **{statistics.median(last) / statistics.median(first):.2f}x** "
        f"| {min(last) / min(first):.2f}x |"
    )
    return "\n".join(lines) + (f"\n\n{goal}\n" if goal else "\n")


def print_comparison(times: dict[str, list[float]], label: str) -> None:
    print(comparison(times, label), end="")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=21)
    parser.add_argument("--small", action="store_true", help="3 runs, for a test")
    parser.add_argument("--out", type=Path, default=OUT, help="folder for bench_startup.md")
    args = parser.parse_args()
    runs = 3 if args.small else args.runs

    from affinity.loaders.objwriter import write_obj
    from affinity.scenes import latlong_sphere

    with tempfile.TemporaryDirectory() as tmp:
        mesh = os.path.join(tmp, "sphere_1k.obj")
        write_obj(latlong_sphere(32, 32), mesh)  # 1024 quads with uv and normals
        env = installed_env(os.path.join(tmp, "pycache"))
        commands = {
            "`python -c 'import numpy'`": [sys.executable, "-c", "import numpy"],
            "`affinity check` (1,024 quads)": [*affinity_command(), "check", "--jobs", "1", mesh],
        }
        timings(commands, 2, env)  # warm the file cache and the bytecode cache
        times = timings(commands, runs, env)
    table = comparison(times, "check / import numpy", "; bytecode cached as after `pip install`",
                       "Goal (issue 28): at most 1.5x, median.")
    write_table(table.splitlines(), args.out, "bench_startup.md")


if __name__ == "__main__":
    main()
