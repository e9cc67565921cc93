"""Render the collected run into one self-contained HTML page (Jinja2, autoescaped)."""

from __future__ import annotations

from pathlib import Path

from .build import ReportRun
from .sections import CLOSING_SECTIONS, MESH_SECTIONS, file_row, summary_section

TEMPLATES = Path(__file__).parent / "templates"


def plural(count: int, noun: str) -> str:
    """``"1 quad"``, ``"3 quads"`` (the templates' ``plural`` filter)."""
    return f"{count} {noun}" + ("" if count == 1 else "s")


def render_page(run: ReportRun) -> str:
    """The report as HTML text.

    Autoescaping is on for every template: file names, group names and error
    messages come from the user's files and must show as text, never as markup.
    """
    from jinja2 import Environment, FileSystemLoader, StrictUndefined

    from .. import __version__

    environment = Environment(loader=FileSystemLoader(TEMPLATES), autoescape=True, undefined=StrictUndefined,
                              trim_blocks=True, lstrip_blocks=True)
    environment.filters["plural"] = plural
    meshes = [
        {"row": file_row(result), "result": result,
         "sections": [section(result) for section in MESH_SECTIONS] if result.readable else []}
        for result in run.meshes
    ]
    return environment.get_template("report.html.j2").render(
        run=run, version=__version__, summary=summary_section(run), meshes=meshes,
        closing=[section(run) for section in CLOSING_SECTIONS],
    )
