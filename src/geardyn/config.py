"""Case files: validated parameter sets with units and provenance.

A case is a TOML file read with :mod:`tomllib` and validated by the pydantic models below
(``extra="forbid"``: a misspelt key is an error, not a silent default). Quantities accept a bare
number (SI) or a unit string (``"6 mm"``, ``"20 deg"``, ``"1e6 N/m"``, ``"100 N m"``) and are
stored as SI floats. Any value may be written as ``{ value = ..., source = "..." }`` to record
where it comes from; the shipped paper case does this for every entry, and the sources are kept in
:attr:`Case.provenance` (and shown by ``geardyn config show`` and in the report).

Overrides use dotted keys, ``--set pinion.teeth=25`` or ``--set simulation.dt="5e-6 s"``; the
value is read as a TOML value when it parses as one, otherwise as a string.

Partial case files (issue 13): a file gives only what it changes over a base case, ``extends =
"xue_howard"`` (the default), another shipped case, or another case file relative to it (chains
up to :data:`MAX_EXTENDS`, cycles refused); ``extends = false`` marks a complete case (what
:func:`case_to_toml` writes). Values from a base keep their source, values of an extending file
without a source get the file's path, overrides get ``"--set"``; :func:`load_case_details` also
keeps the values as written and each value's origin for ``geardyn config show``.

Bounded input (issue 19): a case file must be a regular file of at most :data:`MAX_CASE_BYTES`
bytes of UTF-8, nested at most :data:`MAX_NESTING` deep; ``--set`` values at most
:data:`MAX_OVERRIDE_CHARS` characters; user strings (names, descriptions, sources) may not hold
control characters (tab excepted). Case files are written with tomli-w.
"""

from __future__ import annotations

import copy
import functools
import json
import math
import os
import re
import stat
import tomllib
import typing
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    WithJsonSchema,
    field_validator,
    model_validator,
)

from .errors import DataFileError, InputError
from .units import DIMENSIONS, format_si, to_si

__all__ = [
    "Case",
    "load_case",
    "paper_case",
    "case_to_toml",
    "case_schema",
    "case_file_schema",
    "parse_overrides",
    "PAPER_CASE",
    "CaseDetails",
    "load_case_details",
    "with_written_value",
    "case_to_display_toml",
    "read_case_text",
    "parse_case_toml",
    "check_text",
    "shipped_cases",
    "MAX_CASE_BYTES",
    "MAX_NESTING",
]

PAPER_CASE = "xue_howard"


# --------------------------------------------------------------------------- quantities
class _QuantityJsonSchema(WithJsonSchema):
    """:class:`pydantic.WithJsonSchema` that hands out a copy of its schema each time: pydantic
    2.6 returned the dict itself and then wrote a field's constraints into it (``gt: 0``), so
    every later schema showed one field's constraint on all quantities of that dimension and
    two calls of :func:`case_file_schema` differed (found by the dependency floors' run)."""

    def __get_pydantic_json_schema__(self, core_schema, handler):
        return copy.deepcopy(super().__get_pydantic_json_schema__(core_schema, handler))


def _quantity(dimension: str):
    dim = DIMENSIONS[dimension]

    def parse(v: Any) -> float:
        try:
            return to_si(v, dimension, "value")
        except InputError as exc:
            raise ValueError(exc.allowed) from None

    schema = {
        "anyOf": [{"type": "number"}, {"type": "string"}],
        "description": f"{dim.name}: a number in {dim.si_unit} or a string with a unit, "
                       f"e.g. {dim.example!r}",
        "x-unit": dim.si_unit,
        "x-dimension": dim.name,
    }
    return Annotated[float, BeforeValidator(parse), _QuantityJsonSchema(schema)]


Length = _quantity("length")
Angle = _quantity("angle")
Mass = _quantity("mass")
Inertia = _quantity("inertia")
Stiffness = _quantity("stiffness")
Damping = _quantity("damping")
TorsionalStiffness = _quantity("torsional stiffness")
TorsionalDamping = _quantity("torsional damping")
Torque = _quantity("torque")
Pressure = _quantity("pressure")
Time = _quantity("time")
AngularVelocity = _quantity("angular velocity")
QuadraticCoefficient = _quantity("quadratic torque coefficient")

class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True)


# --------------------------------------------------------------------------- sections
class PairConfig(_Model):
    """Tooth system shared by both gears (ISO 53 basic rack by default)."""

    module: Length = Field(gt=0, description="Module m [m].")
    pressure_angle: Angle = Field(description="Pressure angle of the basic rack [rad], (0, 35 deg].")
    addendum_coefficient: float = Field(1.0, gt=0, le=2, description="h_a* [-].")
    dedendum_coefficient: float = Field(1.25, gt=0, le=3, description="h_f* [-].")
    tool_tip_radius_coefficient: float | None = Field(
        None, ge=0, description="Rack tip radius rho* [-]; omit for (h_f*-h_a*)/(1-sin alpha).")
    face_width: Length = Field(gt=0, description="Face width b [m] (both gears).")


    @field_validator("pressure_angle")
    @classmethod
    def _pressure_angle(cls, v: float) -> float:
        if not (0 < v <= math.radians(35)):
            raise ValueError(f"a pressure angle in (0, 35] deg (this is {math.degrees(v):.6g} deg)")
        return v


class GearConfig(_Model):
    """One gear: teeth, body, support and rotor data."""

    teeth: int = Field(ge=5, le=1000, strict=True, description="Number of teeth (whole number).")
    profile_shift: float = Field(0.0, ge=-1.5, le=1.5, description="Profile shift x [-].")
    bore_radius: Length = Field(gt=0, description="Bore (hub) radius [m].")
    mass: Mass = Field(gt=0, description="Mass [kg].")
    inertia: Inertia = Field(gt=0, description="Polar moment of inertia [kg m^2].")
    bearing_stiffness: Stiffness = Field(gt=0, description="Bearing stiffness along the LOA [N/m].")
    bearing_damping: Damping | None = Field(
        None, ge=0, description="Bearing damping [N s/m]; omit to use bearing_damping_ratio.")
    bearing_damping_ratio: float = Field(0.05, ge=0, lt=1,
                                         description="Damping ratio of the bearing mode [-].")
    bearing_stiffness_x: Stiffness | None = Field(
        None, gt=0, description="Bearing stiffness across the line of action [N/m] (the "
                                "transverse model, simulation.dynamics = 'transverse'); omit "
                                "for isotropic bearings (= bearing_stiffness).")
    bearing_damping_x: Damping | None = Field(
        None, ge=0, description="Bearing damping across the line of action [N s/m] (transverse "
                                "model); omit: bearing_damping for isotropic bearings, else "
                                "from bearing_damping_ratio and bearing_stiffness_x.")
    torsional_damping: TorsionalDamping = Field(
        0.0, ge=0, description="Absolute torsional damping q_st (drag on absolute speed) "
                               "[N m s/rad].")


class MaterialConfig(_Model):
    """Elastic constants of both gears."""

    youngs_modulus: Pressure = Field(gt=0, description="Young's modulus E [Pa].")
    poisson_ratio: float = Field(gt=0, lt=0.5, description="Poisson's ratio [-].")
    density: _quantity("density") = Field(2700.0, gt=0, description="Density [kg/m^3].")


class CouplingConfig(_Model):
    """A torsional coupling (shaft and coupling) between two rotors."""

    stiffness: TorsionalStiffness = Field(gt=0, description="Torsional stiffness [N m/rad].")
    damping: TorsionalDamping | None = Field(
        None, ge=0, description="Torsional damping [N m s/rad]; omit to use damping_ratio.")
    damping_ratio: float = Field(0.05, ge=0, lt=1, description="Damping ratio of the coupling "
                                                                "mode [-].")


class MotorConfig(_Model):
    """Input: motor rotor and torque law (eq. 9)."""

    inertia: Inertia = Field(gt=0, description="Motor inertia I_m [kg m^2].")
    law: Literal["constant", "induction"] = Field(
        "constant", description="'constant' torque, or an 'induction' motor (Kloss) curve.")
    torque: Torque = Field(gt=0, description="Input torque T_in [N m] (constant law); for the "
                                             "induction law, the rated torque.")
    synchronous_speed: AngularVelocity | None = Field(
        None, gt=0, description="Induction law: synchronous speed [rad/s].")
    breakdown_torque: Torque | None = Field(None, gt=0, description="Induction law: breakdown "
                                                                     "torque [N m].")
    breakdown_slip: float | None = Field(None, gt=0, lt=1, description="Induction law: slip at "
                                                                        "breakdown [-].")
    ripple: float = Field(0.0, ge=0, lt=1, description="Input torque ripple amplitude as a "
                          "fraction of the mean input torque [-] (0: none; issue 14.3).")
    ripple_order: float = Field(1.0, gt=0, le=1000, description="Ripple cycles per motor "
                                                                "revolution [-].")
    ripple_phase: Angle = Field(0.0, description="Phase of the ripple [rad].")
    profile_times: list[float] | None = Field(
        None, description="Speed profile (issue 14.3): times [s], strictly increasing; with "
                          "profile_speeds a piecewise-linear target motor speed, constant beyond "
                          "the ends (two points: a ramp run-up or coast-down). Omit for none.")
    profile_speeds: list[float] | None = Field(None, description="Speed profile: target motor "
                                                                 "speeds [rad/s].")
    drive_gain: TorsionalDamping = Field(
        5.0, gt=0, description="Speed-controlled drive with a profile: T_in = T + gain "
                               "(w_target(t) - w_m) [N m s/rad].")

    @model_validator(mode="after")
    def _induction_fields(self) -> MotorConfig:
        if self.law == "induction":
            for name in ("synchronous_speed", "breakdown_torque", "breakdown_slip"):
                if getattr(self, name) is None:
                    raise ValueError(f"motor.{name} is required with motor.law = 'induction'")
        return self


class LoadConfig(_Model):
    """Output: load rotor and torque law (eq. 16)."""

    inertia: Inertia = Field(gt=0, description="Load inertia I_out [kg m^2].")
    law: Literal["linear", "constant", "quadratic", "table"] = Field(
        "linear", description="T_out = c w ('linear'), T ('constant'), c w^2 ('quadratic') or "
                              "interpolated in a table of speeds and torques ('table').")
    speed: AngularVelocity | None = Field(
        None, gt=0, description="Target mean pinion speed [rad/s]; the law's coefficient is "
                                "calibrated so the steady state runs at it (paper: 114.14 rad/s).")
    coefficient: float | None = Field(
        None, gt=0, description="Law coefficient, SI (N m s/rad linear, N m s^2/rad^2 quadratic, "
                                "N m constant); omit to calibrate from 'speed'.")
    table_speeds: list[AngularVelocity] | None = Field(
        None, description="'table' law: output speeds [rad/s], increasing.")
    table_torques: list[Torque] | None = Field(None, description="'table' law: torques [N m].")

    @model_validator(mode="after")
    def _law_fields(self) -> LoadConfig:
        if self.law == "table":
            sp, tq = self.table_speeds, self.table_torques
            if not sp or not tq or len(sp) != len(tq) or len(sp) < 2:
                raise ValueError("load.table_speeds and load.table_torques must be given with "
                                 "the same length >= 2 for load.law = 'table'")
            if any(b <= a for a, b in zip(sp, sp[1:], strict=False)):
                raise ValueError("load.table_speeds must be strictly increasing")
        elif self.speed is None and self.coefficient is None:
            raise ValueError("give load.speed (to calibrate) or load.coefficient")
        return self


class MeshConfig(_Model):
    """Tooth mesh damping (eq. 14)."""

    damping: Damping | None = Field(None, ge=0, description="Mesh damping q_mb [N s/m]; omit to "
                                                             "use damping_ratio.")
    damping_ratio: float = Field(0.07, ge=0, lt=1, description="Mesh damping ratio with the "
                                                                "equivalent mass [-].")
    friction_coefficient: float = Field(
        0.0, ge=0, le=0.5, description="Coulomb coefficient of sliding friction between the "
                                       "teeth [-] (the transverse model, simulation.dynamics = "
                                       "'transverse'; typical lubricated steel 0.03-0.1).")


class CrackConfig(_Model):
    """A root crack on one tooth."""

    enabled: bool = Field(True, description="Whether the crack is modelled.")
    gear: Literal["pinion", "gear"] = Field("pinion", description="Which gear is cracked.")
    tooth: int = Field(0, ge=0, strict=True, description="Cracked tooth number (0-based, in "
                                                         "mesh order; tooth k passes the pitch "
                                                         "point at pinion angle 2 pi k / z1).")
    depth: Length = Field(ge=0, description="Crack length from the root fillet [m]; 0 is the "
                                            "healthy tooth (a crack of zero size).")
    angle: Angle = Field(math.radians(45), gt=0, lt=math.pi / 2,
                         description="Angle between the crack and the tooth centreline [rad]; the "
                                     "tip is depth*sin(angle) nearer the centreline than the mouth.")
    @property
    def active(self) -> bool:
        """Whether the crack changes the stiffness: enabled and of non-zero depth (a zero-size
        crack is the healthy tooth, issue 15 item 5, so a sweep over depth can start at 0)."""
        return bool(self.enabled) and self.depth > 0.0

    limit_line: Literal["tip", "parallel"] = Field(
        "tip", description="PEM crack limit line: towards the tooth tip (Mohammed et al. 2013) or "
                           "parallel to the centreline (Chen & Shao 2011).")


class FaultConfig(_Model):
    """One tooth fault of the ``faults`` list (geardyn.faults); which keys a type takes:
    root_crack (depth, angle, limit_line, width, front, slices), spall (start and length, or
    roll_start and roll_length, width, depth), breakage (height, width), wear (depth, start and
    length or roll_start and roll_length, stiffness, law)."""

    type: Literal["root_crack", "spall", "breakage", "wear"] = Field(
        description="Fault type.")
    gear: Literal["pinion", "gear"] = Field("pinion", description="Which gear has the fault.")
    tooth: int = Field(0, ge=0, strict=True, description="Faulty tooth (0-based, mesh order).")
    depth: Length | None = Field(None, description="Crack length, spall depth or wear depth [m].")
    angle: Angle | None = Field(None, description="root_crack: angle to the tooth centreline "
                                                  "[rad] (default 45 deg).")
    limit_line: Literal["tip", "parallel"] | None = Field(None, description="root_crack: PEM "
                                                          "limit line (default 'tip').")
    width: Length | None = Field(None, description="Width across the face [m]: cracked width, "
                                                   "spall width or broken width (default: the "
                                                   "whole face for root_crack and breakage).")
    front: Literal["uniform", "linear", "parabolic"] | None = Field(
        None, description="root_crack: depth profile across the cracked width.")
    slices: int | None = Field(None, strict=True, description="root_crack: slices across the "
                                                               "cracked width (default 20).")
    start: Length | None = Field(None, description="spall, wear: roll length of the lower edge "
                                                   "from the base-circle tangency point [m].")
    length: Length | None = Field(None, description="spall, wear: extent in roll length [m].")
    roll_start: Angle | None = Field(None, description="spall, wear: roll angle of the lower "
                                                       "edge [rad].")
    roll_length: Angle | None = Field(None, description="spall, wear: extent in roll angle "
                                                        "[rad].")
    height: Length | None = Field(None, description="breakage: height lost from the tip [m].")
    stiffness: bool | None = Field(None, description="wear: also thin the tooth in the PEM "
                                                     "stiffness (default false).")
    law: Literal["uniform", "archard"] | None = Field(
        None, description="wear: depth along the profile, 'uniform' (default) or 'archard' "
                          "(Archard's law over one mesh: load share times sliding, zero at "
                          "the pitch point; depth is then the largest depth).")


class FEConfig(_Model):
    """Finite-element mesh stiffness settings."""

    torque: Torque | None = Field(
        None, gt=0, description="Pinion hub torque the FE map is built at [N m]; omit for the "
                                "case's operating torque motor.torque (paper: 100), so that a "
                                "sweep over motor.torque gets the map of each torque.")
    definition: Literal["secant", "tangent"] = Field(
        "secant", description="FE mesh stiffness: 'secant' T / dtheta at the torque (the "
                              "paper's FEA) or 'tangent' dT / dtheta there (central difference "
                              "at T (1 +/- 0.05)), the incremental stiffness of small "
                              "fluctuations about the mean load.")
    torques: list[Torque] | None = Field(
        None, description="K(theta, d, F): FE maps at these pinion torques [N m] (at least two, "
                          "increasing, bracketing the operating torque); the dynamics read the "
                          "stiffness at each step's elastic mesh force, interpolated linearly "
                          "between them. Omit for one map at `torque`.")
    plane: Literal["strain", "stress"] = Field("strain", description="Plane strain or stress.")
    mesh_size: Length | None = Field(None, gt=0, description="Element size in the tooth zone "
                                                              "[m]; omit for the default.")
    refinement: float = Field(1.0, gt=0, le=16, description="Mesh refinement factor [-] "
                                                            "(1 = default, 2 = twice as fine).")
    teeth_in_model: int = Field(5, ge=3, strict=True, description="Teeth in each body sector.")
    substructure: bool = Field(
        False, description="Faulty bodies (crack, breakage) by substructuring: the healthy part "
                           "of the faulted gear is condensed once onto an interface below the "
                           "faulty tooth's sector and cached, so each new fault size meshes and "
                           "solves only that sector (about 1 s instead of a whole body's 7 s; "
                           "the first fault pays the condensation, about 2.5 whole bodies). For "
                           "sweeps over fault size. Its mesh differs from the whole-body mesh "
                           "by the discretisation only.")

    @model_validator(mode="after")
    def _torques(self) -> FEConfig:
        t = self.torques
        if t is not None and (len(t) < 2 or any(b <= a for a, b in zip(t[:-1], t[1:],
                                                                         strict=True))
                              or any(not v > 0 for v in t)):
            raise ValueError(f"stiffness.fe.torques = {t}: give at least two increasing "
                             "torques > 0 [N m], or omit it for one map")
        return self


class StiffnessConfig(_Model):
    """Mesh stiffness map K(theta, d)."""

    method: Literal["pem", "fe"] = Field("pem", description="Potential energy method or FE.")
    centre_distance_min: Length = Field(-0.5e-3, description="Lowest centre distance change [m].")
    centre_distance_max: Length = Field(2.0e-3, description="Highest centre distance change [m].")
    centre_distances: int = Field(31, ge=1, le=1001, strict=True,
                                  description="Number of centre distances in the map.")
    nodes_per_segment: int = Field(24, ge=2, le=4096, strict=True,
                                   description="Map nodes in each single/double contact zone.")
    body_torsion: bool = Field(False, description="PEM: add each gear body's elastic torsion "
                                                  "between bore and root circle in series with "
                                                  "the mesh (hub-to-hub stiffness, as FE and the "
                                                  "paper's FEA report it).")
    foundation_half_angle: Literal["fillet", "ross", "alpha3"] | Angle = Field(
        "fillet", description="PEM: root half-angle theta_f of the Sainsot foundation term: "
                              "'fillet' (the generated tooth, 3.013/z), 'ross' (ROSS's 2.831/z), "
                              "'alpha3' (Wan et al.'s root rectangle) or an angle.")
    fe: FEConfig = Field(default_factory=FEConfig)

    @model_validator(mode="after")
    def _range(self) -> StiffnessConfig:
        if self.centre_distance_max < self.centre_distance_min:
            raise ValueError("stiffness.centre_distance_max must be >= centre_distance_min")
        if self.centre_distances > 1 and self.centre_distance_max == self.centre_distance_min:
            raise ValueError("stiffness.centre_distances > 1 needs a non-empty range")
        return self


class SimulationConfig(_Model):
    """Time integration (Newmark) and model choice."""

    model: Literal["I", "I-static", "II"] = Field(
        "II", description="Model I: K(theta) at the design centre distance; I-static: K(theta) at "
                          "the static operating centre distance (eq. 4), held fixed; model II: "
                          "K(theta, d(t)).")
    dynamics: Literal["6-dof", "transverse"] = Field(
        "6-dof", description="'6-dof': the paper's model, centres moving along the line of "
                             "action only; 'transverse': x and y for each centre, the mesh "
                             "force along the operating line of action that turns with the "
                             "centres, and sliding friction (mesh.friction_coefficient).")
    dt: Time = Field(1e-5, gt=0, description="Time step [s].")
    settle_time: Time = Field(0.5, ge=0, description="Simulated time discarded before recording "
                                                     "[s].")
    record_time: Time = Field(1.0, gt=0, description="Recorded time [s].")
    decimation: int = Field(1, ge=1, strict=True, description="Keep every n-th step.")
    max_steps: float = Field(1e8, gt=0, description="Largest number of time steps (settle plus "
                                                    "record) a simulation may take; a longer one "
                                                    "is refused before it starts [-].")
    tolerance: Length = Field(1e-7, gt=0, description="Model II: |b1 - b2| centre distance "
                                                      "tolerance [m] (paper: 0.1 um).")
    rtol: float = Field(1e-9, gt=0, lt=1, description="Model II: relative tolerance on the "
                                                      "acceleration update [-].")
    max_iterations: int = Field(50, ge=1, strict=True, description="Model II: iterations per "
                                                                   "step before failing.")
    stiffness_evaluation: Literal["predictor", "start"] = Field(
        "predictor", description="Model II: stiffness at the Newmark predictor (2nd order) or at "
                                 "the start of the step (the paper's flow chart, 1st order).")
    stiffness_window: Literal["step", "point"] = Field(
        "step", description="Mesh stiffness in each step: 'step' averages the map over the "
                            "step's rotation (a contact handover inside a step counts for the "
                            "part of the step after it; removes the handover-timing jitter that "
                            "otherwise shows in a healthy gear's TSA residual), 'point' samples "
                            "it at the evaluation angle (the paper's flow chart).")
    integrator: Literal["newmark", "hht"] = Field("newmark", description="Average-acceleration "
                                                                         "Newmark or HHT-alpha.")
    hht_alpha: float = Field(-0.05, ge=-1 / 3, le=0, description="HHT alpha in [-1/3, 0].")
    contact_ratio_formula: Literal["physical", "paper_eq8"] = Field(
        "physical", description="Contact ratio reported: physical or the paper's eq. 8.")


class DiagnosticsConfig(_Model):
    """Diagnostics applied to the simulated signals (paper section 4.2)."""

    harmonic: int = Field(5, ge=1, strict=True, description="Mesh harmonic demodulated.")
    bandwidth: int = Field(11, ge=1, strict=True, description="Half band about it [orders].")
    samples_per_rev: int = Field(2048, ge=64, strict=True, description="TSA samples per "
                                                                       "revolution.")
    residual_preset: Literal["paper", "matlab", "zakrajsek"] = Field(
        "paper", description="Which orders the residual removes.")


class MeasurementConfig(_Model):
    """What a housing accelerometer and a tachometer record (geardyn.measurement, issue 14)."""

    fs: _quantity("frequency") = Field(50_000.0, gt=0, description="DAQ sample rate [Hz]; a "
                                       "simple fraction of the simulation rate 1/(dt decimation).")
    mode_frequencies: list[_quantity("frequency")] = Field(
        [3000.0], description="Transfer path: natural frequency of each housing mode [Hz] (0 = "
                              "rigid-body mode); ignored with frf_table.")
    mode_damping_ratios: list[float] = Field([0.05], description="Damping ratio of each mode [-].")
    mode_gains: list[list[float]] = Field(
        [[0.05, 0.1]], description="Gain of each mode per bearing [pinion, gear] [(m/s^2)/N]: "
                                   "the accelerance far above the mode (mode shapes at sensor "
                                   "and bearing over the modal mass).")
    frf_table: str | None = Field(None, description="Transfer path as a measured FRF: a CSV of "
                                  "frequency [Hz] then re, im per bearing [(m/s^2)/N].")
    frf_settling_time: _quantity("time") = Field(0.1, ge=0, description="Memory of the FRF "
                                                 "table's path, discarded as lead-in [s].")
    accelerometer_resonance: _quantity("frequency") | None = Field(
        None, gt=0, description="Mounted resonance of the accelerometer [Hz]; omit for a flat "
                                "sensor.")
    accelerometer_damping_ratio: float = Field(0.02, gt=0, lt=1, description="Its damping "
                                                                              "ratio [-].")
    antialias_cutoff: _quantity("frequency") | None = Field(
        None, gt=0, description="Anti-alias filter cutoff [Hz] (zero-phase Butterworth "
                                "magnitude); omit for 0.4 fs (antialias_order = 0: no filter).")
    antialias_order: int = Field(8, ge=0, le=64, strict=True, description="Butterworth order "
                                                                          "(0 = no filter) [-].")
    adc_bits: int = Field(24, ge=0, le=32, strict=True, description="ADC resolution [bits], "
                                                                    "2..32; 0 = no quantisation.")
    adc_range: _quantity("acceleration") = Field(50 * 9.80665, gt=0, description="ADC range "
                                                 "+/- [m/s^2]; larger samples are clipped.")
    snr: float | None = Field(20.0, description="Signal-to-noise ratio [dB], >= 0 (signal "
                                                "variance over noise variance); inf = no noise.")
    noise_level: _quantity("acceleration") | None = Field(
        None, ge=0, description="Noise RMS [m/s^2], instead of snr.")
    seed: int = Field(0, ge=0, strict=True, description="Seed of the noise and the tachometer "
                                                        "jitter.")
    tach_shaft: Literal["pinion", "gear"] = Field("pinion", description="Shaft the tachometer "
                                                                        "reads.")
    tach_pulses_per_rev: int = Field(1, ge=1, le=10_000, strict=True,
                                     description="Tachometer pulses per revolution [-].")
    tach_jitter: _quantity("time") = Field(0.0, ge=0, description="Trigger jitter, standard "
                                                                  "deviation [s].")
    tach_offset: Angle = Field(0.0, description="Shaft angle of pulse 0 [rad].")
    tach_amplitude: float = Field(5.0, gt=0, description="Pulse height [V].")
    tach_rise_time: _quantity("time") | None = Field(None, ge=0, description="Pulse edge "
                                                     "duration [s]; omit for 3 / fs.")

    @model_validator(mode="after")
    def _modes(self) -> MeasurementConfig:
        n = len(self.mode_frequencies)
        if self.frf_table is None and not (n >= 1 and len(self.mode_damping_ratios) == n
                                           and len(self.mode_gains) == n):
            raise ValueError("measurement.mode_frequencies, mode_damping_ratios and mode_gains "
                             f"must have the same length >= 1 (got {n}, "
                             f"{len(self.mode_damping_ratios)}, {len(self.mode_gains)})")
        if self.frf_table is None and any(len(g) != 2 for g in self.mode_gains):
            raise ValueError("measurement.mode_gains: two gains per mode, [pinion, gear] "
                             "bearing, in (m/s^2)/N")
        return self


class GearErrorsConfig(_Model):
    """Tooth errors and tip relief of one gear (geardyn.modifications); all off by default.

    Deviations are along the line of action, positive where material is missing."""

    grade: int | None = Field(None, ge=1, le=11, strict=True, description="ISO 1328-1:2013 "
                              "flank tolerance class 1-11 to draw pitch and profile deviations "
                              "from; omit for none.")
    seed: int = Field(0, ge=0, strict=True, description="Seed of the drawn deviations.")
    fraction: float = Field(1.0, gt=0, le=1, description="Drawn deviations span this fraction "
                            "of the class's tolerances (cumulative pitch = fraction * F_pT) [-].")
    cumulative_pitch: list[float] | None = Field(None, description="Table: cumulative pitch "
                                                 "deviation of each tooth on the reference circle "
                                                 "[m] (replaces the drawn one).")
    profile_slope: list[float] | None = Field(None, description="Table: profile slope deviation "
                                              "f_Halpha of each tooth [m].")
    profile_form: list[float] | None = Field(None, description="Table: profile form deviation "
                                             "f_falpha (peak-to-valley) of each tooth [m].")
    form_waves: float = Field(2.0, gt=0, le=50, description="Waves of the form deviation over "
                              "the active profile [-].")
    runout: Length = Field(0.0, ge=0, description="Eccentricity (runout amplitude along the LOA) "
                           "[m].")
    runout_phase: Angle = Field(0.0, description="Phase of the eccentricity [rad].")
    tip_relief: Length = Field(0.0, ge=0, description="Tip relief amount C_a at the tip [m].")
    relief_start: Angle | None = Field(None, description="Roll angle where the relief starts "
                                       "[rad]; omit for the highest point of single tooth "
                                       "contact.")
    relief_shape: Literal["linear", "parabolic"] = Field("linear", description="Relief shape.")


class ModificationsConfig(_Model):
    """Tooth errors and relief of both gears (a missing section: perfect involutes)."""

    pinion: GearErrorsConfig = Field(default_factory=GearErrorsConfig)
    gear: GearErrorsConfig = Field(default_factory=GearErrorsConfig)


class Case(_Model):
    """A complete geardyn case: the gear pair, its supports and loads, and the study settings."""

    name: str = Field("case", description="Name of the case.")
    description: str = Field("", description="Free text.")
    pair: PairConfig
    pinion: GearConfig
    gear: GearConfig
    material: MaterialConfig
    motor: MotorConfig
    load: LoadConfig
    input_coupling: CouplingConfig
    output_coupling: CouplingConfig
    mesh: MeshConfig = Field(default_factory=MeshConfig)
    crack: CrackConfig | None = None
    faults: list[FaultConfig] = Field(default_factory=list, description="Tooth faults "
                                      "(geardyn.faults): [[faults]] tables, any number.")
    modifications: ModificationsConfig | None = None
    stiffness: StiffnessConfig = Field(default_factory=StiffnessConfig)
    simulation: SimulationConfig = Field(default_factory=SimulationConfig)
    diagnostics: DiagnosticsConfig = Field(default_factory=DiagnosticsConfig)
    measurement: MeasurementConfig | None = Field(None, description="Sensor chain for "
                                                  "'geardyn measure'; omit for its defaults.")
    provenance: dict[str, str] = Field(default_factory=dict,
                                       description="Source of each value, by dotted key.")

    @field_validator("name", "description")
    @classmethod
    def _printable(cls, v: str) -> str:
        m = _CONTROL.search(v)
        if m is not None:
            raise ValueError(_control_message(m))
        return v

    # ----------------------------------------------------------------- derived objects
    def gear_pair(self):
        """The :class:`geardyn.geometry.GearPair` of this case."""
        from .geometry import Gear, GearPair

        def make(g: GearConfig, which: str) -> Gear:
            try:
                return Gear(
                    teeth=g.teeth,
                    module=self.pair.module,
                    pressure_angle=self.pair.pressure_angle,
                    addendum_coefficient=self.pair.addendum_coefficient,
                    dedendum_coefficient=self.pair.dedendum_coefficient,
                    tool_tip_radius_coefficient=self.pair.tool_tip_radius_coefficient,
                    profile_shift=g.profile_shift,
                    face_width=self.pair.face_width,
                    bore_radius=g.bore_radius,
                )
            except InputError as exc:
                section = "pair" if exc.field in PairConfig.model_fields else which
                raise InputError(f"{section}.{exc.field}", exc.value, exc.allowed) from None

        return GearPair(make(self.pinion, "pinion"), make(self.gear, "gear"))

    def with_overrides(self, overrides: Mapping[str, Any] | Iterable[str],
                       source: str = "override") -> Case:
        """A new case with dotted-key overrides applied (validated again).

        ``overrides``: a mapping of dotted keys to values, ``"key=value"`` strings, or one such
        string (as in :func:`load_case`). The overridden values get ``source`` as their
        provenance (the CLI's ``--set`` goes through :func:`load_case`, which records
        ``"--set"``).
        """
        data = self.model_dump(mode="python")
        prov = data.pop("provenance")
        ov = _overrides_dict(overrides)
        for key, value in ov.items():
            _set_dotted(data, key, value)
            _drop_under(prov, key)
            if key not in _UNSOURCED:
                prov[key] = source
        data["provenance"] = prov
        return _validate(data, source="overrides")


# --------------------------------------------------------------------------- loading
#: Largest case file read [bytes]; a larger file (or a device such as /dev/zero) is refused before
#: it is parsed. The paper's case is about 10 kB; tomllib reads 256 kB of the worst text (a
#: 100,000-element array, 25,000 tables) in well under 2 s.
MAX_CASE_BYTES = 256 * 1024
#: Deepest nesting of arrays/tables in a case file (the paper's case needs 5).
MAX_NESTING = 16
#: Longest chain of ``extends`` (a file extending a file extending ...).
MAX_EXTENDS = 8
#: Longest ``--set`` value [characters].
MAX_OVERRIDE_CHARS = 10_000
#: Keys of a ``{ value = ..., source = ... }`` table (``si`` and ``origin`` are written by
#: ``geardyn config show`` for the reader and ignored on loading).
_META_KEYS = frozenset({"value", "source", "note", "si", "origin"})
#: Source shown by ``config show`` for a value nobody gave (the field's built-in default).
DEFAULT_SOURCE = "geardyn default (built-in value of the field)"
#: Source (and origin) of a command-line override.
SET_SOURCE = "--set"
_UNSOURCED = frozenset({"name", "description"})
# control characters refused in user strings: C0 except tab, DEL, C1
# (and lone surrogates: bytes that were not UTF-8, e.g. in a command-line argument)
_CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f-\x9f\ud800-\udfff]")
_KEY_PART = r'(?:[A-Za-z0-9_-]+|"[^"\n]{0,200}"|\'[^\'\n]{0,200}\')'
# a dotted key of more than MAX_NESTING parts at a line start, after '[' or '{' or ',' (tomllib
# takes quadratic time in the number of parts: 8000 parts take seconds)
_DEEP_KEY = re.compile(r"(?:^|[\[{,])[ \t]*" + _KEY_PART + r"(?:[ \t]*\.[ \t]*" + _KEY_PART
                       + r"){16,}", re.M)
_SCAN = re.compile(r'"""|\'\'\'|["\'#\[\]{}]')
_BASIC_END = re.compile(r'(?:[^"\\\n]|\\.)*"')
_ML_BASIC_END = re.compile(r'(?:[^"\\]|\\.|"(?!""))*"""', re.S)


def _control_message(m: re.Match) -> str:
    code = ord(m.group(0))
    if 0xD800 <= code <= 0xDFFF:
        return (f"UTF-8 text (found a byte that is not UTF-8 at position {m.start()}, shown as "
                f"U+{code:04X}); no control characters")
    return (f"text without control characters (found U+{code:04X} at position {m.start()}; "
            "tab is allowed)")


def check_text(value: Any, field: str) -> None:
    """Refuse control characters (other than tab) in a user string, naming the field.

    Raises
    ------
    InputError
        If ``value`` is a string holding a character U+0000-U+0008, U+000A-U+001F, U+007F or
        U+0080-U+009F.
    """
    if isinstance(value, str):
        m = _CONTROL.search(value)
        if m is not None:
            raise InputError(field, value, _control_message(m))


def _check_strings(node: Any, prefix: str) -> None:
    """:func:`check_text` on every string (keys and values) of raw case data."""
    stack = [(node, prefix)]
    while stack:
        obj, key = stack.pop()
        if isinstance(obj, dict):
            for k, v in obj.items():
                sub = f"{key}.{k}" if key else str(k)
                check_text(k, sub)
                stack.append((v, sub))
        elif isinstance(obj, list):
            stack.extend((v, f"{key}[{i}]") for i, v in enumerate(obj))
        else:
            check_text(obj, key)


def read_case_text(path: str | Path, kind: str = "case file", limit: int = MAX_CASE_BYTES) -> str:
    """Read a case file as UTF-8 text, bounded in size and time.

    Refuses (with :class:`DataFileError` naming the file) a missing file, a directory, anything
    that is not a regular file (``/dev/zero``, a pipe, a socket: they could stream for ever), a
    file larger than ``limit`` bytes (checked before and while reading), and bytes that are not
    UTF-8 (with the offset of the first bad byte).
    """
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise DataFileError(p, "no such file") from None
    except OSError as exc:
        raise DataFileError(p, f"cannot be read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise DataFileError(p, f"is a directory, not a {kind}")
    if not stat.S_ISREG(st.st_mode):
        raise DataFileError(p, f"is not a regular file (a device, pipe or socket), not a {kind}")
    too_big = f"is larger than {limit} bytes, the limit for a {kind}"
    if st.st_size > limit:
        raise DataFileError(p, too_big)
    try:
        with open(p, "rb") as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise DataFileError(p, f"cannot be read ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise DataFileError(p, too_big)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataFileError(p, f"is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
                               f"{exc.start}); save it as UTF-8") from None


def _nesting(text: str) -> int:
    """Deepest bracket nesting (``[``/``{``) outside strings and comments of TOML text.

    One linear pass that jumps between brackets, quotes and comments; it stops counting once
    :data:`MAX_NESTING` is passed.
    """
    i, n, depth, deepest = 0, len(text), 0, 0
    while i < n:
        m = _SCAN.search(text, i)
        if m is None:
            break
        t, i = m.group(0), m.end()
        if t == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif t == '"""':
            e = _ML_BASIC_END.match(text, i)
            i = n if e is None else e.end()
        elif t == "'''":
            j = text.find("'''", i)
            i = n if j < 0 else j + 3
        elif t == '"':
            e = _BASIC_END.match(text, i)
            i = (text.find("\n", i) if e is None else e.end())
            i = n if i < 0 else i
        elif t == "'":
            j = text.find("'", i)
            i = n if j < 0 else j + 1
        elif t in "[{":
            depth += 1
            deepest = max(deepest, depth)
            if deepest > MAX_NESTING:
                break
        else:
            depth = max(0, depth - 1)
    return deepest


def _tree_depth(node: Any) -> int:
    """Depth of nested dicts/lists (iterative: safe for any depth)."""
    deepest, stack = 0, [(node, 1)]
    while stack:
        obj, d = stack.pop()
        if isinstance(obj, dict | list):
            deepest = max(deepest, d)
            if deepest > MAX_NESTING + 8:
                return deepest
            stack.extend((v, d + 1) for v in (obj.values() if isinstance(obj, dict) else obj))
    return deepest


def parse_case_toml(text: str, origin: str) -> dict[str, Any]:
    """Parse case-file text with :mod:`tomllib`, refusing deep nesting and huge numbers first.

    Raises
    ------
    DataFileError
        Naming ``origin``: not valid TOML, nested deeper than :data:`MAX_NESTING`, or a number
        Python refuses to convert (more than 4300 digits).
    """
    if _nesting(text) > MAX_NESTING:
        raise DataFileError(origin, f"nests arrays or tables deeper than {MAX_NESTING} levels")
    if _DEEP_KEY.search(text) is not None:
        raise DataFileError(origin, f"nests keys deeper than {MAX_NESTING} levels (a dotted key "
                                    f"of more than {MAX_NESTING} parts)")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DataFileError(origin, f"is not valid TOML: {exc}") from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise DataFileError(origin, f"cannot be read as TOML ({type(exc).__name__}: a number too "
                                    "long or values nested too deeply)") from None
    if _tree_depth(raw) > MAX_NESTING + 8:
        raise DataFileError(origin, f"nests keys deeper than {MAX_NESTING + 8} levels")
    return raw


def _extract_provenance(node: Any, prefix: str, out: dict[str, str]) -> Any:
    """Replace ``{value = v, source = s}`` tables by ``v``, recording ``s`` at the dotted key."""
    if isinstance(node, dict):
        keys = set(node)
        if "value" in keys and keys <= _META_KEYS:
            if "source" in node:
                src = node["source"]
                if not isinstance(src, str):
                    raise InputError(f"{prefix}.source", src, "a text naming where the value "
                                                              "comes from")
                check_text(src, f"{prefix}.source")
                note = node.get("note")
                check_text(note, f"{prefix}.note")
                out[prefix] = src + (f" ({note})" if note is not None else "")
            return node["value"]
        if "value" in keys and "source" in keys:  # a { value, source } table with a typo
            bad = sorted(str(k) for k in keys - _META_KEYS)[0]
            raise InputError(f"{prefix}.{bad}", node[bad], "a known key; unknown key here. "
                             f"Allowed keys in a {{ value, source }} table: "
                             f"{', '.join(sorted(_META_KEYS))}")
        return {k: _extract_provenance(v, f"{prefix}.{k}" if prefix else k, out)
                for k, v in node.items()}
    return node


def _leaves(node: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """``(dotted key, value)`` of every non-table value of plain case data."""
    for k, v in node.items():
        key = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict) and v:
            yield from _leaves(v, key)
        else:
            yield key, v


def _drop_under(mapping: dict[str, str], key: str) -> None:
    for k in [k for k in mapping if k == key or k.startswith(key + ".")]:
        del mapping[k]


def _merge(base: dict[str, Any], top: Mapping[str, Any]) -> dict[str, Any]:
    """``top`` over ``base``: tables merge key by key, anything else replaces."""
    out = dict(base)
    for k, v in top.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def shipped_cases() -> list[str]:
    """Names of the cases shipped with geardyn (usable as ``extends = "<name>"``)."""
    return sorted(f.name[:-5] for f in resources.files("geardyn.cases").iterdir()
                  if f.name.endswith(".toml") and not f.name.startswith("sweep_"))


@dataclass
class _Layers:
    """Raw case data (values as written) merged over its bases, with sources and origins."""

    data: dict[str, Any]
    prov: dict[str, str]
    origin: dict[str, str]


def _shipped_layer(name: str, chain: tuple[str, ...]) -> _Layers:
    label = f"geardyn/cases/{name}.toml"
    text = resources.files("geardyn.cases").joinpath(f"{name}.toml").read_text("utf-8")
    return _layer_from_text(text, label, None, chain + (label,))


def _file_layer(path: Path, chain: tuple[str, ...]) -> _Layers:
    try:
        ident = str(path.resolve())
    except (OSError, RuntimeError):
        ident = str(path)
    if ident in chain:
        raise InputError("extends", str(path), "a base case that does not extend itself "
                                               "(cycle: " + " -> ".join(chain[-3:]) + ")")
    text = read_case_text(path)
    label = _CONTROL.sub("?", str(path))  # the file's name as a source: printable
    return _layer_from_text(text, label, path, chain + (ident,))


def _layer_from_text(text: str, label: str, path: Path | None, chain: tuple[str, ...]) -> _Layers:
    raw = parse_case_toml(text, label)
    prov: dict[str, str] = {}
    data = _extract_provenance(raw, "", prov)
    explicit = data.pop("provenance", None)
    if explicit is not None:
        if not isinstance(explicit, dict) or not all(isinstance(v, str) for v in explicit.values()):
            raise InputError("provenance", explicit, "a table of dotted key = \"source text\"")
        _check_strings(explicit, "provenance")
        prov = {**explicit, **prov}
    extends = data.pop("extends", PAPER_CASE if path is not None else False)
    complete = extends is False or extends == "none"
    if complete:
        base = _Layers({}, {}, {})
    elif not isinstance(extends, str) or not extends.strip():
        raise InputError("extends", extends, "the name of a shipped case "
                                             f"({', '.join(shipped_cases())}), a case file "
                                             "relative to this one, or false for a complete case")
    else:
        if len(chain) > MAX_EXTENDS:
            raise InputError("extends", extends, f"a chain of at most {MAX_EXTENDS} base cases")
        check_text(extends, "extends")
        if "/" not in extends and not extends.endswith(".toml") and extends in shipped_cases():
            base = _shipped_layer(extends, chain)
        else:
            bp = Path(extends)
            if not bp.is_absolute():
                bp = (path.parent if path is not None else Path.cwd()) / bp
            if not bp.exists():
                raise InputError("extends", extends,
                                 f"a shipped case ({', '.join(shipped_cases())}) or a case file "
                                 f"relative to {label} (no file {bp})")
            base = _file_layer(bp, chain)
        if path is not None:  # the user's case keeps its own name, never its base's
            stem = _CONTROL.sub("?", path.stem)
            data.setdefault("name", stem)
            data.setdefault("description", f"{stem}: changes to {extends}")
    _check_strings(data, "")
    merged = _merge(base.data, data)
    sources, origins = dict(base.prov), dict(base.origin)
    for key, _ in _leaves(data):
        if key in _UNSOURCED:
            continue
        _drop_under(sources, key)
        _drop_under(origins, key)
        if key in prov or not complete:  # a complete file's own values need no file source
            sources[key] = prov.get(key, label)
        origins[key] = label
    for key, src in prov.items():  # sources given in a [provenance] table for inner keys
        sources.setdefault(key, src)
    return _Layers(merged, sources, origins)


def _set_dotted(data: dict, key: str, value: Any) -> None:
    parts = key.split(".")
    if not all(parts):
        raise InputError("--set", key, "a dotted key such as 'pinion.teeth'")
    node = data
    for i, p in enumerate(parts[:-1]):
        if isinstance(node, list):  # an entry of a list of tables: faults.0.depth
            if not p.isdigit() or int(p) >= len(node):
                raise InputError(".".join(parts[: i + 1]), key,
                                 f"an index in [0, {len(node) - 1}] of the list")
            node = node[int(p)]
            continue
        nxt = node.get(p)
        if nxt is None and (p in ("crack", "modifications", "measurement")
                            or parts[0] == "modifications"):
            nxt = node[p] = {}
        if not isinstance(nxt, dict | list):
            raise InputError(".".join(parts[: i + 1]), nxt if nxt is not None else key,
                             "an existing section of the case (see 'geardyn config show')")
        node = nxt
    if isinstance(node, list):
        raise InputError(key, value, "a key of one entry of the list, e.g. 'faults.0.depth'")
    node[parts[-1]] = value


def parse_overrides(items: Iterable[str] | str) -> dict[str, Any]:
    """Parse ``key=value`` strings; values are TOML values when they parse, else strings.

    ``items`` is an iterable of strings, or one string (a single override: ``"pinion.teeth=25"``
    is ``["pinion.teeth=25"]``, not its characters). Values longer than
    :data:`MAX_OVERRIDE_CHARS` and control characters are refused; anything else than strings
    raises :class:`InputError` naming ``overrides``.

    Examples
    --------
    >>> parse_overrides(["pinion.teeth=25", "simulation.dt=5e-6 s", "crack.enabled=false"])
    {'pinion.teeth': 25, 'simulation.dt': '5e-6 s', 'crack.enabled': False}
    """
    out: dict[str, Any] = {}
    if isinstance(items, str):
        items = [items]
    elif isinstance(items, bytes | bytearray | Mapping) or not isinstance(items, Iterable):
        raise InputError("overrides", items, "'key=value' strings: a list of them or one, e.g. "
                                             "['pinion.teeth=25']")
    for item in items:
        if not isinstance(item, str):
            raise InputError("overrides", item, "'key=value' strings, e.g. 'pinion.teeth=25'")
        if "=" not in item:
            raise InputError("--set", item, "key=value, e.g. 'pinion.teeth=25' or "
                                            "'simulation.dt=\"5e-6 s\"'")
        key, raw = item.split("=", 1)
        key, raw = key.strip(), raw.strip()
        if not key:
            raise InputError("--set", item, "a non-empty dotted key before '='")
        check_text(key, "--set")
        if len(key) > 200:
            raise InputError("--set", key, "a dotted key of at most 200 characters")
        check_text(raw, key)
        if len(raw) > MAX_OVERRIDE_CHARS:
            raise InputError(key, raw, f"a value of at most {MAX_OVERRIDE_CHARS} characters")
        try:
            value = tomllib.loads(f"v = {raw}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw
        except (ValueError, RecursionError):
            raise InputError(key, raw, "a number of at most 4300 digits and values nested at "
                                       f"most {MAX_NESTING} deep") from None
        if _tree_depth(value) > MAX_NESTING:
            raise InputError(key, raw, f"a value nested at most {MAX_NESTING} deep")
        _check_strings(value, key)
        out[key] = value
    return out


_OVERRIDES_ALLOWED = ("a 'key=value' string, a list of them (e.g. ['pinion.teeth=25']), or a "
                      "mapping of dotted keys to values (e.g. {'pinion.teeth': 25})")


def _overrides_dict(overrides: Iterable[str] | Mapping[str, Any] | str) -> dict[str, Any]:
    """The overrides of :func:`load_case` / :meth:`Case.with_overrides` as ``{dotted key:
    value}``: a mapping (its keys strings) is copied, strings go through
    :func:`parse_overrides`."""
    if not isinstance(overrides, Mapping):
        if isinstance(overrides, bytes | bytearray) or not isinstance(overrides, Iterable):
            raise InputError("overrides", overrides, _OVERRIDES_ALLOWED)
        return parse_overrides(overrides)
    for key in overrides:
        if not isinstance(key, str):
            raise InputError("overrides", key, "dotted keys (strings) such as 'pinion.teeth'")
    return dict(overrides)


def _format_validation_error(exc: ValidationError, data: Mapping[str, Any]) -> InputError:
    errs = exc.errors(include_url=False)
    first = errs[0]
    loc = ".".join(str(p) for p in first["loc"] if not str(p).startswith("function-"))
    msg = first["msg"]
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    if first["type"] == "extra_forbidden":
        parent = ".".join(str(p) for p in first["loc"][:-1])
        allowed = _allowed_keys(parent)
        msg = f"a known key; unknown key here. Allowed keys{' in ' + parent if parent else ''}: " \
              f"{', '.join(allowed)}"
    elif first["type"] == "missing":
        msg = "a value (this required field is missing)"
    value = _raw_value(data, first["loc"], first.get("input", None))
    more = f" (and {len(errs) - 1} more problem{'s' if len(errs) > 2 else ''})" if len(errs) > 1 \
        else ""
    return InputError(loc or "case", value, msg + more)


def _raw_value(data: Mapping[str, Any], loc: tuple, default: Any) -> Any:
    """The value as the user wrote it (before unit conversion), found by its location."""
    node: Any = data
    for p in loc:
        if isinstance(node, Mapping) and p in node:
            node = node[p]
        elif isinstance(node, list) and isinstance(p, int) and p < len(node):
            node = node[p]
        else:
            return default
    return node


def _allowed_keys(parent: str) -> list[str]:
    model: type[BaseModel] = Case
    for p in [q for q in parent.split(".") if q]:
        f = model.model_fields.get(p)
        if f is None:
            return []
        ann = f.annotation
        sub = [a for a in getattr(ann, "__args__", (ann,)) if isinstance(a, type)
               and issubclass(a, BaseModel)]
        if not sub:
            return []
        model = sub[0]
    keys = sorted(model.model_fields)
    return [k for k in keys if k != "provenance"] + (["extends"] if model is Case else [])


def _model_leaves(model: BaseModel, prefix: str = "") -> Iterator[tuple[str, Any]]:
    for name in type(model).model_fields:
        if name == "provenance":
            continue
        value = getattr(model, name)
        key = f"{prefix}.{name}" if prefix else name
        if isinstance(value, BaseModel):
            yield from _model_leaves(value, key)
        elif isinstance(value, list) and value and isinstance(value[0], BaseModel):
            yield key, [v.model_dump(mode="json", exclude_none=True) for v in value]
        elif name == "faults" and not value:
            continue
        elif value is not None:
            yield key, value


def _validate(data: dict[str, Any], source: str = "") -> Case:
    """Validate plain case data, naming the first bad field as the user wrote it."""
    try:
        case = Case.model_validate(data)
    except ValidationError as exc:
        raise _format_validation_error(exc, data) from None
    if case.faults:  # geometry checks of the faults list (errors name faults[i].<key>)
        from .faults import check_faults

        check_faults(case)
    return case


@dataclass(frozen=True)
class CaseDetails:
    """A case with how each of its values was given (for ``geardyn config show``).

    Attributes
    ----------
    case : Case
    written : dict
        Raw case data as written in the files and overrides (unit strings kept), nested.
    origin : dict
        Dotted key -> where the value was given: a case file, ``"--set"``, or ``"default"``.
    """

    case: Case
    written: dict[str, Any]
    origin: dict[str, str]


def load_case_details(path: str | Path | None = None,
                      overrides: Iterable[str] | Mapping[str, Any] = (), *,
                      override_source: str = SET_SOURCE) -> CaseDetails:
    """:func:`load_case` keeping the values as written and where each came from."""
    if path is not None and not isinstance(path, str | os.PathLike):
        raise InputError("path", path, "a case file path (str or pathlib.Path), or None for the "
                                       "paper's case")
    ov = _overrides_dict(overrides)
    layers = _shipped_layer(PAPER_CASE, ()) if path is None else _file_layer(Path(path), ())
    data, prov, origin = layers.data, layers.prov, layers.origin
    before = copy.deepcopy(data) if ov else data  # to tell a change from a repeated value
    for key, value in ov.items():
        if isinstance(overrides, Mapping):
            check_text(key, "--set")
            _check_strings(value, key)
        _set_dotted(data, key, value)
        if key in _UNSOURCED:
            continue
        _drop_under(prov, key)
        _drop_under(origin, key)
        prov[key] = override_source
        origin[key] = override_source
    data["provenance"] = prov
    case = _validate(data)
    changed = _changed_keys(before, case, [k for k in ov if k not in _UNSOURCED])
    if changed and "name" not in ov:  # no longer the named case: say so
        data["name"] = f"{data.get('name', 'case')} (modified)"
        if "description" not in ov:
            keys = ", ".join(changed[:6]) + (", ..." if len(changed) > 6 else "")
            data["description"] = f"{data.get('description', '')} [changed by {override_source}: " \
                                  f"{keys}]".strip()
        case = _validate(data)
    origin = {**{k: "default" for k, _ in _model_leaves(case) if k not in _UNSOURCED}, **origin}
    written = {k: v for k, v in data.items() if k != "provenance"}
    return CaseDetails(case=case, written=written, origin=origin)


_MISSING = object()


def _value_at(case: BaseModel, key: str) -> Any:
    """The validated value at a dotted key (``faults.0.depth`` indexes the list), or _MISSING."""
    node: Any = case
    for p in key.split("."):
        if isinstance(node, BaseModel) and p in type(node).model_fields:
            node = getattr(node, p)
        elif isinstance(node, list) and p.isdigit() and int(p) < len(node):
            node = node[int(p)]
        elif isinstance(node, dict) and p in node:
            node = node[p]
        else:
            return _MISSING
    return node


def _same(a: Any, b: Any) -> bool:
    """Equal validated values (floats to 1e-12 relative: '5 mm' and 0.005 are the same)."""
    if isinstance(a, BaseModel) and isinstance(b, BaseModel):
        a, b = a.model_dump(), b.model_dump()
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float):
        return a == b or math.isclose(a, b, rel_tol=1e-12, abs_tol=0.0)
    return type(a) is type(b) and a == b


def _changed_keys(before: dict[str, Any], case: Case, keys: list[str]) -> list[str]:
    """The override ``keys`` whose validated value differs from the case without overrides
    (every key when that case is not valid on its own, e.g. a partial file completed by --set).
    A value set to what the case already has (``--set crack.depth="5 mm"`` on the paper's case)
    is no change."""
    if not keys:
        return []
    try:
        base = _validate(before)
    except InputError:
        return keys
    out = []
    for k in keys:
        old, new = _value_at(base, k), _value_at(case, k)
        if old is _MISSING or new is _MISSING or not _same(old, new):
            out.append(k)
    return out


def with_written_value(exc: InputError, details: CaseDetails) -> InputError:
    """``exc`` with its value as the user wrote it when that was a quantity with a unit, the SI
    value beside (``crack.depth: got '50 mm (= 0.05 m)'``); else ``exc`` itself."""
    dim = _field_dimension(exc.field) if isinstance(exc.field, str) else None
    written = _raw_value(details.written, tuple(exc.field.split(".")), None) if dim else None
    if not isinstance(written, str) or isinstance(exc.value, bool) \
            or not isinstance(exc.value, int | float):
        return exc
    si = format_si(exc.value, dim)
    number, _, unit = written.strip().partition(" ")
    try:
        plain = unit.strip() == DIMENSIONS[dim].si_unit and float(number) == exc.value
    except ValueError:
        plain = False
    value = written if plain else f"{written} (= {si})"
    return type(exc)(exc.field, value, exc.allowed)


def load_case(path: str | Path | None = None, overrides: Iterable[str] | Mapping[str, Any] = (),
              *, override_source: str = SET_SOURCE) -> Case:
    """Read and validate a case file, over its base case.

    A case file may give only the values it changes: it extends a base case, the paper's
    (``extends = "xue_howard"``, the default), another shipped case, or another case file
    (``extends = "base.toml"``, relative to the extending file; cycles are refused); ``extends =
    false`` marks a complete case. Tables merge key by key. Values from a base keep their source;
    a value of the file without a ``source`` gets the file's path as its source; overrides get
    ``override_source`` (``"--set"``). A file that extends another keeps its own ``name`` (default:
    the file's stem) and ``description``; overrides rename the case ``"<name> (modified)"`` unless
    they set ``name``.

    Parameters
    ----------
    path : str or Path, optional
        A TOML case file. ``None`` loads the paper's case shipped with geardyn.
    overrides : iterable of str, str or mapping
        ``"dotted.key=value"`` strings (or a mapping) applied before validation; a single
        string is one override (``"pinion.teeth=25"`` means ``["pinion.teeth=25"]``).
    override_source : str
        Source recorded for the overridden values.

    Returns
    -------
    Case

    Raises
    ------
    DataFileError
        If the file is missing, not a regular file, larger than :data:`MAX_CASE_BYTES`, not
        UTF-8, not valid TOML or nested deeper than :data:`MAX_NESTING`.
    InputError
        If a value is invalid; the message names the dotted key, the value and what is allowed.
        Also for a ``path`` that is not a str or path, and ``overrides`` that are not strings or
        a mapping with string keys (field ``"path"`` or ``"overrides"``).
    """
    return load_case_details(path, overrides, override_source=override_source).case


def paper_case(overrides: Iterable[str] | Mapping[str, Any] = ()) -> Case:
    """The paper's case (Xue & Howard 2018, Table 1 plus documented defaults).

    ``overrides`` as in :func:`load_case`: ``"key=value"`` strings, one such string, or a mapping.
    """
    return load_case(None, overrides)


# --------------------------------------------------------------------------- writing
def _dimension_in(annotation: Any, metadata: Iterable[Any] = ()) -> str | None:
    """The dimension a quantity type declares (its ``x-dimension``), searching unions and lists."""
    for m in list(metadata) + list(getattr(annotation, "__metadata__", ())):
        js = getattr(m, "json_schema", None)
        if isinstance(m, WithJsonSchema) and isinstance(js, dict) and "x-dimension" in js:
            return js["x-dimension"]
    for a in typing.get_args(annotation):
        d = _dimension_in(a)
        if d is not None:
            return d
    return None


@functools.cache
def _dimension_of(model: type[BaseModel], name: str) -> str | None:
    """The physical dimension of a quantity field (a key of :data:`DIMENSIONS`), else None."""
    f = model.model_fields.get(name)
    if f is None:
        return None
    return _dimension_in(f.annotation, f.metadata)


def _field_dimension(key: str) -> str | None:
    """Dimension of a dotted case key (``"pair.module"`` -> ``"length"``), else None."""
    model: type[BaseModel] = Case
    parts = key.split(".")
    for p in parts[:-1]:
        f = model.model_fields.get(p)
        if f is None:
            return None
        sub = [a for a in getattr(f.annotation, "__args__", (f.annotation,))
               if isinstance(a, type) and issubclass(a, BaseModel)]
        if not sub:
            return None
        model = sub[0]
    if parts[-1] not in model.model_fields:
        return None
    return _dimension_of(model, parts[-1])


def _to_toml_tree(model: BaseModel, prov: Mapping[str, str], prefix: str = "") -> dict:
    out: dict[str, Any] = {}
    for name in type(model).model_fields:
        if name == "provenance":
            continue
        value = getattr(model, name)
        key = f"{prefix}.{name}" if prefix else name
        if value is None:
            continue
        if isinstance(value, BaseModel):
            out[name] = _to_toml_tree(value, prov, key)
            continue
        if name == "faults" and not value:
            continue  # no faults: the text of a case without them stays as it was
        if isinstance(value, list) and value and isinstance(value[0], BaseModel):
            value = [_to_toml_tree(v, {}, key) for v in value]  # [[faults]] tables
        dim = _dimension_of(type(model), name)
        if dim is not None and isinstance(value, float):
            value = format_si(value, dim)
        if key in prov and key not in _UNSOURCED:
            value = {"value": value, "source": prov[key]}
        out[name] = value
    return out


def _dumps(tree: Mapping[str, Any]) -> str:
    import tomli_w

    # name, description and extends first, then the sections (tomli-w keeps the order given)
    head = {k: tree[k] for k in ("name", "description", "extends") if k in tree}
    return tomli_w.dumps({**head, **{k: v for k, v in tree.items() if k not in head}})


def case_to_toml(case: Case) -> str:
    """The effective case as TOML text (written by tomli-w), quantities as SI unit strings.

    A value with a recorded source is written as a ``{ value = ..., source = "..." }`` table (a
    ``[section.key]`` table in the text). The text says ``extends = false`` (a complete case) and
    loads back to an equal case with :func:`load_case`.
    """
    tree = _to_toml_tree(case, case.provenance)
    tree["extends"] = False
    return _dumps(tree)


def case_to_display_toml(details: CaseDetails) -> str:
    """The case as ``geardyn config show`` prints it: TOML (loadable by :func:`load_case`) with
    each value as written (``"20 deg"``), its SI value beside when it differs (``si``, stating
    the 2 pi of Hz), its ``source`` and its ``origin`` (base case file, case file, ``"--set"``
    or ``"default"``)."""
    from .units import hz_note

    case, origin = details.case, details.origin
    tree: dict[str, Any] = {"name": case.name, "description": case.description,
                            "extends": False}
    for key, value in _model_leaves(case):
        if key in _UNSOURCED:
            continue
        written = _raw_value(details.written, tuple(key.split(".")), None)
        dim = _field_dimension(key)
        shown: Any = value
        entry: dict[str, Any] = {}
        if dim is not None and isinstance(value, float):
            si = format_si(value, dim)
            shown = written if isinstance(written, str) else si
            if isinstance(written, str) and written.strip() != si:
                note = hz_note(written) if dim == "angular velocity" else None
                entry["si"] = f"{float(value):.10g} {DIMENSIONS[dim].si_unit}" + \
                    (f" ({note})" if note else "")
        entry = {"value": shown, **entry, "source": case.provenance.get(key, DEFAULT_SOURCE),
                 "origin": origin.get(key, "default")}
        node = tree
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = entry
    return _dumps(tree)


#: Keys of a ``{ value = ..., source = ... }`` table, as the JSON schema describes them.
_SOURCE_TABLE_KEYS = {
    "source": {"type": "string", "description": "Where the value comes from (kept as its "
                                                "provenance)."},
    "note": {"description": "Appended to the source in parentheses."},
    "si": {"description": "Written by 'geardyn config show' (the SI value); ignored on loading."},
    "origin": {"description": "Written by 'geardyn config show' (where the value was given); "
                              "ignored on loading."},
}
#: Models whose tables sit in a list (``[[faults]]``): a list replaces its base's whole, so
#: their required keys stay required, and their values cannot be ``{ value, source }`` tables
#: (only tables are searched for them, not lists).
_LIST_ITEM_MODELS = frozenset({"FaultConfig"})


def _sourced(schema: dict[str, Any]) -> dict[str, Any]:
    """``schema``, or the same value written as a ``{ value = ..., source = ... }`` table."""
    meta = {k: schema[k] for k in ("title", "description", "default") if k in schema}
    table = {"type": "object", "properties": {"value": schema, **_SOURCE_TABLE_KEYS},
             "required": ["value"], "additionalProperties": False}
    return {**meta, "anyOf": [schema, table]}


def _def_refs(schema: Any) -> list[str]:
    """Names of the ``$defs`` a property refers to directly or through ``anyOf`` (not through
    ``items``: list entries are not merged with a base)."""
    if not isinstance(schema, dict):
        return []
    ref = schema.get("$ref", "")
    out = [ref.rsplit("/", 1)[1]] if ref.startswith("#/$defs/") else []
    for sub in schema.get("anyOf", ()):
        out += _def_refs(sub)
    return out


def case_file_schema() -> dict[str, Any]:
    """JSON schema (draft 2020-12) of case *files*, as :func:`load_case` reads them.

    From the pydantic model's schema (:class:`Case`), with what the file format adds:

    * ``extends``: a shipped case, a case file, or ``false`` / ``"none"`` for a complete case;
    * every value (and table) of a section may be a ``{ value = ..., source = "..." }`` table
      (keys ``value``, ``source``, ``note``, ``si``, ``origin``), as the shipped case writes them
      and ``geardyn config show`` prints them; not inside the ``[[faults]]`` list;
    * no key is required in a file that extends a base (a partial case: any key may come from
      the base); a complete file (``extends = false`` or ``"none"``) must hold the sections and
      keys the model requires; a ``[[faults]]`` entry is always complete (lists replace);
    * quantities are a number in SI units or a string with a unit (``"5 mm"``), as the model's
      schema says (``x-unit``, ``x-dimension``); the ``[provenance]`` table of dotted key =
      source.

    Not described: the checks of values against each other (model validators, e.g. the load
    law's fields, ``centre_distance_max >= centre_distance_min``), the units a quantity string
    may use, and pydantic's lax conversions (a number written as a string for a plain number).
    """
    model = Case.model_json_schema()
    defs: dict[str, Any] = model.pop("$defs", {})
    complete: dict[str, Any] = {}

    def loosen(name: str, schema: dict[str, Any]) -> dict[str, Any]:
        out = copy.deepcopy(schema)
        if name in _LIST_ITEM_MODELS:
            return out
        required = out.pop("required", [])
        props = out.get("properties", {})
        skeleton: dict[str, Any] = {}
        for key, sub in props.items():
            refs = [r for r in _def_refs(sub) if r not in _LIST_ITEM_MODELS]
            if refs:  # a section: in a complete file its own required keys apply
                skeleton[key] = {"anyOf": [{"$ref": f"#/$defs/{refs[0]}.complete"},
                                           {"not": {"$ref": f"#/$defs/{refs[0]}"}}]}
            if key != "provenance":
                props[key] = _sourced(sub)
        complete[f"{name}.complete"] = {"required": required, "properties": skeleton} \
            if required else {"properties": skeleton}
        return out

    file_defs = {name: loosen(name, d) for name, d in defs.items()}
    root = loosen("Case", model)
    root["properties"]["extends"] = _sourced({
        "description": "The base case this file changes: a shipped case "
                       f"({', '.join(shipped_cases())}) or a case file relative to this one "
                       "(default: xue_howard); false or \"none\" for a complete case.",
        "anyOf": [{"const": False}, {"type": "string", "pattern": "\\S"}],
    })
    root["allOf"] = [{
        "if": {"properties": {"extends": {"enum": [False, "none"]}}, "required": ["extends"]},
        "then": {"$ref": "#/$defs/Case.complete"},
    }]
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", **root,
            "$defs": {**file_defs, **complete}}


def case_schema() -> str:
    """JSON schema of case files (pretty-printed JSON text, :func:`case_file_schema`)."""
    return json.dumps(case_file_schema(), indent=2)


def deep_copy_case_data(case: Case) -> dict[str, Any]:
    """Plain-Python copy of a case's values (SI floats), for hashing and serialisation."""
    exclude = {"provenance"} | (set() if case.faults else {"faults"})  # as before faults
    return copy.deepcopy(case.model_dump(mode="json", exclude=exclude))
