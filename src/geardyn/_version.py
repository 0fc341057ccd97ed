"""geardyn's version and run provenance: the ground floor every module may import.

Inner modules take ``__version__`` from here, never from the package face
(``geardyn/__init__.py``), so that importing one module does not import the whole public API
and no module sits in an import circle with the face.

This module imports only the standard library.
"""

from __future__ import annotations

import platform
from importlib import metadata

__all__ = ["__version__", "package_versions", "PROVENANCE_PACKAGES"]

#: geardyn's version (keep equal to ``[project] version`` in pyproject.toml; a test checks it).
__version__ = "0.1.0"

#: The packages whose versions a result records (those that can change a number or a file).
PROVENANCE_PACKAGES = ("numpy", "scipy", "numba", "xarray", "netCDF4", "h5netcdf", "h5py",
                       "matplotlib", "pydantic", "scikit-fem", "gmsh")


def package_versions(packages: tuple[str, ...] = PROVENANCE_PACKAGES) -> list[tuple[str, str]]:
    """Versions of Python, the platform, geardyn and ``packages``, for a result's provenance.

    Parameters
    ----------
    packages : tuple of str
        Distribution names; a missing one is listed as ``"not installed"``.

    Returns
    -------
    list of (str, str)
        ``(name, version)`` pairs, starting with ``python``, ``platform`` and ``geardyn``.
    """
    out = [("python", platform.python_version()), ("platform", platform.platform()),
           ("geardyn", __version__)]
    for pkg in packages:
        try:
            out.append((pkg, metadata.version(pkg)))
        except metadata.PackageNotFoundError:
            out.append((pkg, "not installed"))
    return out
