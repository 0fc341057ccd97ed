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

# the three modules: the models (models.py), reading case files (loading.py), writing them and
# their schema (writing.py); everything public is here, as when they were one module
from .loading import (
    DEFAULT_SOURCE,
    MAX_CASE_BYTES,
    MAX_EXTENDS,
    MAX_NESTING,
    MAX_OVERRIDE_CHARS,
    PAPER_CASE,
    SET_SOURCE,
    CaseDetails,
    load_case,
    load_case_details,
    paper_case,
    parse_case_toml,
    parse_overrides,
    read_case_text,
    shipped_cases,
    with_written_value,
)
from .models import (
    Case,
    CouplingConfig,
    CrackConfig,
    DiagnosticsConfig,
    FaultConfig,
    FEConfig,
    GearConfig,
    GearErrorsConfig,
    LoadConfig,
    MaterialConfig,
    MeasurementConfig,
    MeshConfig,
    ModificationsConfig,
    MotorConfig,
    PairConfig,
    SimulationConfig,
    StiffnessConfig,
    check_text,
)
from .writing import (
    case_file_schema,
    case_schema,
    case_to_display_toml,
    case_to_toml,
    deep_copy_case_data,
)

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
    "deep_copy_case_data",
    "MAX_CASE_BYTES",
    "MAX_NESTING",
    "MAX_EXTENDS",
    "MAX_OVERRIDE_CHARS",
    "DEFAULT_SOURCE",
    "SET_SOURCE",
    "PairConfig",
    "GearConfig",
    "MaterialConfig",
    "CouplingConfig",
    "MotorConfig",
    "LoadConfig",
    "MeshConfig",
    "CrackConfig",
    "FaultConfig",
    "FEConfig",
    "StiffnessConfig",
    "SimulationConfig",
    "DiagnosticsConfig",
    "MeasurementConfig",
    "GearErrorsConfig",
    "ModificationsConfig",
]
