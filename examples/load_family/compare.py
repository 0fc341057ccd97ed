"""K(theta, d, F): the paper's case with FE maps at 80, 100 and 120 N m read at each step's
mesh load, against the single map at the mean load (issue 18.2).

Run from the repository root: ``python3 examples/load_family/compare.py`` (builds three FE maps:
about 12 s each on a cold cache, about 2.5 s each once the FE bodies are cached; the maps
themselves are cached too). Prints the RMS difference of each signal as a percentage of its
standard deviation.
"""

import numpy as np

import geardyn
from geardyn.dynamics import simulate
from geardyn.stiffness import build_map

case = geardyn.paper_case({"stiffness.method": "fe"})
family = case.with_overrides({"stiffness.fe.torques": [80.0, 100.0, 120.0]})
smap = build_map(case)
single = simulate(case, smap, model="II")
loaded = simulate(family, smap, model="II")
print(loaded.attrs["stiffness_load_family"])
for name in ("v_yg", "mesh_force", "transmission_error", "mesh_stiffness"):
    a, b = single[name].values, loaded[name].values
    print(f"{name:20s} RMS(family - single) = {100 * np.sqrt(np.mean((b - a) ** 2)) / a.std():.3g} "
          f"% of its STD ({single[name].attrs['units']})")
