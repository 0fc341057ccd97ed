"""What a run of the paper's case study produced, and how it reports progress.

The study (:mod:`.paper`) fills a :class:`StudyResult`; the report (:mod:`.paper_report`) reads
it. Neither this module nor the report imports the study.

Progress protocol
-----------------
``progress(stage, done, total)``: three positional arguments, unchanged from earlier versions.

* Announcements: ``(name, i, 6)`` as stage ``name`` (``"geometry"``, ``"stiffness"``,
  ``"simulation"``, ``"diagnostics"``, ``"measurement"``, ``"report"``: the names of
  ``paper.STAGES``) starts, ``i`` stages having finished; ``("done", 6, 6)`` at the end.
* Counts: ``("<bar>: <item>", done, total)`` or ``("<bar>", done, total)``, one bar per ``<bar>``
  with its own count that runs from 0 to ``total`` and is never reused for another count; the
  text after ``": "`` names the item in progress. Bars: ``"stiffness (healthy)"`` and
  ``"stiffness (cracked)"`` (the map builder's own count: FE solves or PEM grid lines; one step
  when the map comes from the cache), ``"simulation"`` (7 records: model I, I-static and II,
  cracked and healthy, and model II with the paper's start-of-step scheme), ``"diagnostics"``
  (5 records: model I and II, cracked and healthy, and model I-static cracked),
  ``"measurement"`` (10 steps: two simulations with tooth errors, then 8 measured records; 0
  then 10 when the results come from the cache) and ``"report"`` (figures, then the files). A
  count call always carries an item when its ``total`` equals the number of stages, so it
  cannot be mistaken for an announcement.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["StudyResult", "Progress", "Deferred", "FigureStore", "RenderedFigure"]

Progress = Callable[[str, int, int], None]


@dataclass
class StudyResult:
    """What a study run produced.

    Attributes
    ----------
    out : Path
        Output folder.
    summary : dict
        The content of ``summary.json``.
    stages : list of str
        Stages completed.
    seconds : dict of str -> float
        Wall time per stage [s].
    maps : dict
        ``"healthy"``, ``"cracked"``: :class:`~geardyn.stiffness.map.StiffnessMap`.
    figures : FigureStore
        Figure name -> :class:`RenderedFigure` (a matplotlib figure stored here is rendered to
        PNG and closed at once, so the run does not hold every figure until the report).
    notes : list of str
        Warnings to show in the report.
    progress : callable, optional
        See the module docstring.
    quick : bool
        Shorter records.
    sims : Mapping
        ``(model, state)`` -> simulation Dataset (:class:`~.paper.CachedRecords` after the
        simulation stage: each access reads the record from the simulation cache).
    diagnoses : dict
        ``(model, state)`` -> diagnosis result.
    crack_angle_rad : float, optional
        Pinion angle of the largest stiffness loss [rad].
    paper_case : bool
        Whether the case's inputs are the paper's (only then is it compared with the paper).
    differences : list of dict
        Physical inputs that differ from the paper's case (``key``, ``paper``, ``case``).
    files : dict of str -> Path
        Files written, by role.
    kernel_compiler : multiprocessing.Process, optional
        A second process compiling the time-step kernel (``--quick`` on a first run after an
        install), which the simulation stage waits for.
    measured_tsa : dict
        ``(variant, state)`` -> TSA of the housing acceleration [m/s^2] over one revolution
        (measurement stage, :mod:`.paper_measurement`).
    """

    out: Path
    summary: dict = field(default_factory=dict)
    stages: list[str] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)
    maps: dict = field(default_factory=dict)
    figures: dict = field(default_factory=lambda: FigureStore())
    notes: list[str] = field(default_factory=list)
    progress: Progress | None = None
    quick: bool = False
    sims: dict = field(default_factory=dict)
    kernel_compiler: object = None
    diagnoses: dict = field(default_factory=dict)
    crack_angle_rad: float | None = None
    paper_case: bool = True
    differences: list = field(default_factory=list)
    files: dict = field(default_factory=dict)
    measured_tsa: dict = field(default_factory=dict)

    def emit(self, stage: str, done: int, total: int) -> None:
        """Report progress (see the module docstring); a no-op without a callback."""
        if self.progress is not None:
            self.progress(stage, done, total)

    def sub_progress(self, stage: str) -> Callable[[int, int], None] | None:
        """A ``progress(done, total)`` callback reporting under ``stage``."""
        if self.progress is None:
            return None
        return lambda done, total: self.emit(stage, done, total)


#: Resolution of the report's figures [dots per inch] (the report's default).
FIGURE_DPI = 110


class RenderedFigure:
    """A figure already rendered to PNG bytes, with the part of the matplotlib ``Figure`` API
    the report uses (``savefig`` into a binary file object)."""

    __slots__ = ("png",)

    def __init__(self, png: bytes):
        self.png = png

    def savefig(self, fh, format: str = "png", **_ignored) -> None:  # noqa: A002 (matplotlib's name)
        """Write the PNG (rendered at :data:`FIGURE_DPI`, :func:`.report.png_bbox`) to ``fh``."""
        if format != "png":
            raise ValueError(f"a rendered figure is PNG only, not {format!r}")
        fh.write(self.png)


class _Undigestable(Exception):
    """An argument the figure cache cannot fingerprint (the figure is then drawn, not cached)."""


#: NumPy scalar types (``dtype.str`` without the byte order) fingerprinted as the Python scalar
#: they hold: float64, int64, bool, complex128 (what NetCDF gives back for a Python attribute);
#: NumPy strings and bytes too.
_PYTHON_SCALARS = ("f8", "i8", "b1", "c16")


class Deferred:
    """A figure argument known by a fingerprint and computed only if the figure is drawn.

    Passed as a positional or keyword argument of :meth:`FigureStore.cached` (not inside a
    container), which fingerprints it by ``fingerprint`` alone and calls ``compute()`` (once)
    on a cache miss. The fingerprint must identify the value: the hash of everything it
    is computed from (e.g. a diagnosis by its input signals, settings and geardyn's sources).

    Parameters
    ----------
    fingerprint : str
        Hash of the value's inputs.
    compute : callable
        ``compute() -> value``.
    """

    __slots__ = ("fingerprint", "_compute", "_value")

    def __init__(self, fingerprint: str, compute: Callable[[], object]):
        self.fingerprint = str(fingerprint)
        self._compute = compute
        self._value: tuple = ()

    def value(self):
        """The value (computed on the first call)."""
        if not self._value:
            self._value = (self._compute(),)
        return self._value[0]


def _resolve(args: tuple, kwargs: dict) -> tuple[tuple, dict]:
    """``args`` and ``kwargs`` with each :class:`Deferred` replaced by its value."""
    def one(a):
        return a.value() if isinstance(a, Deferred) else a

    return tuple(one(a) for a in args), {k: one(v) for k, v in kwargs.items()}


def _digest(obj, h) -> None:
    """Feed a canonical fingerprint of ``obj`` to the hash ``h`` (arrays by dtype, shape and
    bytes; dataclasses, mappings and sequences element by element; xarray objects by their
    variables, coordinates and attributes)."""
    import dataclasses

    import numpy as np

    if isinstance(obj, np.generic) and (obj.dtype.str[1:] in _PYTHON_SCALARS
                                        or obj.dtype.kind in "US"):
        # a NetCDF round trip turns a Python float/int attribute into np.float64/np.int64: the
        # same value, the same figure (issue 16: the first warm run redrew 6 figures for this)
        obj = obj.item()
    if isinstance(obj, Deferred):
        h.update(f"deferred:{obj.fingerprint};".encode())
    elif obj is None or isinstance(obj, (bool, int, float, complex, str, bytes)):
        h.update(f"{type(obj).__name__}:{obj!r};".encode())
    elif isinstance(obj, np.generic):
        h.update(f"{obj.dtype}:{obj.item()!r};".encode())
    elif isinstance(obj, np.ndarray):
        if obj.dtype.hasobject:
            raise _Undigestable(type(obj))
        h.update(f"nd:{obj.dtype.str}:{obj.shape};".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        h.update(f"dc:{type(obj).__module__}.{type(obj).__qualname__};".encode())
        for f in dataclasses.fields(obj):
            h.update(f.name.encode())
            _digest(getattr(obj, f.name), h)
    elif isinstance(obj, dict):
        h.update(f"dict:{len(obj)};".encode())
        for k in sorted(obj, key=repr):
            _digest(k, h)
            _digest(obj[k], h)
    elif isinstance(obj, (list, tuple)):
        h.update(f"{type(obj).__name__}:{len(obj)};".encode())
        for x in obj:
            _digest(x, h)
    elif hasattr(obj, "model_dump") and hasattr(type(obj), "model_fields"):  # pydantic (Case)
        h.update(f"pyd:{type(obj).__module__}.{type(obj).__qualname__};".encode())
        _digest(obj.model_dump(mode="json"), h)
    elif hasattr(obj, "variables") and hasattr(obj, "attrs"):  # xarray.Dataset
        h.update(b"xr-dataset;")
        for name in sorted(obj.variables):
            v = obj.variables[name]
            _digest((name, v.dims, dict(v.attrs)), h)
            _digest(np.asarray(v.values), h)
        _digest(dict(obj.attrs), h)
    else:
        raise _Undigestable(type(obj))


def _source_digest() -> str:
    """Hash of geardyn's Python sources and the plotting library's version: any change of the
    code or of matplotlib invalidates every cached figure."""
    global _SOURCE_DIGEST
    if _SOURCE_DIGEST is None:
        import hashlib
        from importlib import metadata

        # the installed version, read without importing matplotlib (0.25 s; issue 16)
        h = hashlib.sha256(f"matplotlib {metadata.version('matplotlib')}; dpi {FIGURE_DPI};"
                           .encode())
        root = Path(__file__).resolve().parents[1]
        for path in sorted(root.rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
        _SOURCE_DIGEST = h.hexdigest()
    return _SOURCE_DIGEST


_SOURCE_DIGEST: str | None = None


class FigureStore(dict):
    """Figure name -> :class:`RenderedFigure`: a matplotlib figure assigned is rendered to PNG
    (:data:`FIGURE_DPI`, bounding box by :func:`.report.png_bbox`, as the report embeds it) and
    closed, which keeps a run's memory from growing with every figure (measured: the diagnostics
    and report stages of ``geardyn run --quick`` held about 560 MB of figures and their data)."""

    def __setitem__(self, key, fig) -> None:
        if not isinstance(fig, RenderedFigure) and hasattr(fig, "savefig"):
            import io

            import matplotlib.pyplot as plt

            from .report import png_bbox

            buf = io.BytesIO()
            fig.savefig(buf, format="png", dpi=FIGURE_DPI, bbox_inches=png_bbox(fig))
            plt.close(fig)
            fig = RenderedFigure(buf.getvalue())
        super().__setitem__(key, fig)

    def cached(self, key, draw: Callable, *args, **kwargs) -> None:
        """``self[key] = draw(*args, **kwargs)``, through the disk cache (kind ``figure``): the
        PNG is keyed by a fingerprint of the arguments (:func:`_digest`), ``draw``'s name and
        geardyn's sources, so a run whose inputs did not change takes its figures from the
        cache instead of drawing them again (issue 16.6). A :class:`Deferred` argument counts
        by its fingerprint and is computed only when the figure is drawn. Arguments it cannot
        fingerprint, or ``GEARDYN_NO_CACHE``, draw the figure as before."""
        import hashlib

        from ..cache import default_cache

        h = hashlib.sha256(f"{key};{draw.__module__}.{draw.__qualname__};".encode())
        try:
            _digest(args, h)
            _digest(kwargs, h)
        except _Undigestable:
            args, kwargs = _resolve(args, kwargs)
            self[key] = draw(*args, **kwargs)
            return
        h.update(_source_digest().encode())

        def build() -> bytes:
            a, kw = _resolve(args, kwargs)
            self[key] = draw(*a, **kw)
            return dict.__getitem__(self, key).png

        png, _ = default_cache().get_or_build("figure", h.hexdigest(), ".png", build,
                                              lambda data, path: Path(path).write_bytes(data),
                                              lambda path: Path(path).read_bytes())
        super().__setitem__(key, RenderedFigure(png))
