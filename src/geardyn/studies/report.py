"""A self-contained HTML report: figures embedded as PNG data URIs, tables, notes.

The report is one file that opens in any browser with no network access (no scripts, no external
stylesheets or fonts). Each figure is also written as a PNG into ``figures/`` beside it.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..io import write_bytes_atomic, write_text_atomic

__all__ = ["Report", "fmt"]

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 0;
       color: #1d2330; background: #fbfbfd; line-height: 1.45; }
main { max-width: 1180px; margin: 0 auto; padding: 1.5rem 2rem 4rem; }
h1 { font-size: 1.7rem; margin-bottom: .2rem; }
h2 { font-size: 1.3rem; margin-top: 2.4rem; border-bottom: 2px solid #d8dce6; padding-bottom: .2rem; }
h3 { font-size: 1.05rem; margin-top: 1.6rem; }
p.lead { color: #4a5263; margin-top: 0; }
nav ol { columns: 2; font-size: .92rem; }
figure { margin: 1.2rem 0; background: #fff; border: 1px solid #e3e6ee; border-radius: 6px;
         padding: .6rem; }
figure img { max-width: 100%; height: auto; display: block; margin: 0 auto; }
figcaption { font-size: .9rem; color: #3c4454; margin-top: .4rem; }
table { border-collapse: collapse; margin: .8rem 0 1.2rem; font-size: .9rem; background: #fff; }
th, td { border: 1px solid #d8dce6; padding: .3rem .55rem; text-align: right; }
th { background: #eef1f7; }
td.l, th.l { text-align: left; }
caption { caption-side: top; text-align: left; font-weight: 600; padding-bottom: .3rem; }
.pass { color: #16794c; font-weight: 600; }
.fail { color: #b42318; font-weight: 600; }
.assume { color: #8a5a00; }
.note { background: #fff8e6; border-left: 4px solid #f0b429; padding: .5rem .8rem; margin: 1rem 0; }
code { background: #eef1f7; padding: 0 .25rem; border-radius: 3px; }
footer { color: #6b7385; font-size: .85rem; margin-top: 3rem; }
"""


def fmt(v: object, digits: int = 4) -> str:
    """Format a number for a table: ``digits`` significant digits, plain text otherwise."""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v != v:  # NaN
            return "n/a"
        if v == 0:
            return "0"
        a = abs(v)
        if 1e-3 <= a < 1e5:
            text = f"{v:.{digits}g}"
        else:
            text = f"{v:.{max(digits - 1, 1)}e}"
        return text
    return str(v)


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:60] or "section"


def png_bbox(fig) -> str:
    """``bbox_inches`` for saving ``fig``: ``"tight"``, for every figure.

    A constrained-layout figure fits its axes, labels and the height of its titles to the
    canvas, but not a title wider than its axes: saved as it is, the report's Fig. 16 analogue
    lost the end of its right-hand title ("kurtosis 15.07" cut at the canvas edge; seen
    2026-11-26 in a spall case's report). The tight box draws the figure a second time to
    measure it (10-20 % of its saving time, 22 figures of ``geardyn run --quick``: 6.9 s tight,
    5.9 s without, measured 2026-11-26, most of it now in the figure process) and keeps
    everything drawn."""
    return "tight"


@dataclass
class Report:
    """An HTML report being assembled.

    Parameters
    ----------
    title : str
    out : Path
        Folder the report and ``figures/`` go into.
    subtitle : str
        One line under the title.
    """

    title: str
    out: Path
    subtitle: str = ""
    _body: list[str] = field(default_factory=list)
    _toc: list[tuple[str, str]] = field(default_factory=list)
    _n_fig: int = 0
    figures: list[Path] = field(default_factory=list)

    def heading(self, text: str, level: int = 2) -> None:
        """Add a section heading (level 2 headings go into the table of contents)."""
        anchor = _slug(text)
        if level == 2:
            self._toc.append((anchor, text))
        self._body.append(f'<h{level} id="{anchor}">{html.escape(text)}</h{level}>')

    def paragraph(self, text: str, *, raw: bool = False, css: str = "") -> None:
        """Add a paragraph (escaped unless ``raw``)."""
        body = text if raw else html.escape(text)
        cls = f' class="{css}"' if css else ""
        self._body.append(f"<p{cls}>{body}</p>")

    def note(self, text: str) -> None:
        """Add a highlighted note (e.g. where geardyn disagrees with the paper, and why)."""
        self._body.append(f'<div class="note">{html.escape(text)}</div>')

    def bullets(self, items: Iterable[str]) -> None:
        """Add a bulleted list."""
        self._body.append("<ul>" + "".join(f"<li>{html.escape(i)}</li>" for i in items) + "</ul>")

    def figure(self, fig, name: str, caption: str, *, dpi: int = 110) -> Path:
        """Embed a matplotlib figure and write it to ``figures/<name>.png``.

        Parameters
        ----------
        fig : matplotlib.figure.Figure
        name : str
            File stem of the PNG.
        caption : str
            Caption shown under the figure (also its alt text).

        Returns
        -------
        Path
            The PNG written.
        """
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches=png_bbox(fig))
        data = buf.getvalue()
        path = self.out / "figures" / f"{name}.png"
        write_bytes_atomic(path, data)
        self.figures.append(path)
        self._n_fig += 1
        b64 = base64.b64encode(data).decode("ascii")
        cap = html.escape(caption)
        self._body.append(
            f'<figure id="fig-{_slug(name)}"><img src="data:image/png;base64,{b64}" '
            f'alt="{cap}"><figcaption><b>Figure {self._n_fig}.</b> {cap}</figcaption></figure>')
        return path

    def table(self, header: Sequence[str], rows: Iterable[Sequence[object]], caption: str = "",
              *, left_columns: int = 1, classes: Sequence[Sequence[str]] | None = None,
              left: Sequence[int] = ()) -> None:
        """Add a table; numbers are formatted with :func:`fmt`.

        The first ``left_columns`` columns and those in ``left`` are left-aligned (text);
        ``classes[i][j]`` is an optional CSS class of cell ``(i, j)`` (e.g. ``"pass"``).
        """
        lefts = set(range(left_columns)) | set(left)
        parts = ["<table>"]
        if caption:
            parts.append(f"<caption>{html.escape(caption)}</caption>")
        parts.append("<tr>" + "".join(
            f'<th class="{"l" if j in lefts else ""}">{html.escape(str(h))}</th>'
            for j, h in enumerate(header)) + "</tr>")
        for i, row in enumerate(rows):
            cells = []
            for j, v in enumerate(row):
                cls = ["l"] if j in lefts else []
                if classes is not None and i < len(classes) and j < len(classes[i]) \
                        and classes[i][j]:
                    cls.append(classes[i][j])
                attr = f' class="{" ".join(cls)}"' if cls else ""
                cells.append(f"<td{attr}>{html.escape(fmt(v))}</td>")
            parts.append("<tr>" + "".join(cells) + "</tr>")
        parts.append("</table>")
        self._body.append("".join(parts))

    def html(self, footer: str = "") -> str:
        """The complete HTML document."""
        toc = "".join(f'<li><a href="#{a}">{html.escape(t)}</a></li>' for a, t in self._toc)
        stamp = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
        return (
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>{html.escape(self.title)}</title><style>{_CSS}</style></head><body><main>"
            f"<h1>{html.escape(self.title)}</h1>"
            f"<p class=\"lead\">{html.escape(self.subtitle)}</p>"
            f"<nav><h2 id=\"contents\">Contents</h2><ol>{toc}</ol></nav>"
            + "\n".join(self._body)
            + f"<footer>{html.escape(footer)} Generated {stamp}.</footer></main></body></html>\n"
        )

    def write(self, name: str = "report.html", footer: str = "") -> Path:
        """Write the report atomically; returns its path."""
        path = self.out / name
        write_text_atomic(path, self.html(footer))
        return path
