"""The paper's case study, end to end: ``geardyn run``.

Stages run in order, each adding to the summary and to the output folder:

1. ``geometry``: the pair at its design centre distance, at the paper's FE centre distances
   (+0.5, +1.0 mm) and at the static operating point under the input torque (eq. 4).
2. ``stiffness``: the mesh stiffness maps K(theta, d), healthy and with the crack (Figs. 5, 6).

Later stages (stiffness maps, model I / II simulations, diagnostics, the HTML report) are added to
this same pipeline.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import Case, case_to_toml, paper_case
from ..geometry import geometry_summary, static_operating_point
from ..io import write_json_atomic, write_text_atomic

__all__ = ["run_paper_study", "StudyResult", "PAPER_VALUES"]

Progress = Callable[[str, int, int], None]

#: Values the paper reports, used in the validation table (quantity -> (value, where)).
PAPER_VALUES = {
    "design_centre_distance_mm": (138.0, "Table 1"),
    "design_contact_ratio": (1.59, "Table 1"),
    "base_radius_sum_mm": (129.7, "Table 1 ('base radius', erratum 1: the sum of both)"),
    "centre_distance_change_mm": (1.07, "section 4.1, Fig. 8a ('around 1.07 mm')"),
    "operating_pressure_angle_deg": (21.18, "section 4.1, Fig. 8b"),
    "contact_ratio_paper_eq8": (1.43, "section 4.1, Fig. 8c (eq. 8)"),
}


@dataclass
class StudyResult:
    """What a study run produced.

    Attributes
    ----------
    out : Path
        Output folder.
    summary : dict
        The content of ``summary.json``.
    stages : list of str
        Stages completed.
    seconds : dict of str -> float
        Wall time per stage [s].
    """

    out: Path
    summary: dict = field(default_factory=dict)
    stages: list[str] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)
    maps: dict = field(default_factory=dict)
    figures: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    progress: Progress | None = None

    def sub_progress(self, stage: str) -> Callable[[int, int], None] | None:
        """A ``progress(done, total)`` callback reporting under ``stage``."""
        if self.progress is None:
            return None
        cb = self.progress
        return lambda done, total: cb(stage, done, total)


def _validation_row(quantity: str, paper: float, geardyn: float, tolerance: float,
                    note: str = "") -> dict:
    return {"quantity": quantity, "paper": paper, "geardyn": geardyn, "tolerance": tolerance,
            "pass": bool(abs(geardyn - paper) <= tolerance), "note": note}


def geometry_stage(case: Case, out: Path, result: StudyResult) -> None:
    """Geometry at the design, +0.5 mm, +1.0 mm and static operating centre distances."""
    pair = case.gear_pair()
    static = static_operating_point(pair, case.motor.torque, case.pinion.bearing_stiffness,
                                    case.gear.bearing_stiffness)
    report = {
        "design": geometry_summary(pair, 0.0),
        "dd_0.5mm": geometry_summary(pair, 0.5e-3),
        "dd_1.0mm": geometry_summary(pair, 1.0e-3),
        "static_operating_point": geometry_summary(pair, static.centre_distance_change),
    }
    write_json_atomic(out / "geometry.json", report)
    s = result.summary
    s["centre_distance_change_mm"] = static.centre_distance_change * 1e3
    s["operating_pressure_angle_deg"] = math.degrees(static.pressure_angle)
    s["contact_ratio"] = {"physical": static.contact_ratio, "paper_eq8": static.contact_ratio_eq8}
    s.setdefault("sources", {})["centre_distance_change_mm"] = (
        "static equilibrium, rigid teeth (geometry stage): N = T/r_b1 on the bearings, eq. 4")
    val = s.setdefault("validation", [])
    pv = PAPER_VALUES
    val += [
        _validation_row("design centre distance [mm]", pv["design_centre_distance_mm"][0],
                        pair.design_centre_distance * 1e3, 1e-9),
        _validation_row("design contact ratio", pv["design_contact_ratio"][0],
                        report["design"]["operating"]["contact_ratio"]["physical"], 0.005,
                        "paper quotes 2 decimals"),
        _validation_row("base radius sum [mm] (Table 1 '129.7')", pv["base_radius_sum_mm"][0],
                        pair.base_radius_sum * 1e3, 0.05, "erratum 1: Table 1's value is the sum"),
        _validation_row("static centre distance change [mm]",
                        pv["centre_distance_change_mm"][0], static.centre_distance_change * 1e3,
                        0.02, "paper: 'around 1.07 mm' from its simulation; geardyn's static "
                              "value has zero absolute torsional damping"),
        _validation_row("static operating pressure angle [deg]",
                        pv["operating_pressure_angle_deg"][0], math.degrees(static.pressure_angle),
                        0.02),
        _validation_row("static contact ratio, paper eq. 8", pv["contact_ratio_paper_eq8"][0],
                        static.contact_ratio_eq8, 0.005, "physical value "
                        f"{static.contact_ratio:.4f} (erratum 2)"),
    ]


def stiffness_stage(case: Case, out: Path, result: StudyResult) -> None:
    """Healthy and cracked stiffness maps (cached), NetCDF files and the Figs. 5-6 analogues."""
    import json
    import warnings

    from ..stiffness import build_map
    from ..stiffness.plots import crack_angle, fig_crack, fig_load_sharing, fig_stiffness

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the maps record their warnings in attrs (read below)
        healthy = build_map(case, cracked=False, progress=result.sub_progress("stiffness (healthy)"))
        cracked = build_map(case, cracked=True, progress=result.sub_progress("stiffness (cracked)"))
    for m in (healthy, cracked):
        w = m.attrs.get("warnings", "[]")
        for text in (json.loads(w) if isinstance(w, str) else list(w)):
            if text not in result.notes:
                result.notes.append(text)
    result.maps = {"healthy": healthy, "cracked": cracked}
    healthy.to_netcdf(out / "stiffness_healthy.nc")
    cracked.to_netcdf(out / "stiffness_cracked.nc")
    result.figures["fig5_stiffness"] = fig_stiffness(healthy)
    result.figures["fig5_load_sharing"] = fig_load_sharing(healthy)
    if case.crack is not None and case.crack.enabled:
        result.figures["fig6_crack"] = fig_crack(healthy, cracked)
        result.summary["crack_angle_in_stiffness_deg"] = math.degrees(
            crack_angle(healthy, cracked, 0.0))
    th = np.linspace(0.0, healthy.period, 4096, endpoint=False)
    result.summary["mean_mesh_stiffness_N_per_m"] = {
        f"{dd * 1e3:+.1f}mm": float(np.mean(healthy(th, dd))) for dd in (0.0, 0.5e-3, 1.0e-3)
        if healthy.covers(dd)}


STAGES: list[tuple[str, Callable[[Case, Path, StudyResult], None]]] = [
    ("geometry", geometry_stage),
    ("stiffness", stiffness_stage),
]


def run_paper_study(case: Case | None = None, out: str | Path = "geardyn-out", *,
                    quick: bool = False, stiffness: str | None = None,
                    progress: Progress | None = None) -> StudyResult:
    """Reproduce the paper's case study into ``out``.

    Parameters
    ----------
    case : Case, optional
        Default: the paper's case.
    out : path-like
        Output folder (created).
    quick : bool
        Shorter simulations and coarser maps, for a fast look.
    stiffness : {"fe", "pem"}, optional
        Stiffness method; default the case's.
    progress : callable, optional
        ``progress(stage, done, total)``.

    Returns
    -------
    StudyResult
    """
    case = case or paper_case()
    if stiffness is not None:
        case = case.with_overrides({"stiffness.method": stiffness})
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    result = StudyResult(out=out, progress=progress)
    result.summary.update({"case": case.name, "quick": quick,
                           "stiffness_method": case.stiffness.method, "complete": False})
    write_text_atomic(out / "case.toml", case_to_toml(case))
    for i, (name, stage) in enumerate(STAGES):
        if progress:
            progress(name, i, len(STAGES))
        t0 = time.perf_counter()
        stage(case, out, result)
        result.seconds[name] = time.perf_counter() - t0
        result.stages.append(name)
        result.summary["stages"] = list(result.stages)
        write_json_atomic(out / "summary.json", result.summary)
    if progress:
        progress("done", len(STAGES), len(STAGES))
    result.summary["complete"] = True
    result.summary["run_time_s"] = dict(result.seconds)
    write_json_atomic(out / "summary.json", result.summary)
    return result
