"""``affinity stability [--float32] [-o DIR]``: the numerical stability catalogue (issue 11).

Prints the table (case, method, precision, error, tolerance, ratio, status); with ``-o DIR``
writes ``stability.csv`` and ``stability.md`` into DIR (nothing is written without it: a run
from the checkout leaves the committed ``reports/stability`` as it is unless asked,
``-o reports/stability``). Exit 1 when a float64 case of ``render.coords`` fails its tolerance;
float32 rows are reported only.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from ..errors import UsageError
from . import EXIT_CLEAN, EXIT_FINDINGS, require

#: Where the committed catalogue lives (written there only when named with ``-o``).
COMMITTED_DIR = "reports/stability"
CSV_NAME, MARKDOWN_NAME = "stability.csv", "stability.md"


def add_parser(sub) -> None:
    p = sub.add_parser(
        "stability", help="check the quad coordinates on stiff cases against their condition",
        description="Run the catalogue of stiff cases through mean_value and inverse_bilinear, compare "
                    "with 60-digit references, and check each error against the case's own condition.",
    )
    p.add_argument("--float32", action="store_true",
                   help="also run every case in float32 (reported, never failing the command)")
    p.add_argument("-o", "--output", metavar="DIR",
                   help=f"write {CSV_NAME} and {MARKDOWN_NAME} into DIR (default: only print the table; the "
                        f"committed catalogue is {COMMITTED_DIR})")
    p.set_defaults(run=run)


def run(args) -> int:
    require(("mpmath",), "stability")
    from ..atomic import atomic_write
    from ..output.names import printable
    from ..stability import table
    from ..stability.run import PRECISIONS
    from ..stability.run import run as run_catalogue

    folder = None if args.output is None else Path(args.output)
    try:
        if folder is not None:
            folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise UsageError(f"{printable(str(folder))}: cannot create ({err.strerror or err})") from None
    started = time.perf_counter()
    rows = run_catalogue(PRECISIONS if args.float32 else PRECISIONS[:1])
    seconds = time.perf_counter() - started
    sys.stdout.write(table.text(rows))
    failed = any(r.status == "fail" and r.precision == "float64" and not r.naive for r in rows)
    if folder is None:
        return EXIT_FINDINGS if failed else EXIT_CLEAN
    try:
        with atomic_write(folder / CSV_NAME) as f:
            f.write(table.to_csv(rows))
        with atomic_write(folder / MARKDOWN_NAME) as f:
            f.write(table.markdown(rows, seconds))
    except OSError as err:
        raise UsageError(f"{printable(str(folder))}: cannot write ({err.strerror or err})") from None
    return EXIT_FINDINGS if failed else EXIT_CLEAN
