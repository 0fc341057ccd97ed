"""Parameter sweeps on Dask into one resumable Zarr store (``geardyn sweep``).

A **sweep file** (TOML, validated like case files: unknown keys are errors, quantities take unit
strings) names a base case and what changes from run to run::

    name = "crack_torque_bearing"
    base = "xue_howard"        # a shipped case, or a case file relative to this file
    seed = 2024                # sampling and per-run seeds

    [set]                      # fixed overrides of the base case (dotted keys)
    simulation.record_time = "0.5 s"

    [axes]                     # full factorial, first axis slowest
    crack.depth = ["1 mm", "3 mm", "5 mm"]                             # a list
    motor.torque = { start = "50 N m", stop = "150 N m", num = 3 }     # a range (num or step)
    pinion.bearing_stiffness = { start = "5e5 N/m", stop = "2e6 N/m", num = 3, scale = "log" }

    [link]                     # keys that follow a swept key run by run
    gear.bearing_stiffness = "pinion.bearing_stiffness"

    [sample]                   # quasi-random points, crossed with the grid
    method = "sobol"           # or "lhs" (scipy.stats.qmc), seeded by `seed`
    n = 16
    [sample.dimensions]
    load.speed = { low = "80 rad/s", high = "150 rad/s" }
    mesh.damping_ratio = { low = 0.03, high = 0.12, scale = "log" }

    [store]                    # what is kept per run besides the metrics
    signals = ["v_yg", "omega_p", "transmission_error"]   # RECORD_SIGNALS (with units)
    tsa = false                # the synchronous averages
    raw = false                # the recorded series
    noise_snr_db = 30          # optional measurement noise, seeded per run

    [execution]
    batch_size = "auto"        # runs per Dask task; "auto" aims at task_seconds
    task_seconds = 5.0         # the default

Runs are numbered in C order over the grid (first axis slowest) with the sample index
innermost: ``run = ((i0 * n1 + i1) * n2 + i2) * n_samples + s``.

The **store** (Zarr format 2 with consolidated metadata: the format every Zarr reader supports,
strings as fixed-width ``<U``, which the v2 specification defines while Zarr 3 still marks every
string type unstable) has one dimension ``run``. Coordinates: every swept and linked key, named
by its dotted key (SI values, ``units``, ``long_name``, ``sweep_role``), and ``seed`` (the run's
seed). Data variables: ``status`` (0 pending, 1 ok, 2 failed; CF ``flag_values`` /
``flag_meanings``), ``error`` (a failed run's message), ``warning`` (warnings the run raised),
``worker`` (``host:pid`` that computed it), ``run_seconds`` (its wall time) and one variable per
result, e.g. ``v_yg__FM4``, each with ``units`` and ``long_name`` (see
:class:`GeardynEvaluator`). The attributes hold the geardyn and library versions, the sweep file
text, the effective base case (TOML), the sweep hash, the batch size and the grid shape. Open it
with ``xarray.open_zarr`` or :func:`open_sweep` (``unstack=True`` gives one dimension per axis).

**Integrity.** Each batch's task writes a SHA-256 checksum of the values it wrote (variable
``batch_checksum``, dimension ``batch``) after its data chunks and before its status chunk. A
resume and :func:`open_sweep` verify every finished batch against it (a deleted, garbage or
swapped chunk fails); a resume puts damaged batches back to pending and names them in
:attr:`SweepResult.damaged`; :func:`verify_store` (``geardyn sweep --verify STORE``) checks without
computing. A missing consolidated metadata file is rebuilt on resume. See
:mod:`geardyn.studies.sweep.integrity`.

**Bounds.** A sweep of more than :data:`DEFAULT_MAX_RUNS` runs is refused before anything is
expanded, with the count and the limit in the message; ``max_runs=`` (``--max-runs``) or
``$GEARDYN_MAX_RUNS`` raises the limit.

**Execution and safety.** The store must be on a filesystem every worker sees (checked before
any task runs). The template (metadata, coordinates, ``status = 0``) is written first, into a
temporary folder renamed into place. The runs are cut into batches of ``batch_size`` consecutive
runs, the chunk length of every variable along ``run``, so a batch is exactly one chunk and no
two tasks ever write the same chunk. A worker evaluates its batch (each run in a ``try``: a run
that raises is recorded as failed with its message and the others go on), writes the data
chunks, then the status chunk. Zarr's local store writes every chunk to a temporary file and
renames it into place (checked by ``tests/sweep/test_store.py``), so a killed writer leaves the
old chunk or the new one, never a torn one; a batch killed before its status chunk is written
still reads as pending and is computed again, with the same values (a run is deterministic given
its case and seed). Re-running the same command therefore computes only the missing runs
(failed runs stay recorded unless ``retry_failed``); a store holding a *different* sweep (another
definition, base case, store options or geardyn version) is refused unless ``force``. The
``[execution]`` section is not part of the sweep's identity: a resumed store keeps its batches.

**Batching.** With ``batch_size = "auto"`` one run is timed on a worker (after a warm-up run
that loads the compiled kernels and the stiffness map) and a task gets
``ceil(task_seconds / t_run)`` runs, with the number of tasks rounded up to whole rounds of the
workers. ``task_seconds`` is 5 s unless set: a batch writes one chunk file per variable (76 for
the sweep benchmark), 0.05-0.13 s a batch on the machines measured, which is 1-3 % of a 5 s task
but 5-13 % of a 1 s one (the default until 2026-11-28). In six comparisons that day, alternating
or in the same run of ``benchmarks/run.py sweep`` (docs/performance.md), one worker ran at
0.62-0.95x of a bare loop of the same runs with 5 s tasks and at 0.58-0.89x with 1 s tasks, each
pair higher with 5 s; and a store of many runs holds a fifth of the files. The price: a worker
reports progress, and loses work to a kill, in steps of about 5 s. Before the runs, each distinct
stiffness map of the sweep is built once, in parallel (:meth:`Evaluator.prepare`), so workers
never build the same map twice at once.

Entry points: :func:`load_sweep`, :meth:`Sweep.plan`, :func:`run_sweep`, :func:`open_sweep`,
:func:`evaluate_run`.
"""

from .evaluate import Evaluator, GeardynEvaluator, Output, diagnostic_features, evaluate_run
from .execute import SweepResult, run_sweep, sweep_digest
from .integrity import DamagedBatch, StoreCheck, verify_store
from .signals import RECORD_SIGNALS
from .spec import (
    DEFAULT_MAX_RUNS,
    DEFAULT_SIGNALS,
    Parameter,
    Sweep,
    SweepFile,
    SweepPlan,
    load_sweep,
    parse_sweep,
    run_seeds,
)
from .store import (
    ERROR_CHARS,
    STATUS_FAILED,
    STATUS_OK,
    STATUS_PENDING,
    open_sweep,
    store_status,
)

__all__ = [
    "STATUS_PENDING",
    "STATUS_OK",
    "STATUS_FAILED",
    "ERROR_CHARS",
    "DEFAULT_SIGNALS",
    "RECORD_SIGNALS",
    "SweepFile",
    "Sweep",
    "SweepPlan",
    "Parameter",
    "Output",
    "Evaluator",
    "GeardynEvaluator",
    "SweepResult",
    "load_sweep",
    "parse_sweep",
    "run_seeds",
    "evaluate_run",
    "diagnostic_features",
    "run_sweep",
    "sweep_digest",
    "open_sweep",
    "store_status",
    "verify_store",
    "StoreCheck",
    "DamagedBatch",
    "DEFAULT_MAX_RUNS",
]
