r"""The stiffness map: mesh stiffness ``K(theta, d)`` over one revolution and a centre-distance range.

Every stiffness method (potential energy, finite elements, a user's table) produces a
:class:`StiffnessMap`; the dynamics only ever sees its arrays.

Why the nodes are boundary-fitted
---------------------------------
In a mesh cycle the number of pairs in contact changes twice: when a pair leaves at the pinion tip
(``s = s_end``, fixed) and when a new pair enters at the gear tip (``s = s_start(d)``, which moves
with the centre distance). Blending two ``K(theta)`` curves tabulated at fixed ``theta`` for two
centre distances therefore smears each step into two half-steps (erratum 6 of
``docs/verification/dynamics.md``). geardyn instead splits each mesh cycle into its two contact zones,

* zone A: from the exit handover ``a`` to the entry handover ``b(d)`` (``floor(eps)`` pairs),
* zone B: from ``b(d)`` to the next exit handover ``a + Theta_m`` (``ceil(eps)`` pairs),

(``Theta_m = 2 pi / z1``), and places ``n_seg`` nodes across each zone, the end nodes holding the
one-sided limits. Interpolation between centre distances happens at equal *fraction of the zone*,
so the steps stay sharp at the right place for every ``d``, and interpolation along ``theta`` never
crosses a step.

Layout of the arrays (``values[i_d, node]``, ``node = (2 c + zone) n_seg + j``)
--------------------------------------------------------------------------------
``dd[i]``            centre distance change of grid line ``i`` [m], uniform spacing;
``phase_a[i]``       pinion angle of the exit handover that starts cycle 0 [rad];
``length_a[i]``      length of zone A [rad] (``(2 - eps) Theta_m`` for ``1 < eps < 2``);
``n_cycles``         mesh cycles in the map's period (``z1`` for one pinion revolution);
``n_seg``            nodes per zone.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..errors import InputError

if TYPE_CHECKING:  # at run time imported on first use: __getattr__ at the end
    from ._lookup_kernels import lookup, lookup_box

__all__ = [
    "StiffnessMap",
    "MapArrays",
    "lookup",
    "lookup_box",
    "lookup_box_reference",
    "lookup_reference",
    "zone_boundaries",
]


class MapArrays(NamedTuple):
    """The plain arrays compiled code needs to evaluate a map (see :func:`lookup`)."""

    dd0: float  # first centre distance change [m]
    ddd: float  # grid spacing [m] (0 if one grid line)
    phase_a: np.ndarray  # (n_d,) [rad]
    length_a: np.ndarray  # (n_d,) [rad]
    mesh_angle: float  # Theta_m [rad]
    n_cycles: int
    n_seg: int
    values: np.ndarray  # (n_d, n_cycles * 2 * n_seg) [N/m]


@functools.lru_cache(maxsize=8)
def _unit_fractions(n_seg: int) -> np.ndarray:
    """``np.linspace(0, 1, n_seg)``, read-only, made once per ``n_seg`` (it cost a quarter of a
    scalar :func:`lookup_reference`)."""
    fr = np.linspace(0.0, 1.0, n_seg)
    fr.setflags(write=False)
    return fr


def lookup_reference(theta: np.ndarray, dd: np.ndarray, arrays: MapArrays) -> np.ndarray:
    """Pure-NumPy twin of :func:`lookup`, written independently (``np.interp`` per zone).

    Used by the tests to check the compiled kernel; vectorised over ``theta`` and ``dd``.
    """
    theta, dd = np.broadcast_arrays(np.asarray(theta, float), np.asarray(dd, float))
    out = np.empty(theta.shape)
    n_d = arrays.values.shape[0]
    tm = arrays.mesh_angle
    period = arrays.n_cycles * tm
    grid = arrays.dd0 + arrays.ddd * np.arange(n_d)
    fr = _unit_fractions(arrays.n_seg)
    for idx in np.ndindex(theta.shape):
        # Python floats: the same IEEE arithmetic as NumPy's float64 scalars (``%`` and ``//``
        # as ``np.mod`` and ``np.floor_divide``), without their per-operation overhead (the
        # twin kernels call this once per time step)
        th, d = float(theta[idx]), float(dd[idx])
        if n_d == 1:
            lines, weights = [0], [1.0]
            a, la = float(arrays.phase_a[0]), float(arrays.length_a[0])
        else:
            if d < grid[0] - 1e-9 * arrays.ddd or d > grid[-1] + 1e-9 * arrays.ddd:
                out[idx] = np.nan
                continue
            a = float(np.interp(d, grid, arrays.phase_a))
            la = float(np.interp(d, grid, arrays.length_a))
            i = min(max(int(np.searchsorted(grid, d, side="right")) - 1, 0), n_d - 2)
            w = min(max((d - float(grid[i])) / arrays.ddd, 0.0), 1.0)
            lines, weights = [i, i + 1], [1 - w, w]
        r = (th - a) % period
        c = min(int(r // tm), arrays.n_cycles - 1)
        r -= c * tm
        if r < la:
            zone, f = 0, r / la
        else:
            zone, f = 1, (r - la) / (tm - la)
        f = min(max(f, 0.0), 1.0)
        start = (2 * c + zone) * arrays.n_seg
        out[idx] = sum(wt * np.interp(f, fr, arrays.values[ln, start:start + arrays.n_seg])
                       for ln, wt in zip(lines, weights, strict=True))
    return out


def lookup_box_reference(theta: float, h: float, dd: float, arrays: MapArrays) -> float:
    """Pure-NumPy twin of :func:`lookup_box` (scalar), through :func:`lookup_reference`.

    Written separately: the handovers are listed as the two families ``a + k Theta_m`` and
    ``a + la + k Theta_m`` around ``theta`` and the one nearest ``theta`` strictly inside the
    window splits it.
    """
    point = float(lookup_reference(np.array(theta), np.array(dd), arrays))
    if not h > 0.0 or np.isnan(point):
        return point
    n_d = arrays.values.shape[0]
    if n_d == 1:
        a, la = float(arrays.phase_a[0]), float(arrays.length_a[0])
    else:
        grid = arrays.dd0 + arrays.ddd * np.arange(n_d)
        a = float(np.interp(dd, grid, arrays.phase_a))
        la = float(np.interp(dd, grid, arrays.length_a))
    tm = arrays.mesh_angle
    k0 = math.floor((theta - a) / tm)
    offsets = [0.0] + ([la] if la > 1e-12 * tm else [])
    cands = [a + (k0 + k) * tm + off for k in (-1, 0, 1, 2) for off in offsets]
    inside = [b for b in cands if abs(b - theta) < h]
    if not inside:
        return point
    tb = min(inside, key=lambda b: abs(b - theta))
    lo, hi = theta - h, theta + h
    vl, vr = (float(lookup_reference(np.array(x), np.array(dd), arrays))
              for x in (0.5 * (lo + tb), 0.5 * (tb + hi)))
    return ((tb - lo) * vl + (hi - tb) * vr) / (2.0 * h)


def _count(value, field_name: str, minimum: int) -> int:
    """``value`` as an int >= ``minimum`` (Python or NumPy integer, not a bool), or
    :class:`InputError` naming ``field_name``."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise InputError(field_name, value, f"a whole number >= {minimum}")
    return int(value)


def _real_array(value, field_name: str, allowed: str) -> np.ndarray:
    """``value`` as a float array (numbers only: a string, ``None`` or a bool is refused)."""
    arr = np.asarray(value)
    if arr.dtype.kind not in "fiu":
        raise InputError(field_name, value, allowed)
    return arr.astype(float, copy=False)


def _not_numbers(value) -> bool:
    """Whether NumPy cannot read ``value`` as a float array."""
    try:
        np.asarray(value, float)
    except (TypeError, ValueError):
        return True
    return False


def zone_boundaries(pair, dd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Geometric exit phase ``a`` and zone-A length for each centre distance change.

    Parameters
    ----------
    pair : geardyn.geometry.GearPair
    dd : ndarray
        Centre distance changes [m].

    Returns
    -------
    phase_a : ndarray
        Pinion angle at which a pair leaves mesh at the pinion tip, in ``[0, Theta_m)`` [rad]
        (independent of ``dd``: the pinion tip position along the LOA is fixed).
    length_a : ndarray
        Length of the zone from that exit to the next entry at the gear tip [rad]:
        ``(ceil(eps) - eps) Theta_m`` (``(2 - eps) Theta_m`` for ``1 < eps < 2``).
    """
    rb1 = pair.pinion.base_radius
    tm = pair.mesh_angle
    pa, la = [], []
    for d in np.atleast_1d(dd):
        op = pair.operating(float(d), check=False)
        a = ((op.s_end - pair.pitch_point_s) / rb1) % tm
        b = ((op.s_start - pair.pitch_point_s) / rb1) % tm
        pa.append(a)
        la.append((b - a) % tm)
    return np.asarray(pa), np.asarray(la)


def _flat_writeable(a: np.ndarray, shape: tuple) -> np.ndarray:
    """``a`` broadcast to ``shape`` and flattened, writeable: numba types a read-only array
    apart and would compile the look-up a second time (0.5 s) for it, so a read-only array (a
    broadcast scalar, a file's array) is copied. ``np.broadcast_arrays`` is not used: asking its
    views whether they are writeable warns (NumPy 2: "future versions will not create a
    writeable array from broadcast_array"), and that warning reached API users."""
    f = a.ravel() if a.shape == shape else np.broadcast_to(a, shape).ravel()
    return f if f.flags.writeable else f.copy()


@dataclass(frozen=True)
class StiffnessMap:
    """Mesh stiffness over one period of pinion angle and a range of centre distance changes.

    Attributes
    ----------
    dd : ndarray, shape (n_d,)
        Centre distance changes ``d' - d`` of the grid lines [m], uniformly spaced.
    phase_a, length_a : ndarray, shape (n_d,)
        Exit-handover phase and zone-A length per grid line [rad] (see module docstring).
    mesh_angle : float
        Pinion angle of one mesh cycle ``2 pi / z1`` [rad].
    n_cycles : int
        Mesh cycles in the period (``z1``: one pinion revolution).
    n_seg : int
        Nodes per contact zone.
    k_mb : ndarray, shape (n_d, n_cycles * 2 * n_seg)
        Translational mesh stiffness along the line of action at the nodes [N/m].
    base_radius : float
        Pinion base radius ``r_b1`` [m]; ``K_t = k_mb r_b1^2`` [N m/rad].
    extra : dict of str -> ndarray
        Further per-node variables, each ``(n_d, nodes, ...)``: ``load_share``
        (``(n_d, nodes, 3)``, share of the pairs ``slot_tooth`` of each cycle) [-],
        ``pairs_in_contact`` [-], ``transmission_error`` [rad] (FE).
    slot_tooth : ndarray of int, shape (n_cycles, 3)
        Pinion tooth of load-share slot k in cycle c (slots ordered by entry into mesh).
    attrs : dict
        Provenance: method, parameters, inputs hash, geardyn version, citations.
    """

    dd: np.ndarray
    phase_a: np.ndarray
    length_a: np.ndarray
    mesh_angle: float
    n_cycles: int
    n_seg: int
    k_mb: np.ndarray
    base_radius: float
    extra: Mapping[str, np.ndarray] = field(default_factory=dict)
    slot_tooth: np.ndarray | None = None
    attrs: Mapping[str, object] = field(default_factory=dict)

    def __post_init__(self) -> None:
        _count(self.n_seg, "n_seg", 2)
        _count(self.n_cycles, "n_cycles", 1)
        dd = np.asarray(self.dd, float)
        if dd.ndim != 1 or dd.size < 1:
            raise InputError("dd", self.dd, "a 1-D array of centre distance changes [m]")
        if dd.size > 1:
            step = np.diff(dd)
            if np.any(step <= 0) or np.ptp(step) > 1e-9 * max(abs(step[0]), 1e-30) + 1e-15:
                raise InputError("dd", self.dd, "uniformly spaced, increasing values")
        nodes = self.n_cycles * 2 * self.n_seg
        if self.k_mb.shape != (dd.size, nodes):
            raise InputError("k_mb", self.k_mb.shape, f"shape ({dd.size}, {nodes})")
        if not np.all(np.isfinite(self.k_mb)) or np.any(self.k_mb < 0):
            raise InputError("k_mb", "non-finite or negative entries", "finite values >= 0 [N/m]")

    # --------------------------------------------------------------- construction
    @property
    def period(self) -> float:
        """Pinion angle covered by the map [rad]."""
        return self.n_cycles * self.mesh_angle

    @staticmethod
    def node_fractions(n_seg: int) -> np.ndarray:
        """Fractions of a zone at which nodes sit: ``linspace(0, 1, n_seg)``."""
        return np.linspace(0.0, 1.0, n_seg)

    @staticmethod
    def node_angles(phase_a: float, length_a: float, mesh_angle: float, n_cycles: int,
                    n_seg: int, nudge: float = 1e-9) -> np.ndarray:
        """Pinion angles of the nodes of one grid line [rad], shape ``(n_cycles * 2 * n_seg,)``.

        End nodes are moved ``nudge * mesh_angle`` into their zone, so a method evaluated there
        returns the one-sided limit of a step.
        """
        f = StiffnessMap.node_fractions(n_seg)
        eps = nudge * mesh_angle
        out = np.empty((n_cycles, 2, n_seg))
        lb = mesh_angle - length_a
        for c in range(n_cycles):
            start = phase_a + c * mesh_angle
            out[c, 0] = start + f * length_a
            out[c, 1] = start + length_a + f * lb
        if n_seg > 1:
            out[:, :, 0] += min(eps, 0.25 * max(min(length_a, lb), 0) / max(n_seg - 1, 1))
            out[:, :, -1] -= min(eps, 0.25 * max(min(length_a, lb), 0) / max(n_seg - 1, 1))
        return out.reshape(-1)

    @classmethod
    def from_function(cls, pair, dd: np.ndarray, fn: Callable[[np.ndarray, float], Mapping],
                      *, n_cycles: int | None = None, n_seg: int = 24,
                      attrs: Mapping[str, object] | None = None,
                      progress: Callable[[int, int], None] | None = None) -> StiffnessMap:
        """Build a map by evaluating ``fn(theta_nodes, dd_i)`` on each grid line.

        Parameters
        ----------
        pair : geardyn.geometry.GearPair
        dd : array_like
            Centre distance changes [m] (uniform, increasing).
        fn : callable
            ``fn(theta, dd) -> {"k_mb": (n,), optional "load_share": (n, 3),
            "pairs_in_contact": (n,), "transmission_error": (n,)}`` for pinion angles ``theta``
            [rad] at the change ``dd`` [m].
        n_cycles : int, optional
            Mesh cycles in the period (>= 1); default ``z1`` (one pinion revolution).
        n_seg : int
            Nodes per contact zone (>= 2: the two end nodes hold the one-sided limits).
        attrs : mapping, optional
            Provenance to store.
        progress : callable, optional
            ``progress(done, total)`` after each grid line.
        """
        n_seg = _count(n_seg, "n_seg", 2)
        n_cycles = pair.pinion.teeth if n_cycles is None else _count(n_cycles, "n_cycles", 1)
        dd = np.atleast_1d(_real_array(dd, "dd", "centre distance changes [m] (numbers)"))
        pa, la = zone_boundaries(pair, dd)
        tm = pair.mesh_angle
        rows: dict[str, list[np.ndarray]] = {}
        for i, d in enumerate(dd):
            th = cls.node_angles(pa[i], la[i], tm, n_cycles, n_seg)
            res = fn(th, float(d))
            for k, v in res.items():
                rows.setdefault(k, []).append(np.asarray(v, float))
            if progress is not None:
                progress(i + 1, len(dd))
        if "k_mb" not in rows:
            raise InputError("fn", sorted(rows), "a function returning at least 'k_mb'")
        k = np.stack(rows.pop("k_mb"))
        extra = {name: np.stack(v) for name, v in rows.items()}
        return cls(dd=dd, phase_a=pa, length_a=la, mesh_angle=tm, n_cycles=n_cycles,
                   n_seg=n_seg, k_mb=k, base_radius=pair.pinion.base_radius, extra=extra,
                   slot_tooth=slot_teeth(pair, float(pa[0]), n_cycles),
                   attrs=dict(attrs or {}))

    @classmethod
    def from_table(cls, pair, theta: np.ndarray, k_mb: np.ndarray, dd: np.ndarray | None = None,
                   *, n_seg: int = 64, attrs: Mapping[str, object] | None = None
                   ) -> StiffnessMap:
        """A map from a user's table of ``k_mb`` [N/m] on a regular pinion-angle grid.

        Parameters
        ----------
        pair : geardyn.geometry.GearPair
        theta : array_like, shape (n_theta,)
            Pinion angles [rad], increasing, covering one period (one mesh cycle or one pinion
            revolution; the table is repeated to fill a revolution).
        k_mb : array_like, shape (n_theta,) or (n_d, n_theta)
            Mesh stiffness along the LOA [N/m].
        dd : array_like, optional
            Centre distance changes of the rows [m]; omit for one row (constant in ``d``).
        n_seg : int
            Nodes per contact zone of the resampled map (>= 2).
        """
        n_seg = _count(n_seg, "n_seg", 2)
        theta = np.asarray(theta, float)
        k2 = np.atleast_2d(np.asarray(k_mb, float))
        if theta.ndim != 1 or theta.size < 4 or np.any(np.diff(theta) <= 0):
            raise InputError("theta", theta.shape, "an increasing 1-D array of >= 4 angles [rad]")
        if k2.shape[-1] != theta.size:
            raise InputError("k_mb", k2.shape, f"last axis of length {theta.size} (as theta)")
        if dd is None:
            if k2.shape[0] != 1:
                raise InputError("dd", None, f"{k2.shape[0]} centre distance changes for the rows")
            dd = np.array([0.0])
        dd = np.atleast_1d(np.asarray(dd, float))
        if dd.size != k2.shape[0]:
            raise InputError("dd", dd.size, f"one centre distance change per row ({k2.shape[0]})")
        span = theta[-1] - theta[0] + (theta[1] - theta[0])
        tm = pair.mesh_angle
        cycles_in_table = span / tm
        if abs(cycles_in_table - round(cycles_in_table)) > 1e-3 or round(cycles_in_table) < 1:
            raise InputError("theta", f"span {span:.6g} rad",
                             f"a whole number of mesh cycles ({tm:.6g} rad each) on a regular grid")
        n_cycles = pair.pinion.teeth
        rows = {i: k2[i] for i in range(dd.size)}

        def fn(th: np.ndarray, d: float) -> dict:
            i = int(np.argmin(np.abs(dd - d)))
            return {"k_mb": np.interp(th, theta, rows[i], period=span)}

        return cls.from_function(pair, dd, fn, n_cycles=n_cycles, n_seg=n_seg,
                                 attrs={"method": "table", **dict(attrs or {})})

    # --------------------------------------------------------------- evaluation
    def arrays(self, variable: str = "k_mb", slot: int | None = None) -> MapArrays:
        """The plain arrays for :func:`lookup` (``variable``: ``"k_mb"`` or an ``extra`` name
        with one value per node; ``slot`` picks one column of ``load_share``)."""
        if variable == "k_mb":
            vals = self.k_mb
        elif isinstance(variable, str) and variable in self.extra:
            vals = self.extra[variable]
        else:
            raise InputError("variable", variable,
                             "one of " + ", ".join(repr(v) for v in ["k_mb", *self.extra]))
        if slot is not None and vals.ndim == 2:
            raise InputError("slot", slot, f"None for {variable!r} (one value per node)")
        if slot is not None and vals.ndim == 3:
            n_slots = vals.shape[-1]
            if isinstance(slot, bool) or not isinstance(slot, int | np.integer) \
                    or not 0 <= slot < n_slots:
                raise InputError("slot", slot, f"an integer in [0, {n_slots - 1}] (a slot of "
                                               f"{variable!r})")
            vals = vals[..., slot]
        if vals.ndim != 2:
            raise InputError("variable", variable, "a variable with one value per node")
        ddd = float(self.dd[1] - self.dd[0]) if self.dd.size > 1 else 0.0
        return MapArrays(float(self.dd[0]), ddd, np.ascontiguousarray(self.phase_a),
                         np.ascontiguousarray(self.length_a), float(self.mesh_angle),
                         int(self.n_cycles), int(self.n_seg), np.ascontiguousarray(vals))

    def __call__(self, theta, dd=0.0, variable: str = "k_mb", slot: int | None = None
                 ) -> np.ndarray:
        """Evaluate the map at pinion angles ``theta`` [rad] and changes ``dd`` [m].

        Returns ``k_mb`` [N/m] by default; NaN outside the centre-distance range.
        ``variable="load_share", slot=k`` gives the share of slot ``k`` (see ``slot_tooth``).

        Raises
        ------
        InputError
            ``theta`` or ``dd`` not numbers (or arrays of them), a non-finite ``theta``, shapes
            that do not broadcast, an unknown ``variable`` or ``slot``.
        """
        arr = self.arrays(variable, slot)
        # cheap checks only (a hot path): what numpy cannot read as numbers and None (which it
        # reads as NaN) are refused here, a non-finite theta by the kernel's loop
        try:
            th = None if theta is None else np.asarray(theta, float)
            d = None if dd is None else np.asarray(dd, float)
        except (TypeError, ValueError):
            th = d = None
        if th is None or d is None:
            if theta is None or _not_numbers(theta):
                raise InputError("theta", theta, "pinion angles [rad]: a number or an array of "
                                                 "them")
            raise InputError("dd", dd, "centre distance changes [m]: a number or an array of "
                                       "them")
        try:
            shape = np.broadcast_shapes(th.shape, d.shape)
        except ValueError:
            raise InputError("dd", f"shape {d.shape}",
                             f"a shape that broadcasts with theta's {th.shape}") from None
        th_f, d_f = _flat_writeable(th, shape), _flat_writeable(d, shape)
        from ._lookup_kernels import _lookup_many

        out, bad = _lookup_many(th_f, d_f, *arr)
        if bad >= 0:
            raise InputError("theta", float(th_f[bad]), "finite pinion angles [rad]")
        return out.reshape(shape) if shape else float(out[0])

    def torsional(self, theta, dd=0.0) -> np.ndarray:
        """Combined torsional mesh stiffness ``K_t = k_mb r_b1^2`` [N m/rad]."""
        return np.asarray(self(theta, dd)) * self.base_radius ** 2

    def __repr__(self) -> str:
        """A line a notebook can show (the dataclass's repr printed every array, 6,800
        characters: a user audit): method, grid, stiffness range [N/m] and the fault state."""
        k = np.asarray(self.k_mb, float)
        dd = np.asarray(self.dd, float) * 1e3
        return (f"StiffnessMap(method={self.attrs.get('method', '?')!r}, "
                f"faulty={bool(self.attrs.get('cracked', self.attrs.get('faulty', 0)))}, "
                f"{dd.size} centre distance "
                f"changes {dd[0]:+.4g}..{dd[-1]:+.4g} mm, {self.n_cycles} mesh cycles x "
                f"{2 * self.n_seg} nodes, k_mb {k.min():.4g}..{k.max():.4g} N/m)")

    def zero_window(self, dd: float, n: int = 4096) -> float:
        """The widest range of pinion angle [rad] over which the mesh stiffness is zero (no
        tooth pair in contact, as a broken tooth can leave) at the centre distance change
        ``dd`` [m] (clipped to the map's range; ``n`` angles over the period): 0 where a pair
        is in contact everywhere. The map is periodic, so a window may wrap around its end."""
        d = float(np.clip(dd if np.isfinite(dd) else 0.0, self.dd[0], self.dd[-1]))
        th = np.linspace(0.0, self.period, n, endpoint=False)
        zero = np.asarray(self(th, d), float) <= 0.0
        if not zero.any():
            return 0.0
        if zero.all():
            return self.period
        z = np.roll(zero, -int(np.argmin(zero)))  # start at a node in contact
        edges = np.flatnonzero(np.diff(np.r_[0, z.astype(np.int8), 0]))
        return int(np.max(edges[1::2] - edges[::2])) * self.period / n

    def covers(self, dd: float) -> bool:
        """Whether ``dd`` [m] lies inside the map's centre-distance range."""
        if self.dd.size == 1:
            return True
        return bool(self.dd[0] - 1e-12 <= dd <= self.dd[-1] + 1e-12)

    def node_theta(self) -> np.ndarray:
        """Pinion angles of the nodes, shape ``(n_d, nodes)`` [rad]."""
        return np.stack([self.node_angles(a, la, self.mesh_angle, self.n_cycles, self.n_seg)
                         for a, la in zip(self.phase_a, self.length_a, strict=True)])

    # --------------------------------------------------------------- storage
    def to_dataset(self):
        """The map as an :class:`xarray.Dataset` with units and provenance."""
        import xarray as xr

        nodes = self.k_mb.shape[1]
        ds = xr.Dataset(
            {
                "k_mb": (("centre_distance_change", "node"), self.k_mb,
                         {"units": "N/m", "long_name": "mesh stiffness along the line of action"}),
                "torsional_stiffness": (("centre_distance_change", "node"),
                                        self.k_mb * self.base_radius ** 2,
                                        {"units": "N m/rad",
                                         "long_name": "combined torsional mesh stiffness "
                                                      "K_t = k_mb r_b1^2"}),
                "phase_a": ("centre_distance_change", self.phase_a,
                            {"units": "rad", "long_name": "pinion angle of the exit handover"}),
                "length_a": ("centre_distance_change", self.length_a,
                             {"units": "rad", "long_name": "length of contact zone A"}),
            },
            coords={
                "centre_distance_change": ("centre_distance_change", self.dd,
                                           {"units": "m", "long_name": "d' - d"}),
                "node": ("node", np.arange(nodes), {"units": "1",
                                                    "long_name": "boundary-fitted node index"}),
                "theta": (("centre_distance_change", "node"), self.node_theta(),
                          {"units": "rad", "long_name": "pinion angle of the node"}),
            },
        )
        units = {"load_share": ("1", "load sharing ratio of the slot's tooth pair"),
                 "pairs_in_contact": ("1", "number of tooth pairs in contact"),
                 "transmission_error": ("rad", "static transmission error (pinion angle)"),
                 "load_share_exiting": ("1", "load sharing ratio of the pair past the end of "
                                             "the theoretical path (extended contact, FE)"),
                 "fault_gap": ("m", "gap of the slot's worn flank along the line of action "
                                    "(the material wear removed)")}
        slots = self.extra["load_share"].shape[2] if "load_share" in self.extra else None
        for name, v in self.extra.items():
            dims = ("centre_distance_change", "node") + tuple(f"{name}_dim{k}"
                                                              for k in range(2, v.ndim))
            if name == "load_share" or (v.ndim == 3 and name == "fault_gap"
                                        and slots in (None, v.shape[2])):
                dims = ("centre_distance_change", "node", "slot")
            u, ln = units.get(name, ("", name))
            ds[name] = (dims, v, {"units": u, "long_name": ln})
        if self.slot_tooth is not None:
            ds["slot_tooth"] = (("cycle", "slot"), self.slot_tooth,
                                {"units": "1",
                                 "long_name": "pinion tooth of each load-share slot"})
        # NetCDF attributes cannot hold containers, booleans or None: store those as JSON text
        ds.attrs.update({k: (json.dumps(v) if isinstance(v, dict | list | tuple | bool)
                             or v is None else v)
                         for k, v in self.attrs.items()})
        ds.attrs.update({"mesh_angle": self.mesh_angle, "mesh_angle_units": "rad",
                         "n_cycles": self.n_cycles, "n_seg": self.n_seg,
                         "base_radius": self.base_radius, "base_radius_units": "m",
                         "geardyn_object": "StiffnessMap"})
        return ds

    @classmethod
    def from_dataset(cls, ds) -> StiffnessMap:
        """Inverse of :meth:`to_dataset`."""
        reserved = {"k_mb", "torsional_stiffness", "phase_a", "length_a", "slot_tooth"}
        extra = {n: np.asarray(ds[n].values) for n in ds.data_vars if n not in reserved}
        attrs = {k: v for k, v in ds.attrs.items()
                 if k not in ("mesh_angle", "mesh_angle_units", "n_cycles", "n_seg",
                              "base_radius", "base_radius_units", "geardyn_object")}
        return cls(
            dd=np.asarray(ds["centre_distance_change"].values, float),
            phase_a=np.asarray(ds["phase_a"].values, float),
            length_a=np.asarray(ds["length_a"].values, float),
            mesh_angle=float(ds.attrs["mesh_angle"]),
            n_cycles=int(ds.attrs["n_cycles"]),
            n_seg=int(ds.attrs["n_seg"]),
            k_mb=np.asarray(ds["k_mb"].values, float),
            base_radius=float(ds.attrs["base_radius"]),
            extra=extra,
            slot_tooth=np.asarray(ds["slot_tooth"].values) if "slot_tooth" in ds else None,
            attrs=attrs,
        )

    def to_netcdf(self, path) -> None:
        """Write the map to NetCDF atomically (temp file, then rename)."""
        from ..io import write_netcdf_atomic

        write_netcdf_atomic(self.to_dataset(), path)

    @classmethod
    def from_netcdf(cls, path) -> StiffnessMap:
        """Read a map written by :meth:`to_netcdf`."""
        from ..io import read_netcdf

        ds = read_netcdf(path, required=("k_mb", "phase_a", "length_a"))
        return cls.from_dataset(ds)

    def regular(self, n_theta: int = 360, dd: np.ndarray | None = None):
        """The map resampled on a regular ``(dd, theta)`` grid, as an xarray DataArray [N/m].

        ``n_theta`` (>= 1) angles over one period; ``dd`` the centre distance changes [m]
        (default: the map's grid lines).
        """
        import xarray as xr

        n_theta = _count(n_theta, "n_theta", 1)
        dd = self.dd if dd is None else np.atleast_1d(
            _real_array(dd, "dd", "centre distance changes [m] (numbers)"))
        th = np.linspace(0.0, self.period, n_theta, endpoint=False)
        vals = self(th[None, :], dd[:, None])
        return xr.DataArray(vals, dims=("centre_distance_change", "theta"),
                            coords={"centre_distance_change": ("centre_distance_change", dd,
                                                               {"units": "m"}),
                                    "theta": ("theta", th, {"units": "rad"})},
                            attrs={"units": "N/m", "long_name": "mesh stiffness along the LOA"},
                            name="k_mb")


def slot_teeth(pair, phase_a: float, n_cycles: int) -> np.ndarray:
    """Pinion tooth of each load-share slot: slot ``k`` of cycle ``c`` is pair
    ``n_exit(c) + 1 + k``, where ``n_exit(c)`` is the pair leaving mesh as the cycle starts."""
    rb1, pb = pair.pinion.base_radius, pair.base_pitch
    op = pair.operating(0.0, check=False)
    out = np.empty((n_cycles, 3), dtype=np.int64)
    for c in range(n_cycles):
        theta = phase_a + c * pair.mesh_angle
        n_exit = round((pair.pitch_point_s + rb1 * theta - op.s_end) / pb)
        out[c] = np.mod(n_exit + 1 + np.arange(3), pair.pinion.teeth)
    return out


def __getattr__(name: str):
    """:func:`lookup` and :func:`lookup_box`, compiled (numba) functions, are defined in
    :mod:`._lookup_kernels` and imported from there on first use, so that importing this module
    does not import numba (see that module)."""
    if name in ("lookup", "lookup_box"):
        from . import _lookup_kernels

        return getattr(_lookup_kernels, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
