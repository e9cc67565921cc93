"""The written page is compact, and compacting changes nothing a browser reads."""

from __future__ import annotations

from html.parser import HTMLParser


class Tokens(HTMLParser):
    """Tags with their attributes, and text with its whitespace runs folded, as an HTML renderer sees them."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tokens: list = []

    def handle_starttag(self, tag, attrs):
        self.tokens.append(("start", tag, [(k, " ".join((v or "").split())) for k, v in attrs]))

    def handle_endtag(self, tag):
        self.tokens.append(("end", tag))

    def handle_data(self, data):
        folded = " ".join(data.split())
        if folded:
            self.tokens.append(("text", folded))


def tokens(html: str) -> list:
    parser = Tokens()
    parser.feed(html)
    return parser.tokens


def test_compacting_the_demo_page_keeps_every_tag_attribute_and_word():
    from affinity.report import page

    captured = {}
    real = page.compact
    page.compact = lambda html: captured.setdefault("raw", html)  # the page as the templates write it
    try:
        from tqdm import tqdm

        from affinity.report.build import collect_run
        from affinity.report.demo import demo_inputs
        from affinity.settings import Settings

        inputs = [item for item in demo_inputs() if "trapezoid" in item.path]
        page.render_page(collect_run(inputs, lambda path: Settings(), Settings(), tqdm(disable=True)))
    finally:
        page.compact = real
    raw = captured["raw"]
    written = page.compact(raw)
    assert written.startswith("<!DOCTYPE html>") and written.count("\n") < raw.count("\n") / 5
    assert tokens(written) == tokens(raw)
