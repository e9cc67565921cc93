"""The calibration table of the README: findings per rule and level with the default settings.

Runs ``affinity check --format json`` (defaults, no configuration file) on
every mesh of ``../shared/meshes/MANIFEST.json`` and prints one Markdown row
per mesh: its quads, then per rule the number of findings and the level.
The last column counts the quads the old Q202 (relative warp above 0.01,
``affinity.geometry.nonplanarity``) flagged, beside today's fold angle.

    python benchmarks/calibration.py [MESH_FOLDER] > table.md
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from affinity.geometry import nonplanarity
from affinity.loaders import load
from affinity.rules import RULES

MESHES = Path(__file__).resolve().parents[2] / "shared" / "meshes"
#: The old Q202 default: relative warp (distance between the diagonals over their mean length).
OLD_WARP_THRESHOLD = 0.01


def old_q202(path: Path) -> int:
    """Quads the old Q202 flagged: relative warp above 0.01."""
    mesh = load(str(path))
    quads = np.flatnonzero(mesh.face_sizes == 4)
    corners = mesh.positions[mesh.corner_vertex[mesh.face_start[quads][:, None] + np.arange(4)]]  # (Q, 4, 3)
    return int((nonplanarity(corners) > OLD_WARP_THRESHOLD).sum())


def row(path: Path) -> tuple[str, int, dict[str, tuple[int, str]], int]:
    """(name, quads, {code: (findings, level)}, old Q202 count) of one mesh checked with the defaults."""
    result = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--isolated", "--format", "json",
                             str(path)], capture_output=True, text=True, check=False)
    doc = json.loads(result.stdout)
    found: dict[str, tuple[int, str]] = {}
    for finding in doc["findings"]:
        n, _ = found.get(finding["code"], (0, finding["level"]))
        found[finding["code"]] = (n + 1, finding["level"])
    return path.name, doc["files"][0]["quads"], found, old_q202(path)


def table(folder: Path) -> str:
    manifest = json.loads((folder / "MANIFEST.json").read_text())
    rows = [row(folder / entry["file"]) for entry in manifest]
    codes = [code for code in RULES if any(code in found for _, _, found, _ in rows)]
    head = ["mesh", "quads", *(f"{code} ({RULES[code].level})" for code in codes), "Q202 before (warp > 0.01)"]
    lines = ["| " + " | ".join(head) + " |", "|---|" + "---:|" * (len(head) - 1)]
    for name, quads, found, old in rows:
        cells = [f"{found[code][0]:,}" if code in found else "0" for code in codes]
        lines.append(f"| {name} | {quads:,} | " + " | ".join(cells) + f" | {old:,} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.stdout.write(table(Path(sys.argv[1]) if len(sys.argv) > 1 else MESHES))
