"""The case's pydantic models: quantities with units (SI floats inside), one model per section,
and :class:`Case` (see :mod:`geardyn.config` for the file format)."""

from __future__ import annotations

import copy
import functools
import math
import re
import typing
from collections.abc import Iterable, Mapping
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    WithJsonSchema,
    field_validator,
    model_validator,
)

from ..errors import InputError
from ..units import DIMENSIONS, to_si


# --------------------------------------------------------------------------- quantities
class _QuantityJsonSchema(WithJsonSchema):
    """:class:`pydantic.WithJsonSchema` that hands out a copy of its schema each time: pydantic
    2.6 returned the dict itself and then wrote a field's constraints into it (``gt: 0``), so
    every later schema showed one field's constraint on all quantities of that dimension and
    two calls of :func:`case_file_schema` differed (found by the dependency floors' run)."""

    def __get_pydantic_json_schema__(self, core_schema, handler):
        return copy.deepcopy(super().__get_pydantic_json_schema__(core_schema, handler))


class FieldProblem(ValueError):
    """A model validator's refusal of one field of its section (``field``, relative to it):
    the user's error then names that field and its value as written, not the whole section
    (:func:`geardyn.config.loading._format_validation_error`).

    Parameters
    ----------
    field : str
        The field's name in the section (``"centre_distance_max"``).
    allowed : str
        What is allowed.
    """

    def __init__(self, field: str, allowed: str):
        super().__init__(allowed)
        self.field = field


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

    @classmethod
    def __pydantic_init_subclass__(cls, **kwargs):
        super().__pydantic_init_subclass__(**kwargs)
        cls.__hash__ = _Model._value_hash  # pydantic's frozen hash fails on list fields

    def _value_hash(self) -> int:
        """Hash of the values as JSON (equal models, equal hashes): a case can key a dict or an
        ``lru_cache`` (pydantic's hash of a frozen model raised "unhashable type: 'list'" for
        the list fields of a case, a user audit of 2026-11-27)."""
        return hash((type(self).__qualname__, self.model_dump_json()))


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
                                "revolution at the case's speed load.speed [-]: the ripple runs at "
                                "the fixed frequency ripple_order x load.speed / 2 pi, so it stays "
                                "at this order only while the motor runs at that speed (refused "
                                "with a speed profile).")
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
                    raise FieldProblem(name, f"a value: motor.{name} is required with "
                                             f"motor.law = 'induction'")
        if self.ripple > 0 and self.profile_times is not None:
            # the ripple is a fixed-frequency torque (ripple_order x load.speed), not locked to
            # the motor angle: in a run-up it would drift off its order (a user audit found it
            # at order 4.8 instead of 6 after a ramp to 145 rad/s), so the two are not combined
            raise FieldProblem("ripple", "0 with a speed profile (motor.profile_times): the "
                                         "ripple runs at a fixed frequency, ripple_order x "
                                         "load.speed, and would not follow the run-up")
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
                raise FieldProblem("table_speeds", "load.table_speeds and load.table_torques "
                                   "given with the same length >= 2 for load.law = 'table'")
            if any(b <= a for a, b in zip(sp, sp[1:], strict=False)):
                raise FieldProblem("table_speeds", "strictly increasing speeds")
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
            raise FieldProblem("torques", "at least two increasing torques > 0 [N m], or no "
                                          "stiffness.fe.torques for one map")
        return self


class StiffnessConfig(_Model):
    """Mesh stiffness map K(theta, d)."""

    method: Literal["pem", "fe"] = Field("pem", description="Potential energy method or FE.")
    centre_distance_min: Length = Field(-0.5e-3, description="Lowest centre distance change [m].")
    centre_distance_max: Length = Field(2.0e-3, description="Highest centre distance change [m].")
    centre_distances: int = Field(31, ge=1, le=1001, strict=True,
                                  description="Number of centre distances in the map, evenly "
                                              "spaced over [centre_distance_min, "
                                              "centre_distance_max]; 1 only where the two are "
                                              "equal.")
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
        lo, hi = self.centre_distance_min, self.centre_distance_max
        if hi < lo:
            raise FieldProblem("centre_distance_max", f"a change >= stiffness.centre_distance_min "
                                                      f"({lo * 1e3:.6g} mm)")
        if self.centre_distances > 1 and hi == lo:
            raise FieldProblem("centre_distances", f"1 for the single centre distance change "
                                                   f"{lo * 1e3:.6g} mm (centre_distance_min = "
                                                   f"centre_distance_max), or a range with "
                                                   f"centre_distance_max > centre_distance_min")
        if self.centre_distances == 1 and hi != lo:
            # one centre distance is the range's lower end (numpy.linspace): the map would
            # hold the mesh stiffness there only, whatever the operating centre distance
            raise FieldProblem("centre_distances", f"at least 2 over the range [{lo * 1e3:.6g}, "
                                                   f"{hi * 1e3:.6g}] mm, or 1 with "
                                                   f"centre_distance_min = centre_distance_max "
                                                   f"(a map at that one centre distance)")
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
    @property
    def active_crack(self) -> CrackConfig | None:
        """The root crack (``[crack]``) where it changes the stiffness (:attr:`CrackConfig.active`:
        enabled, depth > 0), else None (no crack, a disabled one or one of zero depth)."""
        return self.crack if self.crack is not None and self.crack.active else None

    def gear_pair(self):
        """The :class:`geardyn.geometry.GearPair` of this case."""
        from ..geometry import Gear, GearPair

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
        from .loading import _UNSOURCED, _drop_under, _overrides_dict, _set_dotted, _validate

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




# control characters refused in user strings: C0 except tab, DEL, C1
# (and lone surrogates: bytes that were not UTF-8, e.g. in a command-line argument)
_CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f-\x9f\ud800-\udfff]")


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


def _model_field(parts) -> tuple[type[BaseModel], str] | None:
    """The section model and field name a case key's parts reach (``("pair", "module")`` ->
    ``(PairConfig, "module")``), else None (an unknown key, or one inside a list of tables)."""
    model: type[BaseModel] = Case
    parts = [str(p) for p in parts]
    for p in parts[:-1]:
        f = model.model_fields.get(p)
        if f is None:
            return None
        sub = [a for a in getattr(f.annotation, "__args__", (f.annotation,))
               if isinstance(a, type) and issubclass(a, BaseModel)]
        if not sub:
            return None
        model = sub[0]
    return (model, parts[-1]) if parts and parts[-1] in model.model_fields else None


def _field_dimension(key: str) -> str | None:
    """Dimension of a dotted case key (``"pair.module"`` -> ``"length"``), else None."""
    found = _model_field(key.split("."))
    return _dimension_of(*found) if found else None
