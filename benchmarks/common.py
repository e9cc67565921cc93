"""What the benchmark scripts share: the ``--small``/``--out`` options and writing a table to ``reports/bench``
(and into the README's and docs' copies of it)."""

from __future__ import annotations

import argparse
import os
import platform
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Where every benchmark writes its table (``reports/bench/<script>.md``).
OUT = ROOT / "reports" / "bench"
#: The pages that quote tables between ``<!-- generated: benchmarks/<script>.py -->`` and ``<!-- end generated -->``.
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def parse_with_output(parser: argparse.ArgumentParser, small: str, out: str, argv=None) -> argparse.Namespace:
    """``parser``'s arguments with ``--small`` (a quick run, help ``small``) and ``--out`` (the
    folder of the table, default :data:`OUT`, help ``out``) added."""
    parser.add_argument("--small", action="store_true", help=small)
    parser.add_argument("--out", type=Path, default=OUT, help=out)
    return parser.parse_args(argv)


def run_conditions(load: float, rounds: int) -> str:
    """Where and how a benchmark ran, for its table's first line: processor, CPUs, the load average before,
    and how many rounds the medians are of."""
    return (f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, load {load:.2f} before, "
            f"median of {rounds} round{'s' * (rounds > 1)}")


def markdown_table(head: list[str], rows) -> list[str]:
    """The lines of a Markdown table: ``head`` (column titles), the rule (the first column left-aligned, the
    others, numbers, right-aligned), then one line per row of ``rows`` (each a sequence of cell texts)."""
    line = lambda cells: "| " + " | ".join(cells) + " |"
    return [line(head), "|---|" + "---:|" * (len(head) - 1), *map(line, rows)]


def write_table(lines: list[str], folder: Path, name: str) -> str:
    """Write ``lines`` as ``folder/name`` (folder made when missing) and print them; return the text.

    Written to :data:`OUT`, the table also replaces its quoted copies in :data:`PAGES` (a test checks that
    they are equal).
    """
    table = "\n".join(lines) + "\n"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(table)
    if folder.resolve() == OUT.resolve():
        quote(Path(name).stem, table)
    print(table, end="")
    return table


def quote(stem: str, table: str) -> None:
    """Put ``table`` into every generated block of ``benchmarks/<stem>.py`` in :data:`PAGES`."""
    block = re.compile(rf"(^<!-- generated: benchmarks/{re.escape(stem)}\.py -->\n).*?(^<!-- end generated -->$)",
                       re.S | re.M)
    for page in PAGES:
        text = page.read_text()
        updated = block.sub(lambda match: match[1] + table + match[2], text)
        if updated != text:
            page.write_text(updated)
