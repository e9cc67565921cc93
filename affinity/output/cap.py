"""The run cap of SARIF results and GitHub annotations (design.md, output size).

Code scanning takes at most 25,000 results a run, and a reader looks at far
fewer, so a run keeps at most ``cap`` of them: first the findings at the
failing level (``--fail-on`` and above) of every file, then each lower level in
turn. Where a level does not fit in what is left, every file gets a fair share
of it (the same number each, a file with fewer keeping all of its own and
leaving the rest to the others), each file its worst first. A big file cannot
crowd a small one's errors out, and no warning is kept while an error is
dropped. :func:`cap_findings` is the one place this is decided; ``affinity
check`` and ``affinity merge`` call it on their findings.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..rules import LEVELS


@dataclass
class Capped:
    """What :func:`cap_findings` kept.

    Attributes
    ----------
    kept : list of (k,) int64, one per file: the indices of its findings kept, rising
    levels : level -> (kept, total), for the levels with findings
    cap : the cap applied
    """

    kept: list[np.ndarray]
    levels: dict[str, tuple[int, int]]
    cap: int

    @property
    def truncated(self) -> bool:
        return any(kept < total for kept, total in self.levels.values())

    def note(self, what: str) -> str | None:
        """The truncation line (a SARIF notification, a GitHub annotation, stderr), None when nothing was cut.

        It says per level what was left out: ``SARIF results truncated: the worst 5,000 of 6,600 are kept; left
        out: 1,600 of 6,000 warning (...)``.
        """
        if not self.truncated:
            return None
        kept = sum(k for k, _ in self.levels.values())
        total = sum(t for _, t in self.levels.values())
        dropped = ", ".join(f"{total - k:,} of {total:,} {level}" for level, (k, total) in self.levels.items()
                            if k < total)
        return (f"{what} truncated: the worst {kept:,} of {total:,} are kept; left out: {dropped} "
                f"(at most {self.cap:,} per run by default, the failing level first and a fair share per file; "
                "--max-findings N keeps the worst N per file and rule instead)")


def fair_shares(counts: np.ndarray, capacity: int) -> np.ndarray:
    """How many of each file's ``counts`` (F,) int64 fit in ``capacity``: all when they do; else the same
    number s each (the largest that fits), files with fewer keeping theirs, and what is left one more each
    to the first files with more.

    >>> fair_shares(np.array([4000, 3, 900]), 1000).tolist()
    [499, 3, 498]
    """
    counts = np.asarray(counts, dtype=np.int64)
    if counts.sum() <= capacity:
        return counts.copy()
    low, high = 0, int(counts.max())
    while low < high:  # the largest s with sum(min(counts, s)) <= capacity
        middle = (low + high + 1) // 2
        low, high = (middle, high) if np.minimum(counts, middle).sum() <= capacity else (low, middle - 1)
    shares = np.minimum(counts, low)
    left = capacity - int(shares.sum())
    shares[np.flatnonzero(counts > low)[:left]] += 1
    return shares


def cap_findings(ranked: Sequence[tuple[np.ndarray, np.ndarray]], fail_on: str, cap: int) -> Capped:
    """Keep at most ``cap`` findings of a run, the failing level first, a fair share per file.

    Parameters
    ----------
    ranked : per file, ``(levels, badness)``: (n,) int level rank of each finding (0 ``error``,
        1 ``warning``, 2 ``info``; ``RuleHits.level_ranks``) and (n,) float64 order within a
        level, lowest the worst (``affinity.output.badness``)
    fail_on : the lowest failing level (``--fail-on``): every level from it up is one tier, kept
        before any lower level
    cap : the most findings kept
    """
    ranks = [np.asarray(levels, dtype=np.int64) for levels, _ in ranked]
    # Tier 0: every failing level; then one tier per lower level.
    failing = LEVELS.index(fail_on)
    tiers = [np.maximum(r - failing, 0) for r in ranks]
    worst_first = [np.lexsort((np.arange(len(r)), np.asarray(bad, dtype=float), r))
                   for r, (_, bad) in zip(ranks, ranked)]
    kept = [np.zeros(0, dtype=np.int64) for _ in ranked]
    left = cap
    for tier in range(len(LEVELS) - failing):
        members = [order[tier_of[order] == tier] for order, tier_of in zip(worst_first, tiers)]
        shares = fair_shares(np.array([len(m) for m in members], dtype=np.int64), left)
        kept = [np.concatenate([k, m[:share]]) for k, m, share in zip(kept, members, shares.tolist())]
        left -= int(shares.sum())
    kept = [np.sort(k) for k in kept]
    levels = {}
    for rank, level in enumerate(LEVELS):
        total = sum(int((r == rank).sum()) for r in ranks)
        if total:
            levels[level] = (sum(int((r[k] == rank).sum()) for r, k in zip(ranks, kept)), total)
    return Capped(kept, levels, cap)
