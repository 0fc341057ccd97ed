r"""Finite-element mesh stiffness ``K(theta, d)`` with load sharing (Xue & Howard 2018, section 3).

The paper computes the combined torsional mesh stiffness and the load sharing ratio with a contact
FE model of the gear pair at each position, for several centre distance increments, healthy and
with a 5 mm root crack (its Figs. 4-6). geardyn computes the same quantities with a real FE model of
the real tooth shape, but factorises each gear body once:

1. :mod:`.mesh` meshes each whole gear body (rack-generated involute and trochoid teeth, to the
   bore) with gmsh, refined along the loaded flanks; the crack is a slit with duplicated nodes.
2. :mod:`.solve` builds plane-strain (or plane-stress) P2 elasticity with scikit-fem, factorises
   it once and computes the flank influence coefficients under Hertzian pressure patches.
3. :mod:`.contact` finds the contact points, the unloaded gaps (zero on the theoretical path,
   exact corner-to-flank gaps beyond it, so extended and tip contact appear under load) and
   solves compatibility with non-negative forces under the torque, with an analytical correction
   of the local Hertzian deformation to the actual contact width.
4. :func:`fe_map` tabulates ``k_mb = K_t / r_b1^2`` (secant ``K_t = T / Delta theta``), the load
   sharing ratio per pair, the number of pairs in contact and the static transmission error in a
   :class:`geardyn.stiffness.StiffnessMap`.

:mod:`.direct` solves the two bodies in contact directly (no influence coefficients, no assumed
pressure distribution); it is the independent check of the load sharing and the "full FE solve
per position" baseline of the benchmark.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..map import StiffnessMap
from .model import FESettings, FEStiffness, body_influence

__all__ = ["fe_map", "plot_mesh", "FEStiffness", "FESettings", "body_influence"]


def fe_map(case, dd: np.ndarray, *, cracked: bool,
           progress: Callable[[int, int], None] | None = None, cache=None) -> StiffnessMap:
    """FE stiffness map of a case over one pinion revolution.

    Parameters
    ----------
    case : geardyn.config.Case
        Geometry, material, ``[stiffness.fe]`` (torque, plane, mesh size, refinement, teeth in
        model) and ``[crack]``.
    dd : ndarray
        Centre distance changes [m] (uniform, increasing).
    cracked : bool
        Include the case's crack if it has an enabled one.
    progress : callable, optional
        ``progress(done, total)``: the bodies (meshing, factorisation, influence coefficients),
        then each centre distance.
    cache : geardyn.cache.Cache, optional
        Where the bodies' influence coefficients are cached (default cache).

    Returns
    -------
    StiffnessMap
        ``k_mb`` [N/m] and extras ``load_share`` (n_d, nodes, 3) [-] for the three load-share
        slots of each cycle, ``pairs_in_contact`` [-], ``transmission_error`` [rad].
    """
    dd = np.atleast_1d(np.asarray(dd, float))
    n_bodies = 3 if (cracked and case.crack is not None and case.crack.enabled) else 2
    total = n_bodies + dd.size

    def p_bodies(i: int, _n: int) -> None:
        if progress is not None:
            progress(i, total)

    model = FEStiffness(case, cracked=cracked, cache=cache, progress=p_bodies)

    def p_lines(i: int, _n: int) -> None:
        if progress is not None:
            progress(n_bodies + i, total)

    return StiffnessMap.from_function(model.pair, dd, model.evaluate,
                                      n_seg=case.stiffness.nodes_per_segment,
                                      attrs=model.attrs(), progress=p_lines)


def plot_mesh(case, *, cracked: bool = True, zoom: bool = True):
    """Figure of the FE mesh of the cracked (or loaded) tooth, zoomed on the tooth.

    Parameters
    ----------
    case : geardyn.config.Case
    cracked : bool
        Show the cracked body if the case has an enabled crack.
    zoom : bool
        Add a panel zoomed on the crack tip.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .plots import plot_body_mesh

    return plot_body_mesh(case, cracked=cracked, zoom=zoom)
