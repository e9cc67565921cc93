"""The shards' JSON results checked against each other and joined into the reports of one run.

The inputs must be the N shards of one run, each once, each complete:

- each a readable ``affinity check --shard K/N --format json`` result
  (:func:`~affinity.shards.results.read_result`), not truncated by ``--max-findings``, or a
  finished ``--resume`` journal (``.jsonl``, :func:`~affinity.shards.journal.read_journal`);
- all of one run: the same N, the same count and digest of the run's file list,
  the same tool version, the same settings (but for ``root``, the configuration's
  folder, which differs between checkouts) and the same use of a baseline; the
  run is the one most inputs agree on (ties: the first input's), and every other
  input is named as from another run;
- every shard K = 1..N exactly once, and their files filling the run's list.

Every problem is one line naming the input (or the missing shard); the merge
reports them all and gives no result. The merged reports stand in the run's file
order (each shard records its files' positions in it).
"""

from __future__ import annotations

import dataclasses
from collections import Counter

from ..findings import FileReport
from ..settings import Settings
from .journal import read_journal
from .results import CheckResult, ResultError, read_result

#: The suffix of a ``--resume`` journal (JSON lines); every other input is read as a ``--format json`` result.
JOURNAL_SUFFIX = ".jsonl"


class MergeError(Exception):
    """The inputs do not make up one run; ``problems`` holds one line per problem."""

    def __init__(self, problems: list[str]):
        super().__init__("\n".join(problems))
        self.problems = problems


@dataclasses.dataclass
class MergedRun:
    """The reports of the whole run in its file order, the settings it was checked with, and per shard
    result the number of findings a baseline hid (None: no baseline was used)."""

    reports: list[FileReport]
    settings: Settings
    baselined: dict[str, int] | None


def merge_results(paths: list[str]) -> MergedRun:
    """Read the shard results at ``paths`` and join them; :class:`MergeError` when they are not one run."""
    results, problems = [], []
    for path in paths:
        try:
            result = read_journal(path) if path.lower().endswith(JOURNAL_SUFFIX) else read_result(path)
        except ResultError as err:
            problems.append(f"{path}: {err}")
            continue
        if result.shard is None:
            problems.append(f"{path}: not a shard's result (checked without --shard K/N)")
            continue
        if result.truncated:  # still counted as its shard, so it is not also reported missing
            problems.append(f"{path}: truncated by --max-findings: a merge needs every finding "
                            "(check the shard again without --max-findings)")
        results.append(result)
    if results:
        problems += _run_problems(results)
    if problems:
        raise MergeError(problems)
    return _joined(results)


def _identity(result: CheckResult) -> tuple:
    shard = result.shard
    return shard.of, shard.run_files, shard.run_digest, shard.version


def _describe(result: CheckResult) -> str:
    shard = result.shard
    return (f"{shard.of} shards of {shard.run_files} files, file list {shard.run_digest[:12]}, "
            f"quad-affinity {shard.version}")


def _comparable_settings(result: CheckResult) -> dict:
    settings = dataclasses.asdict(result.settings)
    del settings["root"]
    return {**settings, "baseline": result.shard.baseline}


def _run_problems(results: list[CheckResult]) -> list[str]:
    """One line per input that is not part of the run most inputs belong to, per shard given twice,
    and per shard missing."""
    run = Counter(map(_identity, results)).most_common(1)[0][0]  # ties: the first input's
    reference = next(r for r in results if _identity(r) == run)
    problems = [f"{r.path}: from another run ({_describe(r)}; {reference.path}: {_describe(reference)})"
                for r in results if _identity(r) != run]
    ours = [r for r in results if _identity(r) == run]
    expected = _comparable_settings(reference)
    for r in ours:
        differ = [key for key, value in _comparable_settings(r).items() if expected[key] != value]
        if differ:
            problems.append(f"{r.path}: checked with other settings than {reference.path} ({', '.join(differ)})")
    given: dict[int, str] = {}
    for r in ours:
        index = r.shard.index
        if index in given:
            problems.append(f"{r.path}: shard {index}/{r.shard.of} given twice (also {given[index]})")
        else:
            given[index] = r.path
    problems += [f"shard {k}/{reference.shard.of} missing" for k in range(1, reference.shard.of + 1)
                 if k not in given]
    if not problems:
        problems += _position_problems(ours, reference.shard.run_files)
    return problems


def _position_problems(results: list[CheckResult], run_files: int) -> list[str]:
    """A line per shard whose files do not fit the run's list (a damaged record)."""
    problems, placed = [], set()
    for r in results:
        positions = r.shard.positions
        fits = (len(positions) == len(r.reports) and all(0 <= p < run_files for p in positions)
                and placed.isdisjoint(positions))
        if not fits:
            problems.append(f"{r.path}: its files do not fit the run's file list (a damaged shard record)")
        placed.update(positions)
    if not problems and len(placed) != run_files:
        problems.append(f"the shards hold {len(placed)} of the run's {run_files} files")
    return problems


def _joined(results: list[CheckResult]) -> MergedRun:
    reference = results[0]
    reports: list[FileReport | None] = [None] * reference.shard.run_files
    for r in results:
        for position, report in zip(r.shard.positions, r.reports):
            reports[position] = report
    baselined = {r.path: r.baselined for r in results} if reference.shard.baseline else None
    return MergedRun(reports, reference.settings, baselined)
