"""The stability table's rows and the tolerance constants they are judged by.

Kept apart from the mpmath references so that reading a committed table
(``affinity.stability.table.from_csv``) needs NumPy only.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Unit roundoff u of each precision.
UNIT_ROUNDOFF = {"float64": 2.0**-53, "float32": 2.0**-24}
#: A case's tolerance is max(TOLERANCE_FLOOR u, TOLERANCE_FACTOR x its condition estimate).
TOLERANCE_FLOOR = 64
TOLERANCE_FACTOR = 16


@dataclass(frozen=True)
class Row:
    """One case, method and precision.

    ``points``: points with an exact result (a float32 rounding can leave
    none); ``error`` and ``tolerance`` at the point with the worst ``ratio``
    (error / tolerance, inf for a non-finite result); ``unity``, ``linear``,
    ``lagrange``: worst defects (``properties``; unity is NaN for (s, t)).
    ``status``: "pass" (finite, ratio <= 1, every defect <= 64 u), "fail", or
    "skip" (no point has an exact result: only after rounding to float32).
    """

    case: str
    group: str
    method: str
    naive: bool
    precision: str
    points: int
    error: float
    tolerance: float
    ratio: float
    unity: float
    linear: float
    lagrange: float
    status: str
