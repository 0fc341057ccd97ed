"""The files of ``geardyn stiffness``: its maps (NetCDF) and figures (PNG), through the output
cache.

:func:`write_stiffness_outputs` writes them; :func:`fe_mesh_png_task` draws the FE mesh figure
into the cache from the second process that has just meshed the faulty body
(:mod:`geardyn.stiffness.fe.background`), so the first process copies it instead of meshing the
body again. This module imports nothing heavy: the second process unpickles a reference to it
before it builds its bodies.
"""

from __future__ import annotations

import contextlib
import tempfile
from pathlib import Path

__all__ = ["FIGURE_DPI", "write_stiffness_outputs", "fe_mesh_png_task", "healthy_figures_ahead"]

#: PNG resolution of the figures ``geardyn stiffness`` writes [dots per inch].
FIGURE_DPI = 150


def write_stiffness_outputs(out: Path, case, maps: dict, method: str,
                            has_crack: bool) -> list[str]:
    """The maps (NetCDF) and the figures (PNG) of ``geardyn stiffness`` into ``out``.

    Each file goes through the output cache (:func:`.paper_cache.write_output`): a map under
    the same key as ``geardyn run`` writes it, a figure keyed by what it draws (the maps; for
    ``fe_mesh.png`` the case and whether it is cracked), the matplotlib version and the
    resolution. A run whose maps came from the cache then copies the files an earlier run
    wrote instead of encoding the maps, meshing the body again for the mesh figure and drawing
    the figures: 8.2 s -> 2.5-2.7 s for the paper's FE maps (2026-11-28, see the README's
    performance section).

    Parameters
    ----------
    out : Path
        The output folder.
    case : geardyn.config.Case
    maps : dict of str to StiffnessMap
        ``"healthy"``, and ``"cracked"`` or ``"faulty"`` where the case has them.
    method : str
        ``"pem"`` or ``"fe"`` (``"fe"`` adds ``fe_mesh.png``).
    has_crack : bool
        Whether the case's crack is enabled (the mesh figure shows it).

    Returns
    -------
    list of str
        The names of the files written, in order.
    """
    from .paper_cache import write_output

    written = []
    for name, m in maps.items():  # the same key as geardyn run's copies of the maps
        write_output(out / f"stiffness_{name}.nc", "stiffness map", m, "StiffnessMap.to_netcdf",
                     m.to_netcdf)
        written.append(f"stiffness_{name}.nc")

    healthy = maps["healthy"]
    for name, draw in _healthy_figures(healthy):
        _figure(out / name, healthy, draw)
        written.append(name)
    if "cracked" in maps:
        _figure(out / "fig6_crack.png", (healthy, maps["cracked"]),
                lambda: _plots().fig_crack(healthy, maps["cracked"]))
        written.append("fig6_crack.png")
    if "faulty" in maps:
        def faults():
            from ..faults.figures import fig_faults

            return fig_faults(healthy, maps["faulty"])

        _figure(out / "fig_faults.png", (healthy, maps["faulty"]), faults)
        written.append("fig_faults.png")
    if method == "fe":
        _fe_mesh_png(out / "fe_mesh.png", case, has_crack)
        written.append("fe_mesh.png")
    return written


def _plots():
    """:mod:`geardyn.stiffness.plots`, imported where a figure is drawn (matplotlib)."""
    from ..stiffness import plots

    return plots


def _healthy_figures(healthy) -> list[tuple[str, object]]:
    """``(file name, draw)`` of the figures drawn from the healthy map alone (Fig. 5)."""
    return [("fig5_stiffness.png", lambda: _plots().fig_stiffness(healthy)),
            ("fig5_load_sharing.png", lambda: _plots().fig_load_sharing(healthy))]


def healthy_figures_ahead(healthy) -> None:
    """The figures of the healthy map alone drawn into the output cache now, for
    :func:`write_stiffness_outputs` to copy later.

    For ``geardyn stiffness --method fe`` while its second process still builds the faulty
    body that the faulty map waits for: matplotlib is imported and Fig. 5 drawn during that
    wait instead of after it, when they were 1-1.5 s of the command's end (py-spy of a cold
    run, 2026-11-28). The cache entries are the ones :func:`write_stiffness_outputs` looks up
    (same key: the map, the file's name, the resolution, matplotlib's version); the command's
    cache line counts each once. Nothing is drawn without the cache (it would be drawn twice).
    """
    from ..cache import default_cache

    if not default_cache().enabled:
        return
    with tempfile.TemporaryDirectory(prefix="geardyn-figures-") as tmp:
        for name, draw in _healthy_figures(healthy):
            _figure(Path(tmp) / name, healthy, draw)


def _figure(target: Path, data, draw) -> None:
    """``draw()`` saved as ``target`` (PNG, :data:`FIGURE_DPI`) through the output cache,
    keyed by ``data``, the file's name, the resolution and the matplotlib version."""
    from importlib.metadata import version

    from .paper_cache import write_output

    def write(path: Path) -> None:
        draw().savefig(path, dpi=FIGURE_DPI, format="png")

    write_output(target, f"geardyn stiffness figure {target.name}", data,
                 {"dpi": FIGURE_DPI, "format": "png", "matplotlib": version("matplotlib")},
                 write)


def _fe_mesh_png(target: Path, case, has_crack: bool) -> None:
    from ..config import case_to_toml

    def mesh():
        from ..stiffness.fe import plot_mesh

        return plot_mesh(case, cracked=has_crack)

    _figure(target, (case_to_toml(case), has_crack), mesh)


def fe_mesh_png_task(case, has_crack: bool) -> None:
    """``fe_mesh.png`` of ``geardyn stiffness`` into the output cache, for the second process
    to call right after it has built the faulty bodies (a ``then`` task of
    :func:`geardyn.stiffness.fe.background.faulty_bodies_in_background`): it holds the cracked
    body's mesh, so it draws the figure without meshing again (about 1.5 s of gmsh on the
    paper's pinion), while the first process evaluates the maps; the first then copies it.

    A failure here is left to the first process, which draws the figure itself and meets (and
    reports) the same error.
    """
    with contextlib.suppress(Exception), tempfile.TemporaryDirectory() as tmp:
        _fe_mesh_png(Path(tmp) / "fe_mesh.png", case, has_crack)
