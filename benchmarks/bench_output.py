"""Every output format of ``affinity check`` on a mesh with tens of thousands of findings, whole processes.

The goal of issue 38: JSON, SARIF, GitHub and JUnit are written in time and
memory proportional to the findings with small constants: each format's whole
``affinity check`` process takes at most 1.5 times the text output's (which
prints 20 findings per rule) and at most 300 MiB. The mesh is the shared car
subdivided three times (100,800 quads, each mapping the whole texture square:
about 88,000 findings, most of them errors; ``bench_report.write_car``). Each
format writes to a file (``-o``) with the result cache off; the formats take
turns, round after round, so the load of a shared machine weighs on all alike,
after one untimed round that fills the bytecode cache.

    python benchmarks/bench_output.py                 # 100,800 quads, 5 rounds
    python benchmarks/bench_output.py --small --out /tmp/bench   # 6,300 quads, 1 round (the test's case)

The table goes to ``<out>/bench_output.md`` (default ``reports/bench/``) and into the README.
"""

from __future__ import annotations

import os
import platform
import re
import statistics
import sys
import tempfile

from bench_check import revision, run
from bench_report import car_options
from common import write_table

HERE = os.path.dirname(os.path.abspath(__file__))
FORMATS = ("text", "json", "sarif", "github", "junit")
#: The issue's goals: a machine format's median time over the text output's, and its peak memory.
TIME_GOAL, MEMORY_GOAL = 1.5, 300


def main(argv=None) -> None:
    args, levels, rounds = car_options(__doc__, 5, "bench_output.md", argv)
    with tempfile.TemporaryDirectory() as folder:
        mesh = os.path.join(folder, "car.obj")
        pycache = os.path.join(folder, "pycache")
        # Written by a child: a child's peak memory counts from its fork, so this process stays small.
        child = (f"import sys; sys.path.insert(0, {HERE!r}); from bench_report import write_car; "
                 f"print(*write_car({mesh!r}, {levels}), sep='\\t')")
        made = run([sys.executable, "-c", child], pycache)[3]
        source, quads = made.strip().split("\t")
        quads = int(quads)

        def command(fmt: str) -> list[str]:
            return [sys.executable, "-m", "affinity.cli", "check", "--no-cache", "--format", fmt, mesh,
                    "-o", os.path.join(folder, f"out.{fmt}")]

        for fmt in FORMATS:  # fills the bytecode cache
            run(command(fmt), pycache)
        with open(os.path.join(folder, "out.text")) as text_output:  # not the JSON: this process stays small
            summary = text_output.read().splitlines()[-1]  # "Found 88503 findings: 82194 error, ... (1 file checked)."
        load = os.getloadavg()
        times: dict[str, list[float]] = {fmt: [] for fmt in FORMATS}
        cpu: dict[str, list[float]] = {fmt: [] for fmt in FORMATS}
        memory: dict[str, float] = dict.fromkeys(FORMATS, 0.0)
        for _ in range(rounds):
            for fmt in FORMATS:
                wall, seconds, peak, _, code = run(command(fmt), pycache)
                if code not in (0, 1):
                    sys.exit(f"{' '.join(command(fmt))} exited {code}")
                times[fmt].append(wall)
                cpu[fmt].append(seconds)
                memory[fmt] = max(memory[fmt], peak)
        after = os.getloadavg()
        sizes = {fmt: os.path.getsize(os.path.join(folder, f"out.{fmt}")) for fmt in FORMATS}
    median = {fmt: statistics.median(times[fmt]) for fmt in FORMATS}
    best = {fmt: min(times[fmt]) for fmt in FORMATS}
    median_cpu = {fmt: statistics.median(cpu[fmt]) for fmt in FORMATS}
    found = re.match(r"Found (\d+) findings: (.+) \(", summary)
    by_level = re.sub(r"\d+", lambda n: f"{int(n[0]):,}", found[2])
    rows = [
        f"| {fmt} | {median[fmt]:.2f} | {best[fmt]:.2f} | {median_cpu[fmt]:.2f} | "
        f"**{median[fmt] / median['text']:.2f}** | {best[fmt] / best['text']:.2f} | "
        f"{median_cpu[fmt] / median_cpu['text']:.2f} | {memory[fmt]:.0f} | "
        f"{sizes[fmt] / 1e6:.1f} |"
        for fmt in FORMATS
    ]
    worst = max(median[fmt] / median["text"] for fmt in FORMATS[1:])
    write_table([
        f"{quads:,} quads ({source}, per-face unit uv): {int(found[1]):,} findings ({by_level}); "
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, affinity at {revision()}; "
        f"{rounds} round{'s' * (rounds > 1)}, whole `affinity check --no-cache --format F -o FILE` processes taking "
        f"turns. Load average before {load[0]:.2f}, after {after[0]:.2f} (a shared machine: compare the formats of "
        "one run; CPU time is the steadier measure).",
        "",
        "| format | median s | best s | median CPU s | median / text | best / text | CPU / text | peak MiB "
        "| output MB |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"Slowest machine format / text (medians): {worst:.2f} (goal: at most {TIME_GOAL}); largest peak memory "
        f"{max(memory.values()):.0f} MiB (goal: at most {MEMORY_GOAL}).",
    ], args.out, "bench_output.md")


if __name__ == "__main__":
    main()
