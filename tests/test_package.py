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
