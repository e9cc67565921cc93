"""Render the collected run into one self-contained HTML page (Jinja2, autoescaped)."""

from __future__ import annotations

import re
import time
from pathlib import Path

from .build import ReportRun
from .scene3d import VIEW_SCRIPTS, view_scripts
from .sections import CLOSING_SECTIONS, MESH_SECTIONS, PAGE_TIME, RUN_TIME, file_row, summary_section

TEMPLATES = Path(__file__).parent / "templates"
#: A line break and the indentation around it: one space to HTML (the page has no ``<pre>``, its script no
#: ``//`` comment and every statement ends with ``;``).
LINE_BREAK = re.compile(r"[ \t]*\n\s*")


def compact(html: str) -> str:
    """The page with its line breaks folded into spaces, one line per ``<section>``: the same document to a
    browser, a few lines to a reader of the committed reports (pages of one template differ in a few values)."""
    return LINE_BREAK.sub(" ", html).replace("<section", "\n<section").strip() + "\n"


def plural(count: int, noun: str) -> str:
    """``"1 quad"``, ``"3 quads"`` (the templates' ``plural`` filter)."""
    return f"{count} {noun}" + ("" if count == 1 else "s")


def render_page(run: ReportRun) -> str:
    """The report as HTML text.

    Autoescaping is on for every template: file names, group names and error
    messages come from the user's files and must show as text, never as markup.
    The run time printed is from ``run.start`` (the command's start) to the page
    rendered: all of the command but writing the file.
    """
    from jinja2 import Environment, FileSystemLoader, StrictUndefined

    from .. import __version__

    begun = time.perf_counter()
    environment = Environment(loader=FileSystemLoader(TEMPLATES), autoescape=True, undefined=StrictUndefined,
                              trim_blocks=True, lstrip_blocks=True)
    environment.filters["plural"] = plural
    meshes = [
        {"row": file_row(result, run.fail_on), "result": result,
         "sections": [section(result) for section in MESH_SECTIONS] if result.readable else []}
        for result in run.meshes
    ]
    html = compact(environment.get_template("report.html.j2").render(
        run=run, version=__version__, summary=summary_section(run), meshes=meshes,
        closing=[section(run) for section in CLOSING_SECTIONS], run_time=RUN_TIME, view_scripts=VIEW_SCRIPTS,
    ))
    html = html.replace(VIEW_SCRIPTS, view_scripts(), 1) if VIEW_SCRIPTS in html else html
    # Both stand-ins come before any text from the user's files (the header and the summary's facts).
    finished = time.perf_counter()
    html = html.replace(PAGE_TIME, f"{finished - begun:.1f} s", 1)
    return html.replace(RUN_TIME, f"{finished - run.start:.1f} s", 2)
