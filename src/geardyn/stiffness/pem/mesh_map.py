"""The PEM stiffness map of a case on a centre-distance grid (what ``build_map`` caches)."""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np

from ..map import StiffnessMap
from .foundation import SainsotRangeWarning
from .model import PEMModel

CITATIONS = (
    "Yang & Lin 1987, J. Mech. Transm. Autom. Des. 109:189-196 (Hertz, bending, shear, axial)",
    "Tian 2004, MSc thesis, University of Alberta (PEM, parallel crack limit line)",
    "Sainsot, Velex & Duverger 2004, J. Mech. Des. 126:748-752 (fillet foundation)",
    "Ma, Song, Pang & Wen 2014, Eng. Fail. Anal. 44:179-194 (trochoid fillet)",
    "Chen & Shao 2011, Eng. Fail. Anal. 18:2149-2164 (crack, parallel limit line)",
    "Mohammed, Rantatalo & Aidanpaa 2013, Eng. Fail. Anal. 34:235-251 (tip limit line)",
)


#: Sources of the fault terms (geardyn.faults): what was read, and what could not be.
FAULT_CITATIONS = (
    "PHM-BGU gear model (MATLAB, Ben-Gurion University 2023), calcKeq.m and "
    "calcInvBendingStiff.m (spall and breakage as lost contact width; read)",
    "Chaari, Baccar, Abbes & Haddar 2008, Eur. J. Mech. A/Solids 27:691-705 (spalling and tooth "
    "breakage; not read)",
    "Chen & Shao 2011, Eng. Fail. Anal. 18:2149-2164 (crack along the tooth width, slicing; "
    "not read)",
)


def _case_faults(case) -> tuple:
    """The case's validated faults when it has a ``faults`` list, else ``()`` (the ``[crack]``
    section alone keeps the original model, bit for bit)."""
    if not getattr(case, "faults", None):
        return ()
    from ...faults import faults_from_case

    return faults_from_case(case)


def pem_map(case, dd: np.ndarray, *, cracked: bool,
            progress: Callable[[int, int], None] | None = None,
            model: str = "exact") -> StiffnessMap:
    """The PEM stiffness map of a case on the centre-distance grid ``dd``.

    Called by :func:`geardyn.stiffness.build_map` (which caches it). One pinion revolution
    (``n_cycles = z1``), or one gear revolution (``z2`` cycles) when the crack is on the gear,
    with ``case.stiffness.nodes_per_segment`` nodes per contact zone.

    Parameters
    ----------
    case : geardyn.config.Case
    dd : ndarray
        Centre distance changes ``d' - d`` [m], uniform and increasing.
    cracked : bool
        Include the case's crack (if it has an enabled one).
    progress : callable, optional
        ``progress(done, total)`` after each centre distance.

    Returns
    -------
    StiffnessMap
        ``k_mb`` [N/m] with ``load_share`` (n_d, nodes, 3) and ``pairs_in_contact``.

    Warns
    -----
    SainsotRangeWarning
        If a gear lies outside the fitted range of the foundation formula (recorded in
        ``attrs["warnings"]`` as well; informational notes, such as ``theta_f`` beyond the
        unsourced ``[0.01, 0.12]`` rad box, go to ``attrs["notes"]`` only).
    """
    faults = _case_faults(case) if cracked else ()
    if faults:  # the faults list (geardyn.faults): the fault model
        from .fault_model import fault_model_from_case

        pem = fault_model_from_case(case, faults, model=model)
    else:
        pem = PEMModel.from_case(case, cracked=cracked, model=model)
    dd = np.atleast_1d(np.asarray(dd, float))
    pem.check_range(dd)
    notes = pem.validity_warnings()
    for msg in notes:
        warnings.warn(msg, SainsotRangeWarning, stacklevel=2)
    info = [m for m in pem.validity_warnings(notes=True) if m not in notes]
    n_cycles = None
    if pem.crack is not None and pem.crack.gear == "gear":
        n_cycles = pem.pair.gear.teeth
    if faults:
        n_cycles = pem.period_cycles

    def fn(theta: np.ndarray, d: float) -> dict:
        r = pem.evaluate(theta, d)
        out = {"k_mb": r["k_mb"], "load_share": r["load_share"],
               "pairs_in_contact": r["pairs_in_contact"].astype(float)}
        if "fault_gap" in r:
            out["fault_gap"] = r["fault_gap"]
        return out

    from ..._version import __version__

    attrs = {
        "method": "pem",
        "title": "mesh stiffness by the potential energy method",
        "citations": list(CITATIONS),
        "parameters": pem.parameters(),
        "cracked": int(pem.crack is not None),
        "warnings": notes,
        "notes": info,
        "geardyn_version": __version__,
        "case": case.name,
    }
    if faults:
        attrs["cracked"] = int(bool(pem.active))
        attrs["faulty"] = int(bool(pem.active))
        attrs["citations"] = list(CITATIONS) + list(FAULT_CITATIONS)
    return StiffnessMap.from_function(pem.pair, dd, fn, n_cycles=n_cycles,
                                      n_seg=case.stiffness.nodes_per_segment, attrs=attrs,
                                      progress=progress)
