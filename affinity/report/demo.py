"""What ``affinity report`` reports on: mesh files, or the built-in demo scenes with their views."""

from __future__ import annotations

from dataclasses import dataclass

from ..scenes import DEMO_DIR, DEMO_SCENES, View


@dataclass(frozen=True)
class MeshInput:
    """A mesh to report on: its path, the name the report gives it, and its view."""

    path: str
    label: str
    view: View = View()


def demo_inputs() -> list[MeshInput]:
    """Every bundled demo scene (``affinity.scenes.DEMO_SCENES``), each with its view."""
    return [MeshInput(str(DEMO_DIR / scene.file), f"{scene.file} (built-in demo)", scene.view) for scene in DEMO_SCENES]
