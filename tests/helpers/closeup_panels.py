"""The close-up figures of a report page and their panels, decoded (tests of the report's static pictures)."""

from __future__ import annotations

import base64
import io
from html.parser import HTMLParser

import numpy as np


class Closeups(HTMLParser):
    """Every close-up figure's rule, face and panel sources by what they show (``split``, ``exact``, ...)."""

    def __init__(self):
        super().__init__()
        self.figures: list[dict] = []
        self._current: dict | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "figure" and "data-face" in attrs:
            self._current = {"rule": attrs["data-rule"], "face": int(attrs["data-face"]), "images": {}}
            self.figures.append(self._current)
        elif tag == "img" and self._current is not None:
            self._current["images"][attrs.get("alt", "").split(",")[0]] = attrs["src"]  # alt "split, face F"

    def handle_endtag(self, tag):
        if tag == "figure":
            self._current = None


def decode_panel(src: str) -> np.ndarray:
    """A panel's PNG data URI as (H, W, 3) int RGB."""
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(base64.b64decode(src.split(",", 1)[1]))).convert("RGB")).astype(int)
