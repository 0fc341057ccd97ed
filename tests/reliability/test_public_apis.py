"""geardyn uses only the public APIs of zarr, xarray, dask and distributed (issue 17.3).

The test reads every module of src/geardyn with :mod:`ast` (imports in any form, and dotted
attribute chains such as ``zarr.core.sync.sync`` reached without an import) and fails on a
private module: ``zarr.core`` (internal in zarr-python 3), ``xarray.core`` (internal), and any
module or attribute path component starting with an underscore under these packages.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src" / "geardyn"
PACKAGES = ("zarr", "xarray", "dask", "distributed")
PRIVATE_PREFIXES = ("zarr.core", "xarray.core")


def private(dotted: str) -> bool:
    parts = dotted.split(".")
    if parts[0] not in PACKAGES:
        return False
    if any(dotted == p or dotted.startswith(p + ".") for p in PRIVATE_PREFIXES):
        return True
    return any(part.startswith("_") and not part.startswith("__") for part in parts[1:])


def _dotted(node: ast.AST) -> str | None:
    names = []
    while isinstance(node, ast.Attribute):
        names.append(node.attr)
        node = node.value
    if isinstance(node, ast.Name):
        return ".".join([node.id, *reversed(names)])
    return None


def private_uses(source: str) -> list[str]:
    """The private module paths a Python source uses (imports and attribute chains)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if private(a.name)]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found += [f"{node.module}.{a.name}" for a in node.names
                      if private(f"{node.module}.{a.name}")]
        elif isinstance(node, ast.Attribute):
            d = _dotted(node)
            if d and private(d):
                found.append(d)
    return found


@pytest.mark.parametrize(("source", "bad"), [
    ("from zarr.core.sync import sync", True),
    ("import zarr.core.sync", True),
    ("import zarr\nzarr.core.sync.sync(x)", True),
    ("from xarray.core.dataset import Dataset", True),
    ("from dask.array._shuffle import x", True),
    ("import zarr\nzarr.open_group('a')", False),
    ("import dask.array as da\nda.full(3, 1)", False),
    ("from distributed import Client", False),
])
def test_the_detector_itself(source, bad):
    assert bool(private_uses(source)) is bad


def test_no_private_zarr_xarray_or_dask_module_in_src():
    files = sorted(SRC.rglob("*.py"))
    assert len(files) > 30
    offences = {str(f.relative_to(SRC)): uses for f in files
                if (uses := private_uses(f.read_text(encoding="utf-8")))}
    assert offences == {}, offences
