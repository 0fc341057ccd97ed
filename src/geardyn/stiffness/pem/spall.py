"""Contact width lost to a spall or a tooth breakage (effective-width model).

While the contact point of a pair lies on the spall's roll window (or above a breakage's cut),
the contact line is shorter by the spall's (broken) width ``b``; every term of the pair's
compliance is then taken with the face width ``L - b`` (:mod:`geardyn.faults.spall`,
:mod:`geardyn.faults.breakage` for the sources: Chaari, Baccar, Abbes & Haddar 2008, not read;
the PHM-BGU gear model's ``calcKeq.m``, read).
"""

from __future__ import annotations

import numpy as np


def width_lost(fault, gear, roll) -> np.ndarray:
    """Contact width [m] a spall or breakage on ``gear`` removes at roll ``roll`` [rad]."""
    if fault.kind == "breakage":
        return fault.width_lost(gear, roll)
    return fault.width_lost(roll)


def effective_width_factor(face_width: float, lost) -> np.ndarray:
    """``L_c / L = max(L - b, 0) / L`` [-], the factor on the pair stiffness."""
    return np.clip((face_width - np.asarray(lost, float)) / face_width, 0.0, 1.0)
