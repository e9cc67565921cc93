"""Run-time measurement for the study: warm-up, interleaved repeats, median and spread, machine facts.

Every configuration of a scene is timed in the same process, on the same
inputs, and the repeats are interleaved (round 1 runs every configuration once,
then round 2, ...), so that a slow phase of a shared machine (another job, a
frequency change) spreads over all of them instead of penalising one.
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass
class Timing:
    """The repeated run times of one configuration, and the result of its last run.

    ``seconds`` (repeat,) float64, wall-clock (``time.perf_counter``).
    """

    seconds: np.ndarray
    result: object

    @property
    def median(self) -> float:
        return float(np.median(self.seconds))

    @property
    def low(self) -> float:
        return float(self.seconds.min())

    @property
    def high(self) -> float:
        return float(self.seconds.max())


def time_interleaved(calls: list[Callable[[], object]], repeat: int, warmup: int = 1) -> list[Timing]:
    """Time every call ``repeat`` times after ``warmup`` untimed rounds, interleaving the calls.

    Returns one :class:`Timing` per call, in order, holding the result of its last run.

    >>> timings = time_interleaved([lambda: 1, lambda: 2], repeat=3)
    >>> [t.result for t in timings], [t.seconds.shape for t in timings]
    ([1, 2], [(3,), (3,)])
    """
    if repeat < 1:
        raise ValueError(f"repeat must be at least 1, got {repeat}")
    results = [None] * len(calls)
    for _ in range(warmup):
        for k, call in enumerate(calls):
            results[k] = call()
    seconds = np.empty((len(calls), repeat))
    for r in range(repeat):
        for k, call in enumerate(calls):
            start = time.perf_counter()
            results[k] = call()
            seconds[k, r] = time.perf_counter() - start
    return [Timing(seconds[k], results[k]) for k in range(len(calls))]


def machine_facts() -> dict[str, str]:
    """CPU model, logical cores, load average, Python, NumPy and OS: what the timings depend on."""
    facts = {
        "cpu": _cpu_model(),
        "logical cores": str(os.cpu_count()),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "os": platform.platform(terse=True),
    }
    if hasattr(os, "getloadavg"):
        facts["load average (1 min) at start"] = f"{os.getloadavg()[0]:.2f}"
    return facts


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            for line in info:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"
