"""Static close-ups show their crease: on every shared mesh, and on a copy of Spot with every face's corner order
reversed, each uv or colour close-up's split and exact panels differ by at least 8/255 over a region at least
3 pixels across (a 3 x 3 block) inside the outlined place's box, decoded from the page's own PNGs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from helpers.closeup_panels import Closeups, decode_panel
from helpers.corpus import SHARED_MESHES

from affinity.draw.shading import FLAG_COLOUR
from affinity.rules import RULES

pytestmark = pytest.mark.slow  # a report of every shared mesh

MESHES = sorted(SHARED_MESHES.glob("*.obj")) if SHARED_MESHES.is_dir() else []
#: Rules whose close-up shows a crease of the attribute (uv, colours), from the registry.
CREASE_RULES = tuple(code for code, rule in RULES.items() if rule.scored and rule.attribute in ("texcoords", "colors"))
CHANGED_STEP = 8
#: The crease must hold a SPAN x SPAN block of changed pixels.
SPAN = 3





def _widest_block(changed: np.ndarray) -> bool:
    """Whether ``changed`` (H, W) bool holds a SPAN x SPAN block of True."""
    height, width = changed.shape
    block = np.ones((height - SPAN + 1, width - SPAN + 1), dtype=bool)
    for dy in range(SPAN):
        for dx in range(SPAN):
            block &= changed[dy:dy + height - SPAN + 1, dx:dx + width - SPAN + 1]
    return bool(block.any())


def _reversed_copy(source: Path, folder: Path) -> Path:
    """``source`` with every face's corners in the opposite order (the file winds its faces clockwise)."""
    lines = []
    for line in source.read_text(encoding="utf-8").splitlines():
        if line.startswith("f "):
            line = "f " + " ".join(reversed(line.split()[1:]))
        lines.append(line)
    copy = folder / f"{source.stem}_reversed.obj"
    copy.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return copy


@pytest.mark.parametrize("mesh", [*MESHES, "reversed spot_control_mesh.obj"],
                         ids=lambda mesh: getattr(mesh, "name", mesh))
def test_closeups_show_a_crease_at_least_3_pixels_across(mesh, tmp_path, report_of):
    if not MESHES:
        pytest.skip("../shared/meshes is absent")
    if isinstance(mesh, str):
        mesh = _reversed_copy(SHARED_MESHES / "spot_control_mesh.obj", tmp_path)
    built, report = report_of(mesh)
    assert built.returncode == 0, built.stderr
    parser = Closeups()
    parser.feed(report.read_text(encoding="utf-8"))
    flag = np.array([int(FLAG_COLOUR[i:i + 2], 16) for i in (1, 3, 5)])
    figures = [figure for figure in parser.figures if figure["rule"] in CREASE_RULES]
    assert figures  # every shared mesh has a uv or colour finding with a close-up
    for figure in figures:
        split, exact = decode_panel(figure["images"]["split"]), decode_panel(figure["images"]["exact"])
        rows, columns = np.nonzero((split == flag).all(axis=-1))  # the place's outline
        box = (slice(rows.min(), rows.max() + 1), slice(columns.min(), columns.max() + 1))
        changed = np.abs(split - exact).max(axis=-1) >= CHANGED_STEP
        assert _widest_block(changed[box]), (mesh.name, figure["rule"], figure["face"], int(changed[box].sum()))
