"""Case files: validated parameter sets with units and provenance.

A case is a TOML file read with :mod:`tomllib` and validated by the pydantic models below
(``extra="forbid"``: a misspelt key is an error, not a silent default). Quantities accept a bare
number (SI) or a unit string (``"6 mm"``, ``"20 deg"``, ``"1e6 N/m"``, ``"100 N m"``) and are
stored as SI floats. Any value may be written as ``{ value = ..., source = "..." }`` to record
where it comes from; the shipped paper case does this for every entry, and the sources are kept in
:attr:`Case.provenance` (and shown by ``geardyn config show`` and in the report).

Overrides use dotted keys, ``--set pinion.teeth=25`` or ``--set simulation.dt="5e-6 s"``; the
value is read as a TOML value when it parses as one, otherwise as a string.
"""

from __future__ import annotations

import copy
import functools
import json
import math
import tomllib
from collections.abc import Iterable, Mapping
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
    "parse_overrides",
    "PAPER_CASE",
]

PAPER_CASE = "xue_howard"


# --------------------------------------------------------------------------- quantities
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
    }
    return Annotated[float, BeforeValidator(parse), WithJsonSchema(schema)]


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
    table_speeds: list[float] | None = Field(None, description="'table' law: output speeds "
                                                                "[rad/s], increasing.")
    table_torques: list[float] | None = Field(None, description="'table' law: torques [N m].")

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


class CrackConfig(_Model):
    """A root crack on one tooth."""

    enabled: bool = Field(True, description="Whether the crack is modelled.")
    gear: Literal["pinion", "gear"] = Field("pinion", description="Which gear is cracked.")
    tooth: int = Field(0, ge=0, strict=True, description="Cracked tooth number (0-based, in "
                                                         "mesh order; tooth k passes the pitch "
                                                         "point at pinion angle 2 pi k / z1).")
    depth: Length = Field(gt=0, description="Crack length from the root fillet [m].")
    angle: Angle = Field(math.radians(45), gt=0, lt=math.pi / 2,
                         description="Angle between the crack and the tooth centreline [rad]; the "
                                     "tip is depth*sin(angle) nearer the centreline than the mouth.")
    limit_line: Literal["tip", "parallel"] = Field(
        "tip", description="PEM crack limit line: towards the tooth tip (Mohammed et al. 2013) or "
                           "parallel to the centreline (Chen & Shao 2011).")


class FEConfig(_Model):
    """Finite-element mesh stiffness settings."""

    torque: Torque = Field(100.0, gt=0, description="Torque on the pinion hub [N m] (paper: 100).")
    plane: Literal["strain", "stress"] = Field("strain", description="Plane strain or stress.")
    mesh_size: Length | None = Field(None, gt=0, description="Element size in the tooth zone "
                                                              "[m]; omit for the default.")
    refinement: float = Field(1.0, gt=0, le=16, description="Mesh refinement factor [-] "
                                                            "(1 = default, 2 = twice as fine).")
    teeth_in_model: int = Field(5, ge=3, strict=True, description="Teeth in each body sector.")


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

    model: Literal["I", "II"] = Field("II", description="Model I: K(theta) at the design centre "
                                                        "distance; model II: K(theta, d(t)).")
    dt: Time = Field(1e-5, gt=0, description="Time step [s].")
    settle_time: Time = Field(0.5, ge=0, description="Simulated time discarded before recording "
                                                     "[s].")
    record_time: Time = Field(1.0, gt=0, description="Recorded time [s].")
    decimation: int = Field(1, ge=1, strict=True, description="Keep every n-th step.")
    tolerance: Length = Field(1e-7, gt=0, description="Model II: |b1 - b2| centre distance "
                                                      "tolerance [m] (paper: 0.1 um).")
    rtol: float = Field(1e-9, gt=0, lt=1, description="Model II: relative tolerance on the "
                                                      "acceleration update [-].")
    max_iterations: int = Field(50, ge=1, strict=True, description="Model II: iterations per "
                                                                   "step before failing.")
    stiffness_evaluation: Literal["predictor", "start"] = Field(
        "predictor", description="Model II: stiffness at the Newmark predictor (2nd order) or at "
                                 "the start of the step (the paper's flow chart, 1st order).")
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
    stiffness: StiffnessConfig = Field(default_factory=StiffnessConfig)
    simulation: SimulationConfig = Field(default_factory=SimulationConfig)
    diagnostics: DiagnosticsConfig = Field(default_factory=DiagnosticsConfig)
    provenance: dict[str, str] = Field(default_factory=dict,
                                       description="Source of each value, by dotted key.")

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

    def with_overrides(self, overrides: Mapping[str, Any] | Iterable[str]) -> Case:
        """A new case with dotted-key overrides applied (validated again)."""
        data = self.model_dump(mode="python")
        prov = data.pop("provenance")
        ov = parse_overrides(overrides) if not isinstance(overrides, Mapping) else overrides
        for key, value in ov.items():
            _set_dotted(data, key, value)
            prov.pop(key, None)
        data["provenance"] = prov
        return _validate(data, source="overrides")


# --------------------------------------------------------------------------- loading
def _extract_provenance(node: Any, prefix: str, out: dict[str, str]) -> Any:
    """Replace ``{value = v, source = s}`` tables by ``v``, recording ``s`` at the dotted key."""
    if isinstance(node, dict):
        keys = set(node)
        if "value" in keys and keys <= {"value", "source", "note"}:
            if "source" in node:
                out[prefix] = str(node["source"]) + (f" ({node['note']})" if "note" in node else "")
            return node["value"]
        return {k: _extract_provenance(v, f"{prefix}.{k}" if prefix else k, out)
                for k, v in node.items()}
    return node


def _set_dotted(data: dict, key: str, value: Any) -> None:
    parts = key.split(".")
    if not all(parts):
        raise InputError("--set", key, "a dotted key such as 'pinion.teeth'")
    node = data
    for i, p in enumerate(parts[:-1]):
        nxt = node.get(p)
        if nxt is None and p in ("crack",):
            nxt = node[p] = {}
        if not isinstance(nxt, dict):
            raise InputError(".".join(parts[: i + 1]), nxt if nxt is not None else key,
                             "an existing section of the case (see 'geardyn config show')")
        node = nxt
    node[parts[-1]] = value


def parse_overrides(items: Iterable[str]) -> dict[str, Any]:
    """Parse ``key=value`` strings; values are TOML values when they parse, else strings.

    Examples
    --------
    >>> parse_overrides(["pinion.teeth=25", "simulation.dt=5e-6 s", "crack.enabled=false"])
    {'pinion.teeth': 25, 'simulation.dt': '5e-6 s', 'crack.enabled': False}
    """
    out: dict[str, Any] = {}
    for item in items:
        if "=" not in item:
            raise InputError("--set", item, "key=value, e.g. 'pinion.teeth=25' or "
                                            "'simulation.dt=\"5e-6 s\"'")
        key, raw = item.split("=", 1)
        key, raw = key.strip(), raw.strip()
        if not key:
            raise InputError("--set", item, "a non-empty dotted key before '='")
        try:
            value = tomllib.loads(f"v = {raw}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw
        out[key] = value
    return out


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
    return sorted(model.model_fields)


def _validate(data: dict[str, Any], source: str) -> Case:
    try:
        return Case.model_validate(data)
    except ValidationError as exc:
        raise _format_validation_error(exc, data) from None


def load_case(path: str | Path | None = None, overrides: Iterable[str] | Mapping[str, Any] = (),
              ) -> Case:
    """Read and validate a case file.

    Parameters
    ----------
    path : str or Path, optional
        A TOML case file. ``None`` loads the paper's case shipped with geardyn.
    overrides : iterable of str or mapping
        ``"dotted.key=value"`` strings (or a mapping) applied before validation.

    Returns
    -------
    Case

    Raises
    ------
    DataFileError
        If the file is missing, unreadable or not valid TOML.
    InputError
        If a value is invalid; the message names the dotted key, the value and what is allowed.
    """
    if path is None:
        text = resources.files("geardyn.cases").joinpath(f"{PAPER_CASE}.toml").read_text("utf-8")
        origin = f"geardyn/cases/{PAPER_CASE}.toml"
    else:
        from .io import read_text

        text = read_text(path, "case file")
        origin = str(path)
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DataFileError(origin, f"is not valid TOML: {exc}") from None
    prov: dict[str, str] = {}
    data = _extract_provenance(raw, "", prov)
    if isinstance(data.get("provenance"), dict):
        prov = {**data["provenance"], **prov}
    ov = dict(overrides) if isinstance(overrides, Mapping) else parse_overrides(overrides)
    for key, value in ov.items():
        _set_dotted(data, key, value)
        prov.pop(key, None)
    data["provenance"] = prov
    return _validate(data, source=origin)


def paper_case(overrides: Iterable[str] | Mapping[str, Any] = ()) -> Case:
    """The paper's case (Xue & Howard 2018, Table 1 plus documented defaults)."""
    return load_case(None, overrides)


# --------------------------------------------------------------------------- writing
@functools.cache  # builds a JSON schema: slow, and the answer never changes
def _dimension_of(model: type[BaseModel], name: str) -> str | None:
    """The physical dimension of a quantity field (from its JSON-schema unit), else None."""
    schema = model.model_json_schema()["properties"].get(name, {})
    unit = schema.get("x-unit") or next((a.get("x-unit") for a in schema.get("anyOf", [])
                                         if isinstance(a, dict) and a.get("x-unit")), None)
    if unit is None:
        return None
    return next(key for key, dim in DIMENSIONS.items() if dim.si_unit == unit)


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
        dim = _dimension_of(type(model), name)
        if dim is not None and isinstance(value, float):
            value = format_si(value, dim)
        if key in prov:
            value = {"value": value, "source": prov[key]}
        out[name] = value
    return out


def _toml_scalar(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else
                                                 ("inf" if v > 0 else "-inf"))
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)  # a JSON string is a TOML basic string
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_scalar(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_scalar(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def case_to_toml(case: Case) -> str:
    """The effective case as TOML text, quantities as SI unit strings, sources kept inline.

    A value with a recorded source is written ``key = { value = ..., source = "..." }``. The text
    loads back to an equal case with :func:`load_case`.
    """
    tree = _to_toml_tree(case, case.provenance)
    lines: list[str] = []

    def is_section(v: Any) -> bool:
        return isinstance(v, dict) and not ("value" in v and set(v) <= {"value", "source"})

    def emit(node: dict, path: str) -> None:
        scalars = [(k, v) for k, v in node.items() if not is_section(v)]
        if path and (scalars or not any(is_section(v) for v in node.values())):
            lines.append(f"\n[{path}]")
        for k, v in scalars:
            lines.append(f"{k} = {_toml_scalar(v)}")
        for k, v in node.items():
            if is_section(v):
                emit(v, f"{path}.{k}" if path else k)

    emit(tree, "")
    return "\n".join(lines).lstrip("\n") + "\n"


def case_schema() -> str:
    """JSON schema of case files (pretty-printed JSON text)."""
    return json.dumps(Case.model_json_schema(), indent=2)


def deep_copy_case_data(case: Case) -> dict[str, Any]:
    """Plain-Python copy of a case's values (SI floats), for hashing and serialisation."""
    return copy.deepcopy(case.model_dump(mode="json", exclude={"provenance"}))
