"""Optional dependencies, installed with pip extras, and the error that names the extra.

``pip install geardyn`` gives everything the README's main command (``geardyn run``), the
single simulations, stiffness maps and diagnostics need. Heavy parts that only some users want
are extras:

========  ==========================  ==========================================================
extra     packages                    used by
========  ==========================  ==========================================================
sweep     dask[distributed], zarr     parameter sweeps (``geardyn sweep``,
                                      :mod:`geardyn.studies.sweep`): Dask scheduling, Zarr store
========  ==========================  ==========================================================

The ``test`` extra includes them, so the test suite covers the sweeps.
"""

from __future__ import annotations

import importlib.util

from .errors import GeardynError

__all__ = ["EXTRAS", "MissingExtraError", "missing_modules", "require_extra"]

#: extra name -> (importable modules it provides, what needs them)
EXTRAS: dict[str, tuple[tuple[str, ...], str]] = {
    "sweep": (("dask", "distributed", "zarr"), "parameter sweeps (Dask scheduling, Zarr store)"),
}


class MissingExtraError(GeardynError, ImportError):
    """An optional part of geardyn is used without the pip extra that installs it."""


def missing_modules(extra: str) -> list[str]:
    """Modules of ``extra`` that cannot be imported here (empty when it is installed)."""
    modules, _ = EXTRAS[extra]
    return [m for m in modules if importlib.util.find_spec(m) is None]


def require_extra(extra: str) -> None:
    """Raise :class:`MissingExtraError` naming the extra when any of its modules is missing.

    Parameters
    ----------
    extra : str
        A key of :data:`EXTRAS`, e.g. ``"sweep"``.
    """
    missing = missing_modules(extra)
    if missing:
        _, what = EXTRAS[extra]
        raise MissingExtraError(
            f"{what} need the optional package(s) {', '.join(missing)}: install them with "
            f"pip install 'geardyn[{extra}]'"
        )
