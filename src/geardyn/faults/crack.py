"""A root crack on one tooth, through the whole face width or part of it.

Geometry. The crack starts on the loaded fillet (the 30 deg tangent point of ISO 6336-3) and runs
at ``angle`` to the tooth centreline (:mod:`geardyn.stiffness.pem.crack`, same conventions as the
``[crack]`` section). Across the face (``z`` from the face end where the crack is deepest) its
depth is ``q(z)``, zero beyond the cracked width ``b_c``:

* ``front = "uniform"``: ``q = q_0`` for ``z <= b_c`` (``b_c = L``: today's ``[crack]``);
* ``front = "linear"``: ``q = q_0 (1 - z / b_c)``;
* ``front = "parabolic"``: ``q = q_0 sqrt(1 - z / b_c)``, the crack front the parabola
  ``z = b_c (1 - q^2 / q_0^2)``.

What the PEM does with it (:mod:`geardyn.stiffness.pem.partial_crack`): the slicing method, the
tooth cut into thin slices across the face, each slice a cantilever with its own crack depth,
the slices in parallel (Chen & Shao 2011, Eng. Fail. Anal. 18:2149-2164, crack propagating along
the tooth width; the same slicing is the basis of Mohammed, Rantatalo & Aidanpaa 2013). Those
papers could not be read from this workplace; the front shapes above are the linear and
parabolic fronts they are known for, written out here as geardyn's definitions. The full-width
uniform limit is checked against the ``[crack]`` model, and the slicing against its own
convergence, in ``tests/faults/test_root_crack.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .base import FaultBase, check_size

FRONTS = ("uniform", "linear", "parabolic")
#: Default number of slices across the cracked width (linear and parabolic fronts).
N_SLICES = 20


@dataclass(frozen=True)
class RootCrack(FaultBase):
    """A straight root crack, through the face or through part of it.

    Parameters
    ----------
    gear, tooth, label
        See :class:`geardyn.faults.base.FaultBase`.
    depth : float
        Crack length ``q_0`` at the face end where it is deepest [m] (0: no crack).
    angle : float
        Angle between the crack and the tooth centreline [rad], in (0, pi/2).
    limit_line : {"tip", "parallel"}
        PEM limit line (:class:`geardyn.stiffness.pem.ToothCrack`).
    width : float or None
        Cracked width ``b_c`` across the face [m]; ``None``: the whole face.
    front : {"uniform", "linear", "parabolic"}
        Depth profile across the cracked width (module docstring).
    slices : int
        Slices across the cracked width for the linear and parabolic fronts.
    face_width : float
        Face width ``L`` [m].
    """

    depth: float = 0.0
    angle: float = math.radians(45)
    limit_line: str = "tip"
    width: float | None = None
    front: str = "uniform"
    slices: int = N_SLICES
    face_width: float = 0.0

    kind = "root_crack"

    @property
    def cracked_width(self) -> float:
        """``b_c`` [m]."""
        return self.face_width if self.width is None else float(self.width)

    def is_null(self) -> bool:
        return self.depth == 0 or self.cracked_width == 0

    @property
    def full_width(self) -> bool:
        """A crack of one depth through the whole face (today's ``[crack]``)."""
        return self.front == "uniform" and self.cracked_width >= self.face_width

    def depth_at(self, z) -> np.ndarray:
        """Crack depth ``q(z)`` at distance ``z`` from the deep face end [m]."""
        z = np.asarray(z, float)
        bc = self.cracked_width
        x = np.clip(1.0 - z / bc, 0.0, 1.0) if bc > 0 else np.zeros(z.shape)
        inside = (z >= 0) & (z <= bc)
        if self.front == "uniform":
            q = np.full(z.shape, self.depth)
        elif self.front == "linear":
            q = self.depth * x
        else:
            q = self.depth * np.sqrt(x)
        return np.where(inside, q, 0.0)

    def slice_depths(self) -> tuple[np.ndarray, np.ndarray]:
        """Crack depths [m] and face-width fractions [-] of the slices of the tooth.

        The cracked width is cut into ``slices`` equal slices at whose midpoints the depth is
        taken (one slice for the uniform front); the rest of the face is one healthy slice
        (depth 0). The fractions sum to 1.
        """
        L, bc = self.face_width, min(self.cracked_width, self.face_width)
        if self.front == "uniform":
            q, f = [self.depth], [bc / L]
        else:
            n = int(self.slices)
            z = (np.arange(n) + 0.5) * bc / n
            q, f = list(self.depth_at(z)), [bc / (n * L)] * n
        if bc < L:
            q.append(0.0)
            f.append((L - bc) / L)
        return np.asarray(q, float), np.asarray(f, float)

    def tooth_crack(self, depth: float | None = None):
        """The :class:`geardyn.stiffness.pem.ToothCrack` of one slice (default: the deepest)."""
        from ..stiffness.pem.crack import ToothCrack

        return ToothCrack(gear=self.gear, tooth=int(self.tooth),
                          depth=float(self.depth if depth is None else depth),
                          angle=float(self.angle), limit_line=self.limit_line)

    def validate(self, pair, face_width: float) -> None:
        """Raise :class:`InputError` for a crack deeper than the tooth, a width beyond the face,
        or a bad angle, front or slice count."""
        from ..stiffness.pem.crack import crack_geometry
        from .base import gear_of

        self.check_place(pair)
        check_size(self.depth, self.field("depth"), "a crack length [m]")
        if not (0 < self.angle < math.pi / 2):
            raise InputError(self.field("angle"), self.angle, "an angle in (0, pi/2) rad")
        if self.limit_line not in ("tip", "parallel"):
            raise InputError(self.field("limit_line"), self.limit_line, "'tip' or 'parallel'")
        if self.front not in FRONTS:
            raise InputError(self.field("front"), self.front, "'uniform', 'linear' or "
                                                              "'parabolic'")
        if isinstance(self.slices, bool) or int(self.slices) != self.slices or \
                not 1 <= self.slices <= 400:
            raise InputError(self.field("slices"), self.slices, "a whole number in [1, 400]")
        if self.width is not None:
            check_size(self.width, self.field("width"), "a cracked width [m]",
                       upper=face_width, upper_text=" m (the face width)")
        if self.is_null():
            return
        try:
            crack_geometry(gear_of(pair, self.gear), self.tooth_crack())
        except InputError as exc:
            raise InputError(self.field("depth"), self.depth, exc.allowed) from None
