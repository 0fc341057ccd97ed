"""Local tooth faults: what is wrong with which tooth, as data with geometry.

One module per fault type, each with its parameters (a frozen dataclass), its validation and the
geometry it removes; the stiffness methods interpret them (:mod:`geardyn.stiffness.pem`,
:mod:`geardyn.stiffness.fe.faults`):

============  ==============================  ================================  ==============================
type          parameters (``[[faults]]``)     PEM                               FE (plane model)
============  ==============================  ================================  ==============================
root_crack,   depth, angle, limit_line        cracked section in the beam       slit with duplicated nodes in
through face                                  terms (Tian / tip limit line)     the mesh of that tooth's body
root_crack,   + width, front, slices          slices across the face, beam      bands across the face: one
partial face                                  compliances in parallel           plane model per slice depth
                                              (Chen & Shao 2011)                (one FE body each), sharing
                                                                                the hub rotation
breakage      height, width                   pair stiffness times              tip removed from the mesh
                                              (L - b_t) / L above the cut       (cut at r_a - height); beyond
                                              (zero for the whole face)         the cut the cut's corner
                                                                                touches (exact gap); part of
                                                                                the face: bands
spall         start+length or roll_start+     pair stiffness times              contact removed in a band of
              roll_length, width, depth       (L - b_s) / L on the window       width b_s while the contact
                                              (effective width)                 point is on the window
wear          depth, window, stiffness,       gap ``fault_gap``; with           the same ``fault_gap``;
              law (uniform or Archard)        ``stiffness`` the thinner         ``stiffness = true`` refused
                                              section
============  ==============================  ================================  ==============================

Why each method does what it does. The PEM is a beam per tooth: a crack or wear changes the
sections, and anything that removes contact along the face (spall, breakage) scales the pair's
compliances, all proportional to ``1/L``, by the remaining width. The FE model is plane (per unit
width): what changes the tooth's shape in its plane is meshed (the crack as a slit, the broken
tip as a cut), so the body's own coupling (rim, neighbouring teeth, the load near a free edge)
comes with it; what varies across the face (a partial crack, a spall, a breakage of part of the
face) needs bands across the face, each a plane model, in parallel under one hub rotation. Wear
is a profile deviation of tens of micrometres, below the FE mesh's flank element size: the FE
records it as the PEM does (the gap, for the dynamics) and refuses the thinner tooth.

Measured differences (paper pair, coarse test mesh, tests/fe/test_fe_faults.py): the 5 mm
through crack loses up to 0.160 of ``k_mb`` in FE against 0.136 in PEM; a 6 mm spall 0.292 against
0.300 (the FE's local Hertz term is not linear in the load per width); a whole-face 2 mm breakage
0.303 against 0.484, since beyond the cut the FE keeps the cut's corner in contact (as the tip
corner in extended contact) where the PEM drops the pair at once.

What the FE refuses (:func:`check_method`, naming the field): wear with ``stiffness = true``; a
breakage leaving less than a tenth of the involute above the form circle; two faulty teeth of one
gear (crack or breakage) closer than ``stiffness.fe.teeth_in_model`` (their body models would
share a loaded tooth).

Every entry names its gear (``pinion`` or ``gear``) and tooth (0-based, mesh order). The legacy
``[crack]`` section is one ``root_crack`` (label ``crack``). :func:`faults_from_case` builds and
validates them all; errors name the entry as ``faults[i].<key>``.
"""

from __future__ import annotations

from ..errors import InputError
from .base import FaultBase, active_roll_range, gear_of
from .breakage import Breakage
from .crack import FRONTS, N_SLICES, RootCrack
from .spall import Spall
from .wear import Wear, archard_scale, archard_shape

__all__ = ["FaultBase", "RootCrack", "Spall", "Breakage", "Wear", "faults_from_case",
           "check_faults", "check_method", "fault_types", "FE_SUPPORTED", "KEYS",
           "active_roll_range", "FRONTS", "N_SLICES", "archard_scale", "archard_shape",
           "without_faults"]

Fault = RootCrack | Spall | Breakage | Wear

#: Keys each fault type takes besides ``type``, ``gear`` and ``tooth``.
KEYS = {
    "root_crack": ("depth", "angle", "limit_line", "width", "front", "slices"),
    "spall": ("start", "length", "roll_start", "roll_length", "width", "depth"),
    "breakage": ("height", "width"),
    "wear": ("depth", "start", "length", "roll_start", "roll_length", "stiffness", "law"),
}
#: Fault types the FE method models (:mod:`geardyn.stiffness.fe.faults`; with the limits that
#: :func:`check_method` enforces).
FE_SUPPORTED: tuple[str, ...] = ("root_crack", "spall", "breakage", "wear")
_COMMON = ("type", "gear", "tooth")


def fault_types() -> tuple[str, ...]:
    """The fault types of the ``faults`` list."""
    return tuple(KEYS)


def _window(cfg, gear, label: str, required: bool, default: tuple[float, float]):
    """Roll window ``(start, length)`` [rad] from ``start``/``length`` (roll length, m) or
    ``roll_start``/``roll_length`` (rad)."""
    rb = gear.base_radius
    by_len = cfg.start is not None or cfg.length is not None
    by_roll = cfg.roll_start is not None or cfg.roll_length is not None
    if by_len and by_roll:
        key = "roll_start" if cfg.roll_start is not None else "roll_length"
        raise InputError(f"{label}.{key}", getattr(cfg, key), "either start and length (roll "
                         "length along the line of action) or roll_start and roll_length "
                         "(roll angle), not both")
    if by_len:
        start, length = cfg.start, cfg.length
        names = ("start", "length")
        scale = 1.0 / rb
    else:
        start, length = cfg.roll_start, cfg.roll_length
        names = ("roll_start", "roll_length")
        scale = 1.0
    if start is None and length is None:
        if required:
            raise InputError(f"{label}.start", None, "the position along the profile: start "
                             "and length (e.g. '3 mm', roll length from the base circle "
                             "tangency point) or roll_start and roll_length (e.g. '20 deg')")
        return default
    for name, value in zip(names, (start, length), strict=True):
        if value is None:
            raise InputError(f"{label}.{name}", None, f"a value (give both {names[0]} and "
                                                      f"{names[1]})")
    if length < 0:
        raise InputError(f"{label}.{names[1]}", length, "a length >= 0 (0: no fault)")
    return start * scale, length * scale


def _from_config(cfg, i: int, pair, face_width: float) -> Fault:
    label = f"faults[{i}]"
    allowed = KEYS[cfg.type]
    for key in type(cfg).model_fields:
        if key in _COMMON or key in allowed:
            continue
        if getattr(cfg, key) is not None:
            raise InputError(f"{label}.{key}", getattr(cfg, key),
                             f"a key of a {cfg.type} fault: {', '.join(_COMMON + allowed)}")
    place = {"gear": cfg.gear, "tooth": int(cfg.tooth), "label": label}
    g = gear_of(pair, cfg.gear)
    if cfg.type == "root_crack":
        if cfg.depth is None:
            raise InputError(f"{label}.depth", None, "a crack length (e.g. '2 mm')")
        kw = {k: getattr(cfg, k) for k in ("angle", "limit_line", "front", "slices")
              if getattr(cfg, k) is not None}
        return RootCrack(**place, depth=cfg.depth, width=cfg.width, face_width=face_width, **kw)
    if cfg.type == "spall":
        for key in ("width", "depth"):
            if getattr(cfg, key) is None:
                raise InputError(f"{label}.{key}", None, f"the spall {key} (e.g. '2 mm')")
        a, du = _window(cfg, g, label, True, (0.0, 0.0))
        return Spall(**place, roll_start=a, roll_length=du, width=cfg.width, depth=cfg.depth)
    if cfg.type == "breakage":
        if cfg.height is None:
            raise InputError(f"{label}.height", None, "the height lost from the tip (e.g. "
                                                      "'1 mm')")
        return Breakage(**place, height=cfg.height, width=cfg.width, face_width=face_width)
    if cfg.depth is None:
        raise InputError(f"{label}.depth", None, "the depth worn off the flank (e.g. '10 um')")
    lo, hi = active_roll_range(pair, cfg.gear)
    a, du = _window(cfg, g, label, False, (lo, hi - lo))
    law = cfg.law or "uniform"
    shape = archard_shape(pair, cfg.gear, (a, a + du)) if law == "archard" and du > 0 else ()
    return Wear(**place, depth=cfg.depth, roll_start=a, roll_length=du,
                stiffness=bool(cfg.stiffness), law=law, shape=shape)


def _overlap(a: tuple[float, float], b: tuple[float, float]) -> bool:
    return a[0] < b[1] and b[0] < a[1]


def _check_pairs(faults: list[Fault], pair) -> None:
    """Two faults on one tooth that cannot both be there."""
    for j, f in enumerate(faults):
        for e in faults[:j]:
            if (e.gear, e.tooth) != (f.gear, f.tooth) or e.is_null() or f.is_null():
                continue
            where = f"{f.gear} tooth {f.tooth}"
            clash = None
            if f.kind == e.kind and f.kind in ("root_crack", "breakage"):
                owner = ("the [crack] section already cracks it (crack.enabled = false, or "
                         "one of the two)" if e.label == "crack" else f"{e.label} is one there")
                clash = (f"not a second {f.kind.replace('_', ' ')} on {where}: {owner}")
            elif f.kind == e.kind and _overlap(f.window, e.window):
                clash = f"a {f.kind} that does not overlap {e.label} on {where} (roll " \
                        f"{e.window[0]:.5g} to {e.window[1]:.5g} rad)"
            elif {f.kind, e.kind} == {"spall", "breakage"}:
                s, b = (f, e) if f.kind == "spall" else (e, f)
                cut = b.cut_roll(gear_of(pair, b.gear))
                if s.window[1] > cut:
                    clash = f"a spall below the broken tip of {b.label} on {where} (cut at " \
                            f"roll {cut:.5g} rad)"
            elif {f.kind, e.kind} == {"root_crack", "wear"}:
                w = f if f.kind == "wear" else e
                if w.stiffness:
                    clash = f"not both a root crack and wear with stiffness = true on {where} " \
                            "(the PEM does not combine the two sections yet)"
            if clash:
                raise InputError(f.field("type"), f.kind, clash)


def faults_from_case(case, *, legacy_crack: bool = True) -> tuple[Fault, ...]:
    """The case's faults, validated: its ``faults`` list and (``legacy_crack``) an enabled
    ``[crack]`` section as a full-width ``root_crack`` labelled ``crack``.

    Raises
    ------
    InputError
        A bad entry, naming it as ``faults[i].<key>`` with the value and what is allowed: a
        spall off the active profile, a crack deeper than the tooth, a tooth out of range, two
        faults that overlap on one tooth, a key the fault type does not take.
    """
    pair = case.gear_pair()
    L = case.pair.face_width
    out: list[Fault] = []
    if legacy_crack and case.crack is not None and case.crack.enabled:
        c = case.crack
        out.append(RootCrack(gear=c.gear, tooth=int(c.tooth), label="crack", depth=c.depth,
                             angle=c.angle, limit_line=c.limit_line, face_width=L))
        out[-1].check_place(pair)
    for i, cfg in enumerate(getattr(case, "faults", None) or ()):
        f = _from_config(cfg, i, pair, L)
        f.validate(pair, L)
        out.append(f)
    _check_pairs(out, pair)
    return tuple(out)


def check_faults(case) -> None:
    """Validate the case's ``faults`` list (see :func:`faults_from_case`)."""
    if getattr(case, "faults", None):
        faults_from_case(case)


def without_faults(case):
    """The healthy gear pair of ``case``: the case without its ``faults`` list (the case itself
    when it has none, so its cache keys stay). The stiffness maps leave the faults out with
    ``cracked=False``; this also removes what the faults put into the tooth deviations (wear's
    gap, :meth:`geardyn.modifications.ToothModifications.from_case`), for the healthy runs of a
    study (``geardyn run``, ``simulate --no-crack``, ``measure --no-crack``)."""
    if not getattr(case, "faults", None):
        return case
    return case.with_overrides({"faults": []})


def check_method(case, method: str) -> None:
    """Raise :class:`InputError` if ``method`` cannot model one of the case's ``faults``.

    The FE method refuses wear with ``stiffness = true``, a breakage that leaves less than a
    tenth of the involute, and two faulty teeth of one gear (crack or breakage) closer than
    ``stiffness.fe.teeth_in_model`` (:func:`geardyn.stiffness.fe.faults.check_fe_faults`), each
    naming the entry's field.
    """
    if method == "pem":
        return
    for i, cfg in enumerate(getattr(case, "faults", None) or ()):
        if cfg.type not in FE_SUPPORTED:  # pragma: no cover - every type is modelled today
            raise InputError("stiffness.method", method,
                             f"'pem' for faults[{i}] (type {cfg.type}): the {method} method does "
                             "not model it; see geardyn.faults")
    if getattr(case, "faults", None):
        from ..stiffness.fe.faults import check_fe_faults

        check_fe_faults(faults_from_case(case), case.gear_pair(),
                        case.stiffness.fe.teeth_in_model)
