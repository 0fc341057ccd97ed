"""The HTML report is self-contained and well formed."""

from __future__ import annotations

import base64
from html.parser import HTMLParser

from geardyn.studies.report import Report, fmt


class _Collect(HTMLParser):
    def __init__(self):
        super().__init__()
        self.stack: list[str] = []
        self.imgs: list[dict] = []
        self.links: list[str] = []
        self.errors: list[str] = []
        self.void = {"meta", "img", "br", "hr", "link", "input"}

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.imgs.append(a)
        if tag in ("link", "script"):
            self.links.append(tag)
        if tag not in self.void:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if tag in self.void:
            return
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"unbalanced </{tag}>")
        else:
            self.stack.pop()


def test_report_embeds_figures_and_balances_tags(tmp_path):
    import matplotlib.figure

    fig = matplotlib.figure.Figure(figsize=(3, 2))
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("pinion angle [deg]")
    r = Report("t <&>", tmp_path, subtitle="s")
    r.heading("Section one")
    r.paragraph("a < b")
    r.figure(fig, "fig_a", "A caption & more")
    r.table(["q", "v"], [["x", 1.23456789], ["y", float("nan")]], caption="tab",
            classes=[["", "pass"], ["", "fail"]])
    path = r.write(footer="f")
    text = path.read_text()
    p = _Collect()
    p.feed(text)
    assert not p.errors and p.stack == []
    assert len(p.imgs) == 1
    src = p.imgs[0]["src"]
    assert src.startswith("data:image/png;base64,")
    assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    assert p.imgs[0]["alt"] == "A caption & more"
    assert not p.links  # no external stylesheet or script
    assert (tmp_path / "figures" / "fig_a.png").read_bytes()[:4] == b"\x89PNG"
    assert "t &lt;&amp;&gt;" in text and 'href="#section-one"' in text


def test_fmt():
    assert fmt(1.23456789) == "1.235"
    assert fmt(2.6e-5) == "2.600e-05"
    assert fmt(0.0) == "0"
    assert fmt(float("nan")) == "n/a"
    assert fmt(True) == "yes"
