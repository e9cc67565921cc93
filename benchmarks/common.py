"""What the benchmark scripts share: the ``--small``/``--out`` options and writing a table to ``reports/bench``."""

from __future__ import annotations

import argparse
from pathlib import Path

#: Where every benchmark writes its table (``reports/bench/<script>.md``).
OUT = Path(__file__).resolve().parents[1] / "reports" / "bench"


def parse_with_output(parser: argparse.ArgumentParser, small: str, out: str, argv=None) -> argparse.Namespace:
    """``parser``'s arguments with ``--small`` (a quick run, help ``small``) and ``--out`` (the
    folder of the table, default :data:`OUT`, help ``out``) added."""
    parser.add_argument("--small", action="store_true", help=small)
    parser.add_argument("--out", type=Path, default=OUT, help=out)
    return parser.parse_args(argv)


def write_table(lines: list[str], folder: Path, name: str) -> str:
    """Write ``lines`` as ``folder/name`` (folder made when missing) and print them; return the text."""
    table = "\n".join(lines) + "\n"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(table)
    print(table, end="")
    return table
