"""Processes of a run, found in /proc (Linux): start one, list its children, wait for them to go; and the big
grid that keeps two workers busy (the ``big_meshes`` fixture of tests/conftest.py)."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import numpy as np

#: Quads a side of the test mesh: 90,000 disaffine quads, a 7 MB JSON output that takes a second or more.
SIDE = 300


def write_grid(path: Path, side: int = SIDE, seed: int = 0) -> None:
    """A ``side`` x ``side`` grid of quads with jittered positions and regular uv: every quad disaffine."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0 : side + 1, 0 : side + 1].astype(float)
    positions = np.column_stack([(x + rng.uniform(-0.3, 0.3, x.shape)).ravel(),
                                 (y + rng.uniform(-0.3, 0.3, y.shape)).ravel()])
    corner = (np.arange(side)[:, None] * (side + 1) + np.arange(side)[None, :]).ravel() + 1
    faces = np.column_stack([corner, corner + 1, corner + side + 2, corner + side + 1])
    lines = [f"v {px:.4f} {py:.4f} 0" for px, py in positions]
    lines += [f"vt {u:.4f} {v:.4f}" for u, v in np.column_stack([x.ravel(), y.ravel()]) / side]
    lines += ["f " + " ".join(f"{k}/{k}" for k in face) for face in faces.tolist()]
    path.write_text("\n".join(lines) + "\n")


def start(*args: str, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "affinity.cli", *args], cwd=cwd,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def children(pid: int) -> list[int]:
    """The live processes whose parent is ``pid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            fields = state_and_parent(int(entry.name))
            if fields is not None and fields[1] == pid and fields[0] != "Z":
                found.append(int(entry.name))
    return found


def state_and_parent(pid: int) -> tuple[str, int] | None:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    state, parent = stat.rsplit(")", 1)[1].split()[:2]
    return state, int(parent)


def alive(pid: int) -> bool:
    """Running (a zombie waiting for init to reap it is not)."""
    fields = state_and_parent(pid)
    return fields is not None and fields[0] != "Z"


def wait_for(condition, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.01)
    return condition()
