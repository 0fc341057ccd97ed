"""The top-level package: its public names, imported on first use (PEP 562)."""

from __future__ import annotations

import subprocess
import sys

import pytest

import geardyn
from geardyn.config import Case, load_case, paper_case
from geardyn.errors import GeardynError, InputError
from geardyn.geometry import GearPair, centre_distance_from_displacements


def test_every_public_name_is_the_object_its_module_defines():
    for name in geardyn.__all__:
        assert getattr(geardyn, name) is not None, name
        assert name in dir(geardyn)
    assert geardyn.Case is Case and geardyn.load_case is load_case
    assert geardyn.paper_case is paper_case and geardyn.GearPair is GearPair
    assert geardyn.centre_distance_from_displacements is centre_distance_from_displacements
    assert geardyn.InputError is InputError and issubclass(geardyn.InputError, GeardynError)
    # the entry points a scripter starts from (help(geardyn) lists them; a user audit of
    # 2026-11-27 found none of them at the top level)
    from geardyn.diagnostics import diagnose, diagnose_file
    from geardyn.dynamics import simulate
    from geardyn.static_te import static_te_of_case
    from geardyn.stiffness import build_map
    from geardyn.studies.measure import measure
    from geardyn.studies.paper import run_paper_study

    for fn in (build_map, simulate, diagnose, diagnose_file, measure, static_te_of_case,
               run_paper_study):
        assert getattr(geardyn, fn.__name__) is fn
        assert f"geardyn.{fn.__name__}" in geardyn.__doc__, fn.__name__
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        geardyn.nope  # noqa: B018


def test_importing_the_package_loads_no_case_models():
    """``import geardyn`` alone imports neither pydantic nor NumPy (a process that needs one
    part, such as the report's figure process or ``geardyn --version``, pays for that part);
    the first use of a name imports its module, and ``from geardyn import *`` gives them
    all."""
    code = ("import sys\n"
            "import geardyn\n"
            "print(sorted(m for m in ('pydantic', 'numpy', 'geardyn.config') if m in sys.modules))\n"
            "geardyn.Case\n"
            "print('geardyn.config' in sys.modules)\n"
            "from geardyn import *\n"
            "print(Case.__name__, GearPair.__name__, DataFileError.__name__)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["[]", "True", "Case GearPair DataFileError"]
