"""After a gmsh mesh, a write to a closed pipe is still a Python ``BrokenPipeError``, not a
silent death of the process by ``SIGPIPE`` (gmsh's initialisation resets the signal to its
default action; :func:`geardyn.stiffness.fe.mesh._initialize_gmsh` puts Python's back). Each
case runs in a process of its own: the failure would kill the process it happens in."""

from __future__ import annotations

import signal
import subprocess
import sys

import pytest

SCRIPT = r"""
import os, sys, threading
import geardyn
from geardyn.stiffness.fe.crack_mesh import edge_crack_strip
from geardyn.stiffness.fe.mesh import CrackGeometry, MeshSettings, build_body_mesh
from geardyn.stiffness.fe.substructure import build_part_mesh

gear = geardyn.paper_case().gear_pair().pinion
coarse = MeshSettings(flank_size=0.2e-3, tooth_size=1.5e-3, body_size=4e-3, refined_teeth=1)

def mesh():
    {call}

if sys.argv[1] == "thread":
    t = threading.Thread(target=mesh)
    t.start()
    t.join()
else:
    mesh()
r, w = os.pipe()
os.close(r)
try:
    os.write(w, b"x")
except BrokenPipeError:
    print("BrokenPipeError")
"""

#: the three places geardyn meshes with gmsh: a body, a cracked strip (the SIF checks' and
#: the crack growth's meshes), a part of a substructured body
CASES = {
    "body mesh": "build_body_mesh(gear, coarse, CrackGeometry(depth=2e-3, angle=0.78))",
    "cracked polygon": "edge_crack_strip(0.01, 2e-3, tip_size=1e-4, size=2e-3)",
    "substructure part": "build_part_mesh(gear, coarse, 'H')",
}


@pytest.mark.skipif(not hasattr(signal, "SIGPIPE"), reason="no SIGPIPE on this platform")
@pytest.mark.parametrize("where", ["main", "thread"])
@pytest.mark.parametrize("case", list(CASES))
def test_a_closed_pipe_is_an_exception_after_a_mesh(case, where):
    script = SCRIPT.format(call=CASES[case])
    p = subprocess.run([sys.executable, "-c", script, where], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, (p.returncode, p.stderr[-2000:])   # -13: killed by SIGPIPE
    assert p.stdout.strip() == "BrokenPipeError"
