"""The report's sections on the case: what differs from the paper's case, every value of the
case with its source, and what ``--quick`` changed (split from :mod:`.paper_report`).

Reads a case and the study's summary; renders text for :class:`~.report.Report`. Each value is
shown with its unit, a fault as ``key = value`` fields, a count as a whole number.
"""

from __future__ import annotations

from ..config import Case, case_to_toml
from .report import Report

__all__ = ["case_sections", "used_case", "quick_sentence"]


#: Case values that count something, by key, with the unit shown after the count: the schema
#: holds them as floats (``simulation.max_steps = 1e8``), the report as integers.
COUNT_UNITS = {"simulation.max_steps": "steps"}


def _tidy_quantity(value) -> str:
    """A value of a fault entry as case.toml writes it (``"0.0001 m"``), its number to 12
    significant digits (``"2.9999999999999997e-05 m"`` -> ``"3e-05 m"``)."""
    if isinstance(value, float):
        return f"{value:.12g}"
    text = str(value)
    number, _, unit = text.partition(" ")
    try:
        x = float(number)
    except ValueError:
        return text
    return f"{x:.12g} {unit}".strip()


def _faults_text(entries) -> str:
    """A faults list (case.toml's ``[[faults]]`` tables) as the report shows it: one ``key =
    value`` list per fault, with units, fields left unset omitted, faults separated by "; ";
    "none" for an empty list."""
    return "; ".join(", ".join(f"{k} = {_tidy_quantity(v)}" for k, v in entry.items()
                               if v is not None)
                     for entry in entries) or "none"


def _unit_of(key: str) -> str:
    """The unit of a case field's plain numbers: its dimension's SI unit (``"Hz"`` for
    ``measurement.mode_frequencies``), else the last bracketed unit of its description
    (``"dB"`` for ``measurement.snr``, ``"(m/s^2)/N"`` for ``measurement.mode_gains``); "" for
    a dimensionless field (``[-]``) or one that states none."""
    import re

    from ..config.loading import _field_description
    from ..config.models import DIMENSIONS, _field_dimension

    dim = _field_dimension(key)
    if dim is not None:
        return DIMENSIONS[dim].si_unit
    units = [u for u in re.findall(r"\[([^\]]+)\]", _field_description(tuple(key.split("."))))
             if "," not in u and u.strip() != "-"]
    return units[-1].strip() if units else ""


def _number_text(x) -> str:
    """A number of the case table: an integer as it is, a float to 10 significant digits
    (``69000000000.0`` -> ``6.9e+10``, ``1.0`` -> ``1``; case.toml keeps every digit)."""
    return str(x) if isinstance(x, int) else f"{x:.10g}"


def _value_text(key: str, value) -> str:
    """A case value (as case.toml holds it: quantities as SI unit strings) as the case table
    shows it: a faults list as :func:`_faults_text`, a count of :data:`COUNT_UNITS` as an
    integer with its unit, an unset value as "not set", a boolean as TOML writes it (``true``),
    a number with its unit (:func:`_unit_of`) to 10 significant digits, an angle in radians with
    its degrees beside (``0.3490658504 rad (20 deg)``); no Python ``None`` or list/dict repr."""
    if value is None:
        return "not set"
    if isinstance(value, bool):
        return "true" if value else "false"
    if key in COUNT_UNITS and isinstance(value, (int, float)) and float(value).is_integer():
        return f"{int(value):,} {COUNT_UNITS[key]}"
    if isinstance(value, list) and all(isinstance(v, dict) for v in value):
        return _faults_text(value)

    def numbers(v):
        return (_number_text(v) if isinstance(v, int | float) and not isinstance(v, bool)
                else "[" + ", ".join(numbers(w) for w in v) + "]" if isinstance(v, list)
                else str(v))

    if isinstance(value, int | float | list):
        unit = _unit_of(key)
        return f"{numbers(value)} {unit}".strip()
    number, _, unit = str(value).partition(" ")
    try:
        x = float(number)
    except ValueError:
        return str(value)
    text = f"{_number_text(x)} {unit}".strip()
    if unit == "rad" and x != 0:
        import math

        text += f" ({math.degrees(x):.6g} deg)"
    return text


def _case_rows(case: Case) -> list[tuple[str, str, str]]:
    """(key, value, source) for every value of the case, in file order; values as
    :func:`_value_text` renders them (SI, with units)."""
    text = case_to_toml(case)
    import tomllib

    data = tomllib.loads(text)
    rows: list[tuple[str, str, str]] = []

    def walk(node, prefix):
        for k, v in node.items():
            key = f"{prefix}.{k}" if prefix else k
            if isinstance(v, dict) and not ("value" in v and set(v) <= {"value", "source"}):
                walk(v, key)
            elif isinstance(v, dict):
                rows.append((key, _value_text(key, v["value"]), v.get("source", "")))
            elif key in ("name", "description", "extends"):
                continue
            else:
                rows.append((key, _value_text(key, v),
                             case.provenance.get(key, "geardyn default (schema default)")))

    walk(data, "")
    return rows


_GEOMETRY_KEYS = ("pinion.teeth", "gear.teeth", "pair.module", "pair.pressure_angle",
                  "pair.addendum_coefficient", "pair.dedendum_coefficient",
                  "pinion.profile_shift", "gear.profile_shift")


#: Source notes of the shipped case that state numbers computed for its inputs, by key: the
#: inputs (key prefixes) they were computed from. Off that case, a note whose inputs changed is
#: shown as the shipped case's, not as a fact of this case (:func:`_case_table_rows`).
SHIPPED_NOTE_INPUTS = {
    "pair.face_width": (*_GEOMETRY_KEYS, "pair.face_width", "material."),
    "pinion.profile_shift": _GEOMETRY_KEYS,
    "pinion.bore_radius": (*_GEOMETRY_KEYS, "pinion.bore_radius"),
    "pinion.bearing_damping_ratio": ("pinion.mass", "pinion.bearing_stiffness"),
    "load.speed": ("motor.torque", "load.speed"),
    "crack.enabled": ("crack.", "faults"),
    "crack.gear": ("crack.", "faults"),
    "crack.tooth": (*_GEOMETRY_KEYS, "crack.", "faults"),
    "stiffness.foundation_half_angle": ("pinion.teeth", "gear.teeth"),
    "simulation.dt": ("pinion.teeth", "load.speed", "simulation.dt"),
    "simulation.record_time": ("load.speed", "simulation.record_time"),
    "measurement.fs": ("pinion.teeth", "load.speed", "simulation.dt", "measurement.fs"),
    "measurement.tach_jitter": ("load.speed",),
    # notes that quote the paper's 1.07 mm operating point, which the load, the bearings and
    # the geometry set (unflagged in another case's report: a user audit, 2026-11-27)
    "pinion.torsional_damping": (*_GEOMETRY_KEYS, "motor.torque", "pinion.bearing_stiffness",
                                 "gear.bearing_stiffness"),
    "stiffness.centre_distance_min": (*_GEOMETRY_KEYS, "motor.torque",
                                      "pinion.bearing_stiffness", "gear.bearing_stiffness"),
}


def _case_table_rows(case: Case, changed: list[str],
                     used: Case | None = None) -> list[tuple[str, str, str]]:
    """:func:`_case_rows` as the report shows them: a section switched off (``enabled =
    false``) says its values are not used, and a note carried over from the shipped case whose
    inputs ``changed`` (keys of the differences from it) is marked as the shipped case's, with
    the shipped values it was written for. A value the run did not use (``used``: the case as
    the run simulated and mapped it, e.g. with ``--quick``'s shorter records) is shown as the
    case's and the one used: ``"1.0 s; used with --quick: 0.3 s"``."""
    from ..config import paper_case

    ref_case = paper_case()
    ref = {k: (v, s) for k, v, s in _case_rows(ref_case)}
    rows = _case_rows(case)
    if used is not None:
        ran = {k: v for k, v, _ in _case_rows(used)}
        rows = [(k, v if ran.get(k, v) == v else f"{v}; used with --quick: {ran[k]}", s)
                for k, v, s in rows]
    off = {k.rsplit(".", 1)[0] for k, v, _ in rows
           if k.endswith(".enabled") and v == "false"}
    out = []
    for key, value, source in rows:
        section = key.rsplit(".", 1)[0]
        if section in off and not key.endswith(".enabled"):
            source = f"not used ({section}.enabled = false); value from: {source}"
        elif key in SHIPPED_NOTE_INPUTS and ref.get(key, (None, None))[1] == source:
            hit = [c for c in changed
                   if any(c == p or (p.endswith(".") and c.startswith(p))
                          for p in SHIPPED_NOTE_INPUTS[key])]
            if hit:
                was = ", ".join(f"{c} = {_short_value(_get(ref_case, c))}" for c in hit)
                source = f"{source} [note of the shipped case, for its {was}: not about this case]"
        out.append((key, value, source))
    return out


def used_case(case: Case, s: dict) -> Case:
    """The case as the run simulated and mapped it: ``case`` with the settings ``--quick``
    changed (``summary["quick_settings"]``, SI values); ``case`` itself without them."""
    changed = {d["key"]: d["used"] for d in s.get("quick_settings", [])}
    return case.with_overrides(changed, source="--quick") if changed else case


def quick_sentence(case: Case, s: dict) -> str:
    """What ``--quick`` changed, with the numbers (e.g. "--quick shortened the records and
    coarsened the stiffness maps: simulation.record_time = 0.3 s (the case: 1.0 s), ..."); ""
    when it changed nothing."""
    changed = [d["key"] for d in s.get("quick_settings", [])]
    if not changed:
        return ""
    was = {k: v for k, v, _ in _case_rows(case)}
    now = {k: v for k, v, _ in _case_rows(used_case(case, s))}
    what = [w for w, prefix in (("shortened the records", "simulation."),
                                ("coarsened the stiffness maps", "stiffness."))
            if any(k.startswith(prefix) for k in changed)]
    return (f"--quick {' and '.join(what) or 'changed numerical settings'}: "
            + ", ".join(f"{k} = {now.get(k)} (the case: {was.get(k)})" for k in changed) + ".")


#: Differences (:func:`~.paper_values.case_differences`) whose value is computed for the run,
#: not read from case.toml, with their SI unit: shown as the number and the unit.
_COMPUTED_UNITS = {"stiffness.fe.torque": "N m"}


def _difference_text(key: str, value, case: Case) -> str:
    """A value of the differences tables as the case table shows it, with its unit: read from
    ``case`` (the paper's, this case or the case as run) when case.toml holds it, so a faults
    list reads as its fields and the paper's empty one as "none"."""
    from .report import fmt

    if isinstance(value, bool):
        return _value_text(key, value)
    if key in _COMPUTED_UNITS:
        return "not set" if value is None else f"{fmt(value)} {_COMPUTED_UNITS[key]}"
    shown = {k: v for k, v, _ in _case_rows(case)}
    if key == "faults":
        text = shown.get(key, "none")
        if text == "none" and case.active_crack is not None:
            text = (f"none besides the [crack] section's {_fault_description(case)}")
        return text
    if key in shown:
        return shown[key]
    return _value_text(key, _set_fields(value))


def _get(case: Case, key: str):
    """The value of a dotted key of ``case`` (None where absent)."""
    node = case
    for part in key.split("."):
        node = getattr(node, part, None)
        if node is None:
            return None
    if isinstance(node, list):
        return [v.model_dump() if hasattr(v, "model_dump") else v for v in node]
    return node


def _fault_description(case: Case) -> str:
    """The case's faults in a few words, e.g. "spall on pinion tooth 11"."""
    parts = [f"{f.get('type')} on {f.get('gear') or 'pinion'} tooth {f.get('tooth')}"
             for f in (_get(case, "faults") or []) if isinstance(f, dict)]
    if case.active_crack is not None:
        parts.insert(0, f"{case.crack.depth * 1e3:g} mm root crack on {case.crack.gear} tooth "
                        f"{case.crack.tooth}")
    return ", ".join(parts) or "no fault: the same pair as the healthy one"


def _short_value(value) -> str:
    """A changed input as the title shows it: a faults list as its types and places, other
    values as they are."""
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return "[" + ", ".join(f"{v.get('type')} on {v.get('gear', 'pinion')} tooth "
                               f"{v.get('tooth')}" for v in value) + "]"
    return str(value)


def _set_fields(value):
    """A changed input for the differences table: each entry of a faults list with the fields
    it sets (SI values), without the many it leaves unset (``None``)."""
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return "; ".join(", ".join(f"{k} = {v}" for k, v in entry.items() if v is not None)
                         for entry in value)
    return value


def _own_case_title(case: Case, diffs: list[dict]) -> tuple[str, str]:
    """Title and subtitle of the report of a case that is not the paper's.

    The title names the case and its first changes; a description inherited from the shipped
    case (``--set`` overrides) is left out: it would be false (e.g. "23/23 spur pair").
    """
    from ..config import paper_case

    ref = paper_case()
    name = f"'{case.name}'"
    if diffs:
        shown = ", ".join(f"{d['key']} = {_short_value(d['case'])}" for d in diffs[:3])
        name += f": {shown}" + (f" and {len(diffs) - 3} more changes" if len(diffs) > 3 else "")
    desc = case.description
    if desc.startswith(ref.description):  # inherited; keep only what was added (e.g. "[changed
        desc = desc[len(ref.description):].strip()  # by --set: ...]")
    desc = f"{desc} | " if desc else ""
    return (f"geardyn: case {name}",
            f"{desc}the study of Xue & Howard (2018) applied to this case; its inputs differ "
            "from the paper's (listed below), so nothing here is compared with the paper's "
            "values")


def case_sections(rep: Report, case: Case, s: dict) -> Case:
    """The report's sections on the case: what differs from the paper's case (inputs, then the
    numerical settings as the run used them) and every value of the case with its source, the
    values ``--quick`` changed shown as the case's and the one used.

    Parameters
    ----------
    rep : Report
        The report the sections are added to.
    case : Case
        The user's case (as case.toml holds it).
    s : dict
        The summary: ``differences_from_paper``, ``numerical_differences`` and
        ``quick_settings`` (:func:`geardyn.studies.paper.run_paper_study`).

    Returns
    -------
    Case
        The case as the run simulated and mapped it (:func:`used_case`).
    """
    from ..config import paper_case

    diffs = s.get("differences_from_paper", [])
    numerical = s.get("numerical_differences", [])
    ref_case, run_case = paper_case(), used_case(case, s)
    if diffs:
        rep.heading("What differs from the paper's case")
        rep.paragraph("These inputs differ from Xue & Howard's case (SI values), so this "
                      "report does not compare its results with the paper's.")
        rep.table(["key", "paper's case", "this case"],
                  [[d["key"], _difference_text(d["key"], d["paper"], ref_case),
                    _difference_text(d["key"], d["case"], case)] for d in diffs],
                  left_columns=1)
    if numerical:
        rep.table(["numerical setting", "paper case's default", "this run"],
                  [[d["key"], _difference_text(d["key"], d["paper"], ref_case),
                    _difference_text(d["key"], d["case"], run_case)
                    + (f" (--quick; the case: "
                       f"{_difference_text(d['key'], d['without_quick'], case)})"
                       if "without_quick" in d else "")] for d in numerical],
                  left_columns=1,
                  caption="Numerical settings that differ from the shipped case, as this run "
                          "used them (they change the resolution or the method, not the case)")

    rep.heading("The case and every assumption")
    rep.paragraph("Every value of the case with its source. Values marked 'geardyn default' "
                  "(in amber) are not given by the paper; the source says what geardyn chose "
                  "and why.")
    quick = quick_sentence(case, s)
    if quick:
        rep.note(f"{quick} The table shows such a value as the case's and the one used ('used "
                 "with --quick'); case.toml holds the case as given, without them. Run without "
                 "--quick for the case's own settings.")
    rows = _case_table_rows(case, [d["key"] for d in diffs], used=run_case)
    rep.table(["key", "value (SI)", "source"], rows, left_columns=3,
              classes=[["", "", "assume" if r[2].startswith("geardyn") else ""] for r in rows])
    return run_case
