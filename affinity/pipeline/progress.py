"""Progress of a long check on stderr: a bar for a person at a terminal, JSON lines for a farm.

Both wrap the stream of ``(task index, report)`` pairs that
:func:`affinity.pipeline.check.check_files` hands its ``progress`` (each pair passed on
unchanged, as it arrives) and say the files done of the total, the findings so far,
files per second and the time left at that rate.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from typing import TextIO

from ..findings import FileReport

Progress = Callable[[Iterable[tuple[int, FileReport]], int], Iterator[tuple[int, FileReport]]]

#: ``--progress`` choices: ``auto`` is a bar where stderr is a terminal and nothing elsewhere.
MODES = ("auto", "bar", "json", "none")
#: Seconds between two JSON progress lines (the first and the last are always written).
JSON_INTERVAL = 1.0


def progress_for(mode: str, files: int, stream: TextIO | None = None) -> Progress | None:
    """The progress of ``--progress mode`` for a run of ``files`` files (None: none is shown).

    ``auto`` shows the bar on a terminal and only for more than one file; ``bar`` and ``json`` always.
    """
    stream = sys.stderr if stream is None else stream
    if mode == "json":
        return lambda results, total: json_lines(results, total, stream)
    if mode == "bar" or (mode == "auto" and files > 1 and stream.isatty()):
        return lambda results, total: bar(results, total, stream)
    return None


def bar(results: Iterable[tuple[int, FileReport]], total: int, stream: TextIO) -> Iterator[tuple[int, FileReport]]:
    """A tqdm bar: files, findings so far, files per second and the time left (tqdm imported only here)."""
    from tqdm import tqdm

    findings = 0
    with tqdm(total=total, unit="file", delay=1.0, leave=False, file=stream) as shown:
        for result in results:
            findings += result[1].n_findings
            shown.set_postfix_str(f"{findings} findings", refresh=False)
            shown.update()
            yield result


def json_lines(results: Iterable[tuple[int, FileReport]], total: int, stream: TextIO,
               clock: Callable[[], float] = time.monotonic) -> Iterator[tuple[int, FileReport]]:
    """One JSON object a line on ``stream``, at most every :data:`JSON_INTERVAL` seconds and once at the end::

        {"progress": "check", "done": 120, "total": 4000, "findings": 311, "unreadable": 0,
         "elapsed_s": 12.5, "files_per_s": 9.6, "eta_s": 404.2}

    ``eta_s`` is the time left at the rate so far (null before the first file).
    """
    start = clock()
    done = findings = unreadable = 0
    last, last_done = None, 0

    def line(now: float) -> str:
        elapsed = now - start
        rate = done / elapsed if elapsed > 0 else None
        eta = (total - done) / rate if rate else None
        return json.dumps({"progress": "check", "done": done, "total": total, "findings": findings,
                           "unreadable": unreadable, "elapsed_s": round(elapsed, 3),
                           "files_per_s": None if rate is None else round(rate, 3),
                           "eta_s": None if eta is None else round(eta, 1)}) + "\n"

    stream.write(line(start))
    for result in results:
        done += 1
        findings += result[1].n_findings
        unreadable += result[1].error is not None
        now = clock()
        if last is None or now - last >= JSON_INTERVAL:
            stream.write(line(now))
            stream.flush()
            last, last_done = now, done
        yield result
    if last_done != done or last is None:
        stream.write(line(clock()))
    stream.flush()
