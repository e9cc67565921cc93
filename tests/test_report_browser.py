"""The demo report in a real headless Chromium: loads cleanly, fetches nothing, every picture decodes.

Chromium is driven over its DevTools pipe (``helpers.chromium``). Skips only when no
Chromium is installed (``.ci/run`` installs Debian's).
"""

from __future__ import annotations

import base64
import io
import json

import numpy as np
import pytest
from helpers.chromium import CHROMIUM, DevTools
from helpers.cli import run
from helpers.corpus import SHARED_MESHES

pytestmark = [pytest.mark.skipif(CHROMIUM is None, reason="no chromium installed"),
              pytest.mark.slow]  # a browser opens the report
VIEWPORT = (1200, 2000)


@pytest.fixture(scope="module")
def loaded_report(tmp_path_factory):
    """The demo report opened in Chromium: (devtools, page session, report path)."""
    folder = tmp_path_factory.mktemp("browser")
    report = folder / "report.html"
    built = run("report", "-q", "-o", str(report))
    assert built.returncode == 0, built.stderr
    browser = DevTools(folder / "profile")
    try:
        target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = browser.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            browser.call(f"{domain}.enable", session=session)
        width, height = VIEWPORT
        browser.call("Emulation.setDeviceMetricsOverride",
                     {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False}, session=session)
        browser.call("Page.navigate", {"url": report.as_uri()}, session=session)
        browser.wait_for("Page.loadEventFired")
        yield browser, session, report
    finally:
        browser.close()


def test_report_loads_without_console_errors(loaded_report):
    browser, session, _ = loaded_report
    browser.call("Runtime.evaluate", {"expression": "document.readyState"}, session=session)  # drain pending events
    errors = [e for e in browser.events if e.get("method") in ("Runtime.exceptionThrown",)
              or (e.get("method") == "Runtime.consoleAPICalled" and e["params"]["type"] in ("error", "assert"))
              or (e.get("method") == "Log.entryAdded" and e["params"]["entry"]["level"] == "error")]
    assert errors == []


def test_report_makes_no_network_request(loaded_report):
    browser, _, report = loaded_report
    requested = [event["params"]["request"]["url"] for event in browser.events
                 if event.get("method") == "Network.requestWillBeSent"]
    assert report.as_uri() in requested  # the page itself: the listener was on
    assert [url[:60] for url in requested if not url.startswith(("file:", "data:"))] == []


def test_every_image_decodes(loaded_report):
    browser, session, _ = loaded_report
    script = """Promise.all(Array.from(document.images).map(
        img => img.decode().then(() => img.naturalWidth, () => 0)))"""
    widths = browser.call("Runtime.evaluate", {"expression": script, "awaitPromise": True, "returnByValue": True},
                          session=session)["result"]["value"]
    assert len(widths) > 10  # renders, crops, overlays, charts of three scenes
    assert min(widths) > 0


def test_screenshot_is_not_blank(loaded_report):
    from PIL import Image

    browser, session, _ = loaded_report
    shot = browser.call("Page.captureScreenshot", {"format": "png"}, session=session)["data"]
    image = Image.open(io.BytesIO(base64.b64decode(shot))).convert("RGB")
    assert image.size == VIEWPORT
    pixels = np.asarray(image).reshape(-1, 3)
    assert pixels.std() > 20  # text, tables and pictures, not one flat colour
    colours = np.unique(pixels.astype(np.int64) @ np.array([1 << 16, 1 << 8, 1]))
    assert len(colours) > 200  # the checker renders and anti-aliased text


MAKEHUMAN = SHARED_MESHES / "makehuman_base_hm08.obj"

#: Every SVG text's rendered height in CSS pixels: its getBBox() height times the screen scale of its element.
TEXT_HEIGHTS = """Array.from(document.querySelectorAll("svg text")).filter(t => t.textContent.trim()).map(t => {
    const box = t.getBBox(), m = t.getScreenCTM();
    return [box.height * Math.hypot(m.b, m.d), t.textContent.trim().slice(0, 30)];
})"""
FIGURES = """Array.from(document.querySelectorAll("figure[data-face]")).map(f => ({
    face: Number(f.dataset.face), rule: f.dataset.rule, src: f.querySelector("img").src}))"""


def _evaluate(browser, session, expression):
    return browser.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True},
                        session=session)["result"]["value"]


def _set_width(browser, session, width):
    browser.call("Emulation.setDeviceMetricsOverride",
                 {"width": width, "height": 1000, "deviceScaleFactor": 1, "mobile": False}, session=session)
    _evaluate(browser, session, "new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")


@pytest.fixture(scope="module")
def makehuman_report(tmp_path_factory):
    """The report on MakeHuman opened in Chromium at 1280 px: (devtools, session, lint JSON)."""
    if not MAKEHUMAN.is_file():
        pytest.skip("../shared/meshes is absent")
    folder = tmp_path_factory.mktemp("makehuman")
    report = folder / "report.html"
    built = run("report", "-q", str(MAKEHUMAN), "-o", str(report))
    assert built.returncode == 0, built.stderr
    lint = run("check", "--format", "json", str(MAKEHUMAN))
    findings = json.loads(lint.stdout)["findings"]
    browser = DevTools(folder / "profile")
    try:
        target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = browser.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        browser.call("Page.enable", session=session)
        _set_width(browser, session, 1280)
        browser.call("Page.navigate", {"url": report.as_uri()}, session=session)
        browser.wait_for("Page.loadEventFired", timeout=60)
        yield browser, session, findings
    finally:
        browser.close()


def test_makehuman_closeups_name_flagged_faces_and_outline_them(makehuman_report):
    from PIL import Image

    from affinity.draw.shading import FLAG_COLOUR

    browser, session, findings = makehuman_report
    figures = _evaluate(browser, session, FIGURES)
    flagged = {(f["code"], f["face"]) for f in findings}
    assert len(figures) >= 5
    assert len({(f["rule"], f["face"]) for f in figures}) == len(figures)  # one figure per place
    assert {f["rule"] for f in figures} == {f["code"] for f in findings}  # every flagged rule gets a view
    flag = [int(FLAG_COLOUR[i:i + 2], 16) for i in (1, 3, 5)]
    for figure in figures:
        assert (figure["rule"], figure["face"]) in flagged
        png = base64.b64decode(figure["src"].split(",", 1)[1])
        pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).reshape(-1, 3)
        assert (pixels == flag).all(axis=1).sum() >= 20, figure  # the place's outline


def test_makehuman_has_a_uv_layout(makehuman_report):
    browser, session, _ = makehuman_report
    layout = _evaluate(browser, session, """Array.from(document.querySelectorAll('figure[data-view="uv-layout"]'))
        .map(f => [f.querySelector("svg image").getBoundingClientRect().width, """
                       """Array.from(f.querySelectorAll("svg text")).map(t => {const r = t.getBoundingClientRect();
                          return [t.textContent, r.left, r.top, r.right, r.bottom];})])""")
    assert len(layout) == 1
    width, labels = layout[0]
    assert width >= 400 and sum(text.count("face ") for text, *_ in labels) >= 5
    for k, (_, left, top, right, bottom) in enumerate(labels):  # as laid out by the browser's own font
        for text, *other in labels[k + 1:]:
            assert not (left < other[2] and other[0] < right and top < other[3] and other[1] < bottom), text


@pytest.mark.parametrize("width", [1280, 800])
def test_makehuman_fits_the_width_and_chart_text_is_legible(makehuman_report, width):
    browser, session, _ = makehuman_report
    _set_width(browser, session, width)
    try:
        scroll, client = _evaluate(browser, session,
                                   "[document.documentElement.scrollWidth, document.documentElement.clientWidth]")
        heights = _evaluate(browser, session, TEXT_HEIGHTS)
    finally:
        _set_width(browser, session, 1280)
    if width == 1280:
        assert scroll <= client  # no horizontal scroll
    assert len(heights) > 20  # histogram, colour bars, UV labels
    small = [(round(h, 1), text) for h, text in heights if h < 11]
    assert small == []
