"""Reading the records the diagnostics chain runs on: a geardyn simulation result (NetCDF, its
exact shaft angle) or measured data as acquisition systems write it (CSV/TXT, .npy/.npz, .mat,
NetCDF) with a tachometer (pulse train or pulse times) or an encoder angle, into a
:class:`Measurement` (:mod:`.pipeline` runs the chain on it)."""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from geardyn.errors import DataFileError, InputError

from .io import NETCDF_SUFFIXES, read_simulation, read_table, stored_rate, unit_in_name
from .tsa import _check_int, tach_pulse_times
from .tsa import tach_threshold as tach_threshold_level

__all__ = ["SIMULATION_SIGNALS", "Measurement", "load_simulation", "load_measurement", "load"]

#: The paper's three signals in a geardyn simulation result, with their units.
SIMULATION_SIGNALS: dict[str, str] = {
    "v_yg": "m/s",  # output gear vertical velocity
    "omega_p": "rad/s",  # input pinion angular velocity
    "transmission_error": "rad",  # theta_p - theta_g
}


@dataclass(frozen=True)
class Measurement:
    """Signals and shaft-angle information ready for :func:`diagnose`.

    Attributes
    ----------
    signals : dict of str to ndarray
        Signals (their own units), all of the same length n.
    fs : float or None
        Sample rate [Hz] (uniform sampling), if known.
    time : ndarray or None
        Sample times [s], if known.
    angle : ndarray or None
        Exact shaft angle of each sample [rad] (unwrapped), if known.
    tach_times : ndarray or None
        Tachometer pulse times [s], if known.
    pulses_per_rev : int
        Tachometer pulses per revolution [-].
    teeth : int or None
        Teeth of the gear on the averaged shaft [-], if the file says.
    units : dict of str to str
        Unit of each signal (may be empty strings).
    source : str
        File the data came from.
    """

    signals: dict[str, np.ndarray]
    fs: float | None = None
    time: np.ndarray | None = None
    angle: np.ndarray | None = None
    tach_times: np.ndarray | None = None
    pulses_per_rev: int = 1
    teeth: int | None = None
    units: dict[str, str] = field(default_factory=dict)
    source: str = ""


# --------------------------------------------------------------------------------------------
# loading
# --------------------------------------------------------------------------------------------
def load_simulation(path, *, signals: Sequence[str] | None = None,
                    angle: str = "theta_p",
                    option_names: Mapping[str, str] | None = None) -> Measurement:
    """Read a geardyn simulation result (NetCDF) for diagnosis.

    The shaft angle is the exact pinion angle ``theta_p`` [rad]; the default signals are the
    paper's three: ``v_yg`` [m/s], ``omega_p`` [rad/s] and ``transmission_error`` [rad]. The
    tooth count for the mesh orders is the attribute ``pinion_teeth`` (else the pinion of the
    case stored in the attribute ``case_toml``).

    Parameters
    ----------
    path : str or path-like
        The ``.nc`` file (NetCDF-4, as ``geardyn simulate`` writes it).
    signals : sequence of str, optional
        Data variables to diagnose; default :data:`SIMULATION_SIGNALS`.
    angle : str
        Data variable holding the shaft angle [rad].
    option_names : mapping, optional
        Names to give the arguments in error messages (e.g. ``{"signals": "--signal"}`` for a
        command line); default the argument names.

    Returns
    -------
    Measurement

    Raises
    ------
    DataFileError
        Missing/corrupt file, no time coordinate.
    InputError
        A requested variable is absent.
    """
    name_of = _namer(option_names)
    names = list(signals) if signals is not None else list(SIMULATION_SIGNALS)
    if not names:
        raise InputError(name_of("signals"), names, "at least one data variable name")
    try:
        time, data, attrs = read_simulation(path, [angle, *[n for n in names if n != angle]],
                                            field_name=name_of("signals"))
    except InputError as exc:
        missing = exc.value if isinstance(exc.value, list) else [exc.value]
        if angle not in missing:
            raise
        # not a simulation result (e.g. a measured record in NetCDF): not a --signal problem
        raise DataFileError(path, f"has no {angle!r}, the shaft angle of a geardyn simulation "
                                  "result: for measured data name its shaft angle or "
                                  f"tachometer channel ({name_of('angle')} or "
                                  f"{name_of('tach')})") from None
    scalars, text = {}, {}
    for k, v in attrs.items():
        if isinstance(v, str):
            text[str(k)] = v
        else:
            try:
                scalars[str(k)] = float(np.asarray(v).reshape(-1)[0])
            except (TypeError, ValueError, IndexError):
                pass
    teeth = _stored_teeth(scalars, text, "pinion")
    units = {n: attrs["units"].get(n) or SIMULATION_SIGNALS.get(n, "") for n in names}
    return Measurement(signals={n: data[n] for n in names}, time=time, angle=data[angle],
                       teeth=teeth, units=units, source=str(path))


#: Units of an angle column: name -> radians per unit.
_ANGLE_UNITS = {"rad": 1.0, "deg": np.pi / 180.0, "rev": 2.0 * np.pi}
#: How files write them (a column name's brackets, a units attribute) -> :data:`_ANGLE_UNITS`.
_ANGLE_SPELLINGS = {"rad": "rad", "radian": "rad", "radians": "rad", "deg": "deg",
                    "degree": "deg", "degrees": "deg", "\u00b0": "deg", "rev": "rev",
                    "revs": "rev", "revolution": "rev", "revolutions": "rev", "turn": "rev",
                    "turns": "rev"}


def _column_name(table, key) -> str:
    """The name of a column given by name or position."""
    return key if isinstance(key, str) and key in table.columns else table.names[int(key)]


def _stated_unit(table, key) -> str:
    """The unit the file states for a column: its units entry, else its name's brackets."""
    try:
        name = _column_name(table, key)
    except (IndexError, ValueError, TypeError):
        return ""  # table.get names the bad column
    return (table.units.get(name) or table.text.get(f"units.{name}", "")
            or unit_in_name(name)).strip()


def _angle_unit_stated(table, key) -> str | None:
    """rad, deg or rev as the angle column states it; None where it states none."""
    unit = _stated_unit(table, key)
    return _ANGLE_SPELLINGS.get(unit.lower()) if unit else None


def _time_scale(table, key, field: str) -> float:
    """Seconds per unit of a time column: 1 unless it states another time unit ("time [ms]"
    was read as seconds, a 1000 times slower shaft, with nothing said: a user audit of
    2026-11-27)."""
    unit = _stated_unit(table, key)
    if not unit or unit == "s":
        return 1.0
    from ..units import to_si

    try:
        return float(to_si(f"1 {unit}", "time", field))
    except InputError:
        raise InputError(field, f"column {_column_name(table, key)!r} in {unit!r}",
                         "a time column in s, or in a time unit its name or the file states "
                         "(ms, us, min)") from None


def load_measurement(
    path,
    *,
    signal: str | int | Sequence[str | int],
    fs: float | None = None,
    time: str | int | None = None,
    angle: str | int | None = None,
    tach: str | int | None = None,
    tach_column_is_pulse_times: bool = False,
    pulses_per_rev: int | None = None,
    tach_threshold: float | None = None,
    tach_edge: str = "rising",
    tach_min_interval: float | None = None,
    angle_unit: str | None = None,
    unwrap_angle: bool = False,
    units: Mapping[str, str] | None = None,
    option_names: Mapping[str, str] | None = None,
) -> Measurement:
    """Read measured data (CSV/text, .npy, .npz, .mat) for diagnosis.

    Give the sampling by ``fs`` (uniform) or a ``time`` column, and the shaft angle by an
    ``angle`` column (encoder angle) or a ``tach`` column. A tachometer column is either a
    sampled pulse train (rising edges found at ``tach_threshold``, default mid-range, with
    sub-sample interpolation; see :func:`geardyn.diagnostics.tach_pulse_times`) or, with
    ``tach_column_is_pulse_times``, a list of pulse times [s] (NaN padding ignored).
    ``pulses_per_rev`` is the number of tachometer pulses per revolution of the shaft to be
    averaged (e.g. 1 for a once-per-rev key phasor, 60 for a 60-tooth wheel); pulses are assumed
    equally spaced around the shaft.

    A file that stores its own sample rate (a scalar ``fs`` in a .npz/.mat file, a global
    attribute ``fs`` of a NetCDF file) is read at that rate: an ``fs`` that differs from it is
    refused. The teeth on the averaged shaft are taken from the file when it says
    (:attr:`Measurement.teeth`): a ``pinion_teeth`` entry, or the pinion of the case a
    ``geardyn measure`` record stores (``case_toml``; the gear when the record's tachometer
    reads the gear shaft, ``tach_shaft = "gear"``, and ``tach`` is given).

    Parameters
    ----------
    path : str or path-like
        The data file.
    signal : str, int or sequence of them
        Column(s) to diagnose (name or 0-based position).
    fs : float, optional
        Sample rate [Hz]; if absent, a scalar ``fs`` stored in the file is used. Not with
        ``time``; for a file that stores its rate, only that rate.
    time : str or int, optional
        Column of sample times: in s, or in the time unit the column states (its name,
        ``"time [ms]"``, or the file's units), converted to s.
    angle : str or int, optional
        Column of shaft angle (unit ``angle_unit``).
    tach : str or int, optional
        Tachometer column.
    tach_column_is_pulse_times : bool
        The ``tach`` column lists pulse times [s] instead of a sampled pulse train.
    pulses_per_rev : int, optional
        Tachometer pulses per shaft revolution [-]; default what the file says
        (``tach_pulses_per_rev``, as ``geardyn measure`` writes it), else 1. A value that
        contradicts the file's is refused.
    tach_threshold : float, optional
        Edge threshold of a sampled pulse train (unit of the column).
    tach_edge : {"rising", "falling"}
        The edge that marks a pulse of a sampled pulse train: its leading edge ("falling"
        for an active-low tachometer).
    tach_min_interval : float, optional
        Shortest time between two pulses [s]: edges closer than this to the last one kept
        (noise on a slow edge, chatter) are dropped.
    angle_unit : {"rad", "deg", "rev"}, optional
        Unit of the angle column; default the unit the column states (its name,
        ``"angle [deg]"``, or the file's units), else rad. One that contradicts the column's
        is refused.
    unwrap_angle : bool
        Unwrap a wrapped angle column (0..2*pi sawtooth).
    units : mapping, optional
        Unit of each signal, for labels (name -> unit).
    option_names : mapping, optional
        Names to give the arguments in error messages, e.g. ``{"fs": "--fs", "time":
        "--time"}`` for a command line; default the argument names.

    Returns
    -------
    Measurement

    Raises
    ------
    DataFileError
        Unreadable/corrupt/truncated file, a stored sample rate that is not a positive number.
    InputError
        Missing column, no sampling or angle information, ``fs`` with ``time``, an ``fs`` other
        than the file's own, bad options.
    """
    name_of = _namer(option_names)
    table = read_table(path)
    file_name = Path(path).name
    specs = [signal] if isinstance(signal, (str, int, np.integer)) else list(signal)
    if not specs:
        raise InputError(name_of("signal"), signal, "at least one column")
    signals: dict[str, np.ndarray] = {}
    for s in specs:
        arr = table.get(s, name_of("signal"))
        name = s if isinstance(s, str) and s in table.columns else table.names[int(s)]
        signals[name] = arr
    n = next(iter(signals.values())).shape[0]

    fs_, time_ = name_of("fs"), name_of("time")
    if isinstance(fs, str):  # "20 kHz", as the command line's --fs
        from ..units import parse_frequency

        fs = parse_frequency(fs, fs_)
    if fs is not None and not (isinstance(fs, int | float | np.integer | np.floating)
                               and np.isfinite(fs) and fs > 0):
        raise InputError(fs_, fs, "a positive sample rate in Hz")
    if fs is not None and time is not None:
        # the time column would win (tach edges, tsa) and fs be ignored without a word
        raise InputError(fs_, f"{fs:.10g} Hz",
                         f"no {fs_} together with {time_} (the times of column {time!r} "
                         f"would be used): give one of them")
    rate_entry = stored_rate(table.scalars)  # fs, Fs, sampleRate, data.sample_rate...
    rate_key, stored_fs = rate_entry if rate_entry is not None else ("fs", None)
    if stored_fs is not None and np.isfinite(stored_fs) and stored_fs > 0:
        if fs is not None and not _same_rate(fs, stored_fs):
            raise InputError(fs_, f"{fs:.10g} Hz",
                             f"{file_name}'s own sample rate, {stored_fs:.10g} Hz, or no "
                             f"{fs_}: the file stores its rate")
        if time is None:
            fs = stored_fs
    elif stored_fs is not None and fs is None and time is None:
        raise DataFileError(path, f"stores a sample rate {rate_key} = {stored_fs:g}, not a "
                                  f"positive number of Hz: give the rate ({fs_}) or a time "
                                  f"column ({time_})")
    t = None if time is None else table.get(time, time_) * _time_scale(table, time, time_)
    if fs is None and t is None:
        timelike = [c for c in table.names
                    if re.match(r"(?i)^\s*(time|t)\b", c) and c not in signals]
        hint = (f" (its column{'s' if len(timelike) > 1 else ''} "
                + ", ".join(repr(c) for c in timelike[:3]) + f" for {time_}?)" if timelike else "")
        raise InputError(f"{fs_}/{time_}", "neither",
                         f"a sample rate in Hz ({fs_}) or a time column ({time_}): "
                         f"{file_name} stores no sample rate{hint}")

    if (angle is None) == (tach is None):
        raise InputError(f"{name_of('angle')}/{name_of('tach')}",
                         "both" if angle is not None else "neither",
                         "exactly one of an angle column or a tachometer column")
    ang = None
    tach_times = None
    sampled_train = (("tach_edge", tach_edge, "rising"), ("tach_threshold", tach_threshold, None),
                     ("tach_min_interval", tach_min_interval, None))
    for key, value, idle in (("tach_column_is_pulse_times", tach_column_is_pulse_times, False),
                             ("pulses_per_rev", pulses_per_rev, None), *sampled_train):
        if angle is not None and value != idle:  # tachometer options with an angle channel
            raise InputError(name_of(key), value, f"no {name_of(key)} with an "
                             f"{name_of('angle')} channel (it applies to a {name_of('tach')} "
                             "channel)")
    for key, value, idle in sampled_train:
        if tach_column_is_pulse_times and value != idle:  # edges of a train, not given times
            raise InputError(name_of(key), value, f"no {name_of(key)} with "
                             f"{name_of('tach_column_is_pulse_times')}: it finds the edges of a "
                             "sampled pulse train, and the column already lists pulse times")
    if angle is None and angle_unit is not None:  # the tachometer's angle has no unit
        raise InputError(name_of("angle_unit"), angle_unit,
                         f"no {name_of('angle_unit')} with a tachometer channel (it is the unit "
                         f"of an {name_of('angle')} channel)")
    if angle is None and unwrap_angle:
        raise InputError(name_of("unwrap_angle"), True,
                         f"no {name_of('unwrap_angle')} with a tachometer channel (it unwraps "
                         f"an {name_of('angle')} channel)")
    if angle is not None:
        stated = _angle_unit_stated(table, angle)
        if angle_unit is None:
            angle_unit = stated or "rad"
        scale = _ANGLE_UNITS.get(angle_unit)
        if scale is None:
            raise InputError(name_of("angle_unit"), angle_unit, "'rad', 'deg' or 'rev'")
        if stated is not None and stated != angle_unit:
            raise InputError(name_of("angle_unit"), angle_unit,
                             f"the unit the angle column {_column_name(table, angle)!r} states, "
                             f"{stated}, or no {name_of('angle_unit')}")
        ang = table.get(angle, name_of("angle")) * scale
        if unwrap_angle:
            ang = np.unwrap(ang)
    else:
        col = table.get(tach, name_of("tach"))
        if not tach_column_is_pulse_times and col.shape[0] != n:
            # before any edge search: a length mismatch is not a threshold problem
            first = next(iter(signals))
            raise InputError(name_of("tach"), f"channel {tach!r} has {col.shape[0]} samples",
                             f"a sampled pulse train as long as the signal {first!r} "
                             f"({n} samples), or a column of pulse times "
                             f"({name_of('tach_column_is_pulse_times')})")
        if tach_column_is_pulse_times:
            tach_times = col[np.isfinite(col)]
        else:
            tach_times = _pulse_times(col, fs=None if t is not None else fs, time=t,
                                      threshold=tach_threshold, edge=tach_edge,
                                      min_interval=tach_min_interval, name_of=name_of)
        if tach_times.size < 2:
            level = ("" if tach_column_is_pulse_times else
                     f" at the threshold {tach_threshold_level(col, tach_threshold):.6g} (the "
                     f"tach's "
                     f"{'mid-range' if tach_threshold is None else 'given level'}; a spike "
                     f"lifts the mid-range: set {name_of('tach_threshold')})")
            raise InputError(name_of("tach"), tach, "a tachometer channel with at least 2 "
                                                    f"pulses (found {tach_times.size}{level})")
    for name, arr in [*signals.items(), (time_, t), (name_of("angle"), ang)]:
        if arr is not None and arr.shape[0] != n:
            raise InputError(name, f"{arr.shape[0]} samples", f"{n} samples like the signal")
    shaft = "pinion"
    if tach is not None and _entry(table.text, "tach_shaft", "").strip() == "gear":
        shaft = "gear"  # a geardyn measure record whose tachometer reads the gear shaft
    ppr = _pulses_per_rev(path, table.scalars, pulses_per_rev, name_of)
    return Measurement(signals=signals, fs=None if fs is None else float(fs), time=t,
                       angle=ang, tach_times=tach_times, pulses_per_rev=ppr,
                       teeth=_stored_teeth(table.scalars, table.text, shaft),
                       # the unit given, else the file's (NetCDF units), else the name's
                       units={k: (units or {}).get(k) or table.units.get(k)
                              or table.text.get(f"units.{k}", "") or unit_in_name(k)
                              for k in signals},
                       source=str(path))



def _pulse_times(col, *, fs, time, threshold, edge, min_interval, name_of) -> np.ndarray:
    """:func:`tach_pulse_times` of a file's tach column, its errors named as the caller knows
    the options, and a pulse train whose pulses come irregularly (noise on a slow edge counted
    as extra pulses) refused with what to set, before the TSA fails on it."""
    finite = col[np.isfinite(col)]
    if finite.size < col.size and finite.size >= 2 and np.all(np.diff(finite) > 0):
        # increasing numbers padded with NaN: a list of pulse times, not a sampled pulse train
        raise InputError(name_of("tach"), f"{finite.size} increasing values and "
                         f"{col.size - finite.size} NaN",
                         "a sampled pulse train; the column looks like a list of pulse times "
                         f"[s]: pass {name_of('tach_column_is_pulse_times')}")
    try:
        times = tach_pulse_times(col, fs=fs, time=time, threshold=threshold,
                                 min_interval=min_interval, edge=edge)
    except InputError as exc:
        field = {"threshold": "tach_threshold", "min_interval": "tach_min_interval",
                 "edge": "tach_edge"}.get(exc.field, exc.field)
        raise InputError(name_of(field), exc.value, exc.allowed) from None
    if times.size >= 4:
        # a pulse less than half its neighbours' interval after the one before: chatter, not
        # a speed change (a run-up changes the interval by a small factor from pulse to pulse)
        gaps = np.diff(times)
        neighbour = np.maximum(np.r_[gaps[1], gaps[:-1]], np.r_[gaps[1:], gaps[-2]])
        # an interval well over its regular neighbours': a pulse missed (the regular intervals
        # beside it then look "too soon", and --tach-min-interval did not help: a user audit)
        # (only a few, each of a few intervals, in a train whose other intervals are all within
        # 30 % of the median: not a run-up, nor chatter, whose short intervals come below)
        typ = float(np.median(gaps))
        is_long = gaps > 1.6 * typ
        if (0 < np.count_nonzero(is_long) <= max(1, gaps.size // 10)
                and np.all(gaps[is_long] < 10.5 * typ)
                and np.all(np.abs(gaps[~is_long] / typ - 1) < 0.3)):
            k = int(np.flatnonzero(is_long)[0])
            missed = max(1, round(gaps[k] / typ) - 1)
            raise InputError(
                name_of("tach"), f"{times.size} pulses, {int(np.count_nonzero(is_long))} "
                                 "interval(s) with a pulse missing",
                f"a pulse train without missing pulses (after the pulse at t = {times[k]:.6g} s "
                f"the next comes {gaps[k]:.4g} s later, {gaps[k] / typ:.3g} times the regular "
                f"interval: about {missed} pulse{'s' if missed > 1 else ''} missed); lower "
                f"{name_of('tach_threshold')} (now {tach_threshold_level(col, threshold):.6g}) "
                "if a pulse is too small to cross it, or diagnose the parts before and after "
                "the gap as records of their own")
        is_short = gaps < 0.5 * neighbour
        short = int(np.count_nonzero(is_short))
        if short:
            med = float(np.median(gaps[~is_short])) if short < gaps.size else float(gaps.max())
            raise InputError(
                name_of("tach"), f"{times.size} pulses, {short} too soon",
                f"a pulse train with one edge per pulse ({short} pulses came less than half "
                "their neighbours' interval after the one before: noise on a slow edge, or a "
                "second edge, crosses the threshold "
                f"{tach_threshold_level(col, threshold):.6g} again); "
                f"set {name_of('tach_min_interval')} (e.g. {0.5 * med:.3g} s, half the "
                f"regular interval), {name_of('tach_threshold')} or {name_of('tach_edge')}")
    return times

def _namer(option_names: Mapping[str, str] | None) -> Callable[[str], str]:
    """``name_of(argument)``: the name an error message gives an argument (its own by
    default, e.g. the command-line option when the CLI passes ``option_names``)."""
    names = dict(option_names or {})
    return lambda key: names.get(key, key)


def _same_rate(a: float, b: float) -> bool:
    """Two sample rates [Hz] equal up to rounding (a rate typed as "51.2 kHz", one computed
    from a time axis)."""
    return math.isclose(float(a), float(b), rel_tol=1e-9)


def _entry(entries: Mapping[str, Any], key: str, default=None):
    """``key`` of a file's entries, at the top or in an ``attrs`` struct (``.mat`` records of
    ``geardyn measure`` keep their attributes there)."""
    return entries.get(key, entries.get(f"attrs.{key}", default))


def _pulses_per_rev(path, scalars: Mapping[str, float], given: int | None,
                    name_of: Callable[[str], str]) -> int:
    """Tachometer pulses per revolution: ``given``, else the file's ``tach_pulses_per_rev``,
    else 1. A ``given`` value that contradicts the file's is refused (a wrong count scales
    every order of the TSA: nothing to diagnose with it)."""
    stored = _entry(scalars, "tach_pulses_per_rev")
    ok = (stored is not None and not isinstance(stored, bool) and np.isfinite(stored)
          and stored >= 1 and float(stored) == int(stored))
    if given is None:
        return int(stored) if ok else 1
    value = _check_int(given, name_of("pulses_per_rev"), 1)
    if ok and value != int(stored):
        raise InputError(name_of("pulses_per_rev"), value,
                         f"{Path(path).name}'s own count, {int(stored)} (its tach_pulses_per_"
                         f"rev), or no {name_of('pulses_per_rev')}: the file states it")
    return value


def _stored_teeth(scalars: Mapping[str, float], text: Mapping[str, str],
                  shaft: str) -> int | None:
    """Teeth of the ``shaft`` ("pinion" or "gear") as a file says: a ``<shaft>_teeth`` entry,
    else ``<shaft>.teeth`` of the case TOML it stores (``case_toml``); None if it says neither
    (or says it in a form that is not a positive whole number)."""
    def whole(v) -> int | None:
        if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
            return None
        return int(v) if np.isfinite(v) and v >= 1 and float(v) == int(v) else None

    value = _entry(scalars, f"{shaft}_teeth")
    if value is not None:
        return whole(value)
    toml = _entry(text, "case_toml")
    if not toml:
        return None
    from ..config import parse_case_toml
    from ..errors import GeardynError

    try:
        raw = parse_case_toml(toml, "case_toml")
    except GeardynError:
        return None
    teeth = raw.get(shaft, {}).get("teeth") if isinstance(raw.get(shaft), dict) else None
    if isinstance(teeth, dict):  # { value = 23, source = "..." }
        teeth = teeth.get("value")
    return whole(teeth)


def load(path, **kwargs) -> Measurement:
    """:func:`load_simulation` for NetCDF files (``.nc``...), else :func:`load_measurement`
    (also for a NetCDF file when a ``tach`` channel is named, as for measured data)."""
    if Path(path).suffix.lower() in NETCDF_SUFFIXES and kwargs.get("tach") is None:
        return load_simulation(path, **kwargs)
    return load_measurement(path, **kwargs)
