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
4. :func:`fe_map` tabulates ``k_mb = K_t / r_b1^2`` (secant ``K_t = T / Delta theta``, or the
   tangent ``dT / d(Delta theta)`` with ``[stiffness.fe] definition = "tangent"``), the load
   sharing ratio per pair, the number of pairs in contact and the static transmission error in a
   :class:`geardyn.stiffness.StiffnessMap`, at the torque ``T`` of ``[stiffness.fe] torque``, by
   default the case's operating torque ``motor.torque`` (:func:`geardyn.stiffness.fe_torque`;
   docs/verification/stiffness.md 3.1).

:mod:`.direct` solves the two bodies in contact directly (no influence coefficients, no assumed
pressure distribution); it is the independent check of the load sharing and the "full FE solve
per position" baseline of the benchmark.

Basis of the numbers: plane strain by default (``[stiffness.fe] plane = "stress"`` for plane
stress), 2-D results per metre of width multiplied by the face width; secant ``K_t = T / dtheta``
at the applied torque with the gear hub fixed and the torque on the pinion hub, so the torsion of
both bodies down to their bores is included (trap T5 of docs/verification/stiffness.md);
``k_mb = K_t / r_b1^2`` with the base radius (trap T6).

Validation (tests/fe, benchmarks/bench_fe.py): the elasticity solver against the exact
Timoshenko-Goodier cantilever and the exact torsion of an annulus; the unloaded gaps against a
brute-force distance; the load sharing and rotation against the direct two-body contact solve
(within 1 % on the path); mesh convergence (default vs. 2x refined: 0.04 %); the steel pair's
pitch-point stiffness against ISO 6336-1 ``c'`` (-11 %). Against the potential-energy method the
single-tooth compliances agree within 13 % everywhere, but in double contact the FE is about 30 %
softer: adjacent loaded teeth share the deformation of the gear body (rim and torsion to the
bore), which the PEM's ``K = sum k_pair`` ignores (trap T13).

Load-share slots: ``load_share[..., k]`` is pair ``n_exit + 1 + k`` as in every map
(:attr:`StiffnessMap.slot_tooth`); the FE also finds *extended contact* of the pair that has just
passed the theoretical end of the path, reported as ``load_share_exiting``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..map import StiffnessMap

__all__ = ["fe_map", "plot_mesh", "FEStiffness", "FESettings", "body_influence"]

#: Names of :mod:`.model` this package offers, imported on first use: the model pulls in the
#: contact code, its compiled kernels and SciPy's LAPACK bindings (0.2 s), which a run whose
#: FE maps are all cached, or a look at :mod:`.background`'s policy, never needs.
_FROM_MODEL = ("FESettings", "FEStiffness", "body_influence")


def __getattr__(name: str):
    if name in _FROM_MODEL:
        from . import model

        return getattr(model, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_FROM_MODEL))


def fe_map(case, dd: np.ndarray, *, cracked: bool,
           progress: Callable[[int, int], None] | None = None, cache=None,
           crack=None) -> StiffnessMap:
    """FE stiffness map of a case over one pinion revolution.

    Parameters
    ----------
    case : geardyn.config.Case
        Geometry, material, ``[stiffness.fe]`` (torque, by default ``motor.torque``; secant or
        tangent definition; plane, mesh size, refinement, teeth in model) and ``[crack]``.
    dd : ndarray
        Centre distance changes [m] (uniform, increasing).
    cracked : bool
        Include the case's faults: an enabled ``[crack]`` and the ``faults`` list (what the FE
        does with each fault: :mod:`.faults`).
    progress : callable, optional
        ``progress(done, total)``: the bodies (meshing, factorisation, influence coefficients),
        then each centre distance.
    cache : geardyn.cache.Cache, optional
        Where the bodies' influence coefficients are cached (default cache).
    crack : CrackGeometry, optional
        Replaces the case's root crack geometry (:class:`FEStiffness`), e.g. a grown path.

    Returns
    -------
    StiffnessMap
        ``k_mb`` [N/m] and extras ``load_share`` (n_d, nodes, 3) [-] for the three load-share
        slots of each cycle, ``load_share_exiting`` [-] (the pair in extended contact beyond the
        theoretical end of the path, which has no slot), ``pairs_in_contact`` [-],
        ``transmission_error`` [rad]; ``fault_gap`` [m] (n_d, nodes, 3) with a worn tooth.
        One pinion revolution, or one gear revolution when a gear tooth is faulty (``lcm(z1,
        z2)`` mesh cycles with faults on both).
    """
    dd = np.atleast_1d(np.asarray(dd, float))
    n_bodies = [0]

    def p_bodies(i: int, n: int) -> None:
        n_bodies[0] = n
        if progress is not None:
            progress(i, n + dd.size)

    from .model import FEStiffness

    model = FEStiffness(case, cracked=cracked, cache=cache, progress=p_bodies, crack=crack)

    def p_lines(i: int, _n: int) -> None:
        if progress is not None:
            progress(n_bodies[0] + i, n_bodies[0] + dd.size)

    # one gear revolution (or lcm of the teeth) when a gear tooth is faulty
    n_cycles = model.period_cycles
    return StiffnessMap.from_function(model.pair, dd, model.evaluate, n_cycles=n_cycles,
                                      n_seg=case.stiffness.nodes_per_segment,
                                      attrs=model.attrs(), progress=p_lines)


def plot_mesh(case, *, cracked: bool = True, zoom: bool = True, opening: bool = False):
    """Figure of the FE mesh of the cracked (or loaded) tooth, zoomed on the tooth.

    Parameters
    ----------
    case : geardyn.config.Case
    cracked : bool
        Show the cracked body if the case has an enabled crack.
    zoom : bool
        Add a panel zoomed on the crack.
    opening : bool
        Draw the zoom deformed (magnified) under the torque at the pitch point, showing the
        crack faces opening (one FE solve).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .plots import plot_body_mesh

    return plot_body_mesh(case, cracked=cracked, zoom=zoom, opening=opening)
