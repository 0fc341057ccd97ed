"""The paper's case study, end to end: ``geardyn run``.

Stages run in order, each adding to the summary and to the output folder:

1. ``geometry``: the pair at its design centre distance, at the paper's FE centre distances
   (+0.5, +1.0 mm) and at the static operating point under the input torque (eq. 4).
2. ``stiffness``: the mesh stiffness maps K(theta, d), healthy and with the crack (Figs. 5, 6).
3. ``simulation``: model I, model I-static (``K(theta)`` at the static operating centre
   distance of eq. 4, held fixed) and model II, cracked and healthy, plus model II with the
   paper's start-of-step stiffness evaluation for the iteration figure (Figs. 8-10); cached. Each
   record is written to ``runs/model_<M>_<state>.nc``. :func:`~.model_compare.compare_models`
   then splits the model II - model I difference into the static shift and the centre-distance
   dynamics (``summary["model_comparison"]``).
4. ``diagnostics``: TSA, spectra, residual, PWVD, demodulation, statistics (Tables 2, 3) and
   condition metrics, healthy against cracked (Figs. 11-23); the diagnoses are cached, keyed by
   the records' signals and the settings (:mod:`.paper_cache`).
5. ``measurement``: the same indicators on a realistic measurement (housing accelerometer
   through the case's sensor chain, ISO 1328 tooth errors, noise, TSA from the tachometer), in
   four variants that separate the errors from the noise (:mod:`.paper_measurement`); reuses
   the maps and records, adds two cached simulations with tooth errors.
6. ``report``: ``report.html``, ``results.nc`` and ``figures/`` (:mod:`.paper_report`).

The output files that encode a map or a record (``stiffness_*.nc``, ``runs/*.nc``) and the
figures go through the cache as well, so a run of the same inputs into a new folder copies them
instead of encoding, compressing and drawing them again (issue 16; :mod:`.paper_cache`).

After each stage the consistency checks and the comparisons with the paper are recomputed from
the summary (:mod:`.paper_validation`). Module layout, one way only: this pipeline imports the
report stage; the report reads the :class:`~.paper_result.StudyResult`, the published values
(:mod:`.paper_values`) and the validation tables, never this module.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from ..config import Case, case_to_toml, paper_case
from ..geometry import geometry_summary, static_operating_point
from ..heap import release_free_memory
from ..io import NETCDF_COMPRESSION, write_json_atomic, write_text_atomic
from .paper_result import (
    PLOT_MESH,
    FigureStore,
    ImportedOnCall,
    Progress,
    StudyResult,
    fe_mesh_figure_task,
    kernels_and_mesh_figure_task,
)
from .paper_validation import validation_tables
from .paper_values import (
    CONDITION_METRICS,
    FAULT_DIP,
    PAPER_PM_LEVEL_DEG,
    PAPER_TABLE2,
    PAPER_TABLE3,
    PAPER_VALUES,
    SIGNAL_KEYS,
    case_differences,
    fault_word,
    faulty_words,
)

__all__ = ["run_paper_study", "StudyResult", "PAPER_VALUES", "PAPER_TABLE2", "PAPER_TABLE3",
           "PAPER_PM_LEVEL_DEG", "SIGNAL_KEYS", "CONDITION_METRICS", "STAGES", "paper_tables",
           "healthy_baseline_is_periodic", "write_run_netcdf", "RUN_ENCODING_FLOAT32"]


def geometry_stage(case: Case, out: Path, result: StudyResult) -> None:
    """Geometry at the design, +0.5 mm, +1.0 mm and static operating centre distances."""
    pair = case.gear_pair()
    static = static_operating_point(pair, case.motor.torque, case.pinion.bearing_stiffness,
                                    case.gear.bearing_stiffness,
                                    fields=("pinion.bearing_stiffness", "gear.bearing_stiffness"))
    report = {
        "design": geometry_summary(pair, 0.0),
        "dd_0.5mm": geometry_summary(pair, 0.5e-3),
        "dd_1.0mm": geometry_summary(pair, 1.0e-3),
        "static_operating_point": geometry_summary(pair, static.centre_distance_change),
    }
    write_json_atomic(out / "geometry.json", report)
    s = result.summary
    s["design"] = {"centre_distance_mm": pair.design_centre_distance * 1e3,
                   "contact_ratio": report["design"]["operating"]["contact_ratio"]["physical"],
                   "base_radius_sum_mm": pair.base_radius_sum * 1e3}
    s["static"] = {"centre_distance_change_mm": static.centre_distance_change * 1e3,
                   "pressure_angle_deg": math.degrees(static.pressure_angle),
                   "contact_ratio": static.contact_ratio,
                   "contact_ratio_eq8": static.contact_ratio_eq8}
    s["centre_distance_change_mm"] = static.centre_distance_change * 1e3
    s["operating_pressure_angle_deg"] = math.degrees(static.pressure_angle)
    s["contact_ratio"] = {"physical": static.contact_ratio, "paper_eq8": static.contact_ratio_eq8}
    s.setdefault("sources", {})["centre_distance_change_mm"] = (
        "static equilibrium, rigid teeth (geometry stage): N = T/r_b1 on the bearings, eq. 4")


def _build_map_with_progress(build_map, case: Case, cracked: bool, result: StudyResult,
                             bar: str):
    """``build_map`` with its own progress bar that always ends full (a cached map is one
    step)."""
    last = {"total": 0}

    def cb(done: int, total: int) -> None:
        last["total"] = int(total or 0)
        result.emit(f"{bar}: building", done, total)

    m = build_map(case, cracked=cracked, progress=cb if result.progress else None)
    n = last["total"] or 1
    result.emit(f"{bar}: {'built' if last['total'] else 'from the cache'}", n, n)
    return m


def _faulty_bodies_in_background(case: Case, result: StudyResult):
    """:func:`geardyn.stiffness.fe.background.faulty_bodies_in_background`, imported only for
    the FE method (the FE package takes 0.2 s to import). Without a second process it builds
    the faulty map's bodies first, under the progress bar ``stiffness (FE bodies)``."""
    import contextlib
    from functools import partial

    if case.stiffness.method != "fe":
        return contextlib.nullcontext(None)
    from ..stiffness.fe.background import faulty_bodies_in_background, tasks_in_background

    progress = result.sub_progress("stiffness (FE bodies)")
    # after its bodies the second process draws the mesh figure from the cracked body's mesh
    # it holds (this one would mesh the body again to draw it: about 1.5 s on the paper's pinion)
    cracked = case.active_crack is not None
    if not result.quick:
        # and compiles the time-step kernel, while this one evaluates the maps and goes on, or
        # loads it from numba's cache (0.3 s) where it is there already (which of the two
        # first: kernels_and_mesh_figure_task); asking numba's cache here would import numba
        # (53 MB) into this process before its own bodies' factorisations, the peak of the
        # run's memory
        then = (partial(kernels_and_mesh_figure_task, case, cracked),) if cracked else \
            (ImportedOnCall("geardyn.dynamics.warm", "compile_kernels"),)
        return faulty_bodies_in_background(case, then=then, progress=progress)
    from ..dynamics.warm import compile_kernels, kernels_compiled

    if not kernels_compiled():
        # a first --quick run after an install: the second process compiles the time-step kernel
        # (5-10 s) from the start, and this one builds the coarse bodies (a second or two) itself;
        # same-time A/B, 2026-11-26: 24.5-26.2 s and 675 MB against 27.5-28.8 s and 801-807 MB
        # with the bodies, then the kernel, in the second process. Once numba has the kernel the
        # second process builds the faulty bodies as in a full run (21.0-21.4 s against
        # 22.7-22.8 s with the bodies here; 665 MB against 484 MB)
        result.kernel_compiler = tasks_in_background((compile_kernels,))
        if result.kernel_compiler is not None:
            result.background.append(result.kernel_compiler)
        return faulty_bodies_in_background(case, progress=progress, second_process=False)
    # --quick with the kernel compiled: the second process ends with the bodies and the mesh
    # figure (loading the kernel there would not load it here)
    mesh_figure = (partial(fe_mesh_figure_task, case, cracked),) if cracked else ()
    return faulty_bodies_in_background(case, then=mesh_figure, progress=progress)


def _note_bodies_process(result: StudyResult, bodies) -> None:
    """Record the FE bodies' second process (``bodies``, a
    :class:`~geardyn.stiffness.fe.background.BackgroundBodies`, or None) among the study's
    background processes; in a full run it also compiles or loads the time-step kernel after
    the bodies (:func:`_faulty_bodies_in_background`), so the simulation stage waits for it
    there (:func:`_wait_for_the_kernel`)."""
    if not bodies:
        return
    result.background.append(bodies.process)
    if not result.quick:
        result.kernel_compiler = bodies.process


def _figure_process(result: StudyResult):
    """A :class:`~.figure_process.FigureProcess` for the study's figures where a second
    process is allowed (:func:`~.figure_process.figure_process_allowed`), started once the
    study's other background processes (``result.background``) have ended; else None."""
    from .figure_process import FigureProcess, figure_process_allowed

    if not figure_process_allowed():
        return None
    return FigureProcess(ready=lambda: not any(p.is_alive() for p in result.background))


def stiffness_stage(case: Case, out: Path, result: StudyResult) -> None:
    """Healthy and cracked stiffness maps (cached), NetCDF files and the Figs. 5-6 analogues."""
    import json
    import warnings

    from ..stiffness import build_map

    # drawn only on a figure-cache miss: importing the plots imports matplotlib (issue 16);
    # the curves are evaluated here, where the maps and numba are, and drawn from plain arrays
    # (a figure process then draws them without importing the maps' code and numba)
    stiffness_curves, load_sharing_curves, crack_curves = (
        ImportedOnCall("geardyn.stiffness.plots", name)
        for name in ("stiffness_curves", "load_sharing_curves", "crack_curves"))
    draw = ImportedOnCall("geardyn.line_figure", "draw_line_figure")
    map_case = _map_case(case, result.quick)
    if map_case is not case:
        what = [f"{map_case.stiffness.centre_distances} centre distances"]
        if map_case.stiffness.fe.refinement != case.stiffness.fe.refinement:
            what.insert(0, f"FE mesh refinement {map_case.stiffness.fe.refinement:g}")
        result.notes.append("--quick: the stiffness maps are coarser than the case's ("
                            + ", ".join(what) + "); run without --quick for the case's own "
                            "maps.")
    with warnings.catch_warnings(), _faulty_bodies_in_background(map_case, result) as bodies:
        # (a second process builds the cracked map's FE bodies meanwhile, where cores and
        # memory allow: geardyn.stiffness.fe.background)
        _note_bodies_process(result, bodies)
        if result.background:  # the figure process starts as soon as they have ended (its
            result.figures.start_early()  # imports then overlap this one's work)
        warnings.simplefilter("ignore")  # the maps record their warnings in attrs (read below)
        healthy = _build_map_with_progress(build_map, map_case, False, result,
                                           "stiffness (healthy)")
        cracked = _build_map_with_progress(build_map, map_case, True, result,
                                           "stiffness (cracked)")
    for m in (healthy, cracked):
        w = m.attrs.get("warnings", "[]")
        for text in (json.loads(w) if isinstance(w, str) else list(w)):
            if text not in result.notes:
                result.notes.append(text)
    result.maps = {"healthy": healthy, "cracked": cracked}
    from .paper_cache import fingerprint, write_output
    from .paper_result import Deferred

    for state, m in result.maps.items():  # the bytes from the cache when an earlier run wrote them
        write_output(out / f"stiffness_{state}.nc", "stiffness map", m, "StiffnessMap.to_netcdf",
                     m.to_netcdf)
    result.figures.cached("fig5_stiffness", draw, Deferred(
        fingerprint("fig5_stiffness curves", healthy), lambda: stiffness_curves(healthy)))
    result.figures.cached("fig5_load_sharing", draw, Deferred(
        fingerprint("fig5_load_sharing curves", healthy), lambda: load_sharing_curves(healthy)))
    cracks = case.active_crack is not None
    if case.stiffness.method == "fe":
        # PLOT_MESH imports the FE package (0.2 s, issue 16) only to draw; the mesh the maps
        # were built on (with --quick, the coarser one), drawn by the process
        # that holds it: the second process that built the cracked body draws it into the
        # cache ahead (fe_mesh_figure_task), else this one, which built it; not the figure
        # process, which would mesh the body again
        result.summary["fe_mesh_refinement"] = float(map_case.stiffness.fe.refinement)
        result.figures.cached_here("fig_fe_mesh", PLOT_MESH, map_case, cracked=cracks)
    dd_op = result.summary.get("static", {}).get("centre_distance_change_mm", 0.0) * 1e-3
    dd_op = dd_op if cracked.covers(dd_op) else 0.0
    numbers = map_numbers(healthy, cracked, cracks, dd_op)
    if fault_word(case):
        # the Fig. 6 analogue for any fault (a spall, breakage, wear...), not only a crack:
        # centred where the faulty map falls furthest below the healthy one
        faulty = faulty_words(case)[0]
        result.figures.cached("fig6_crack", draw, Deferred(
            fingerprint("fig6_crack curves", healthy, cracked, faulty),
            lambda: crack_curves(healthy, cracked, faulty=faulty)))
    if cracks:
        result.summary["crack_angle_in_stiffness_deg"] = math.degrees(numbers["crack_angle_op"])
        result.summary["crack_angle_in_stiffness_at_mm"] = dd_op * 1e3
        result.crack_angle_rad = numbers["crack_angle_0"]
    result.summary["mean_mesh_stiffness_N_per_m"] = numbers["mean"]


#: Bump when :func:`map_numbers` changes meaning, so cached numbers are recomputed.
MAP_NUMBERS_VERSION = "1"


def map_numbers(healthy, cracked, cracks: bool, dd_op: float, cache=None) -> dict:
    """The numbers the study reads off its two maps, through the cache (kind ``map values``).

    Evaluating a map starts numba (0.3-0.4 s to load the compiled lookup), which a run whose
    records come from the cache needs for nothing else (issue 16). Keyed by the maps' content,
    ``cracks``, ``dd_op`` and geardyn's sources; the values are stored as JSON (Python's float
    text round-trips exactly).

    Parameters
    ----------
    healthy, cracked : StiffnessMap
    cracks : bool
        Whether the case has an active crack (the crack angles are computed only then).
    dd_op : float
        Centre distance change of the static operating point [m], within the maps.

    Returns
    -------
    dict
        ``"mean"``: mean healthy mesh stiffness [N/m] over one period at +0.0, +0.5 and
        +1.0 mm (those the map covers), keyed ``"+0.5mm"``; with ``cracks``,
        ``"crack_angle_op"`` and ``"crack_angle_0"``: pinion angle [rad] where the cracked map
        falls furthest below the healthy one, at ``dd_op`` and at 0
        (:func:`geardyn.stiffness.plots.crack_angle`).
    """
    import json

    from ..cache import default_cache
    from .paper_cache import fingerprint
    from .paper_result import _source_digest

    def build() -> dict:
        from ..stiffness.plots import crack_angle

        th = np.linspace(0.0, healthy.period, 4096, endpoint=False)
        out: dict = {"mean": {f"{dd * 1e3:+.1f}mm": float(np.mean(healthy(th, dd)))
                              for dd in (0.0, 0.5e-3, 1.0e-3) if healthy.covers(dd)}}
        if cracks:
            out["crack_angle_op"] = crack_angle(healthy, cracked, dd_op)
            out["crack_angle_0"] = crack_angle(healthy, cracked, 0.0)
        return out

    key = fingerprint("map numbers", MAP_NUMBERS_VERSION, healthy, cracked, bool(cracks),
                      float(dd_op), _source_digest())[:32]
    data, _ = (cache or default_cache()).get_or_build(
        "map values", key, ".json", build,
        save=lambda obj, path: Path(path).write_text(json.dumps(obj)),
        load=lambda path: json.loads(Path(path).read_text()))
    return data


#: Bump when the simulation or its inputs change meaning, so cached records are recomputed.
SIMULATION_CACHE_VERSION = "3"  # 2: stored as .npz; 3: every numeric attribute with its units


#: ``--quick`` maps: FE mesh refinement and centre distances at most these (measured on the paper
#: case: mean stiffness within 0.1 % of the default maps at +1 mm, built in a third of the time).
QUICK_REFINEMENT = 0.5
QUICK_CENTRE_DISTANCES = 11


def _map_case(case: Case, quick: bool) -> Case:
    """The case the stiffness maps are built from (coarser with ``--quick``)."""
    return quick_map_case(case) if quick else case


def quick_map_case(case: Case) -> Case:
    """The case whose stiffness maps a ``--quick`` run builds (``geardyn run``, ``geardyn
    crack-growth``): the FE mesh refinement at most :data:`QUICK_REFINEMENT` and at most
    :data:`QUICK_CENTRE_DISTANCES` centre distances; ``case`` itself where it is that coarse."""
    st = case.stiffness
    ov = {}
    if st.method == "fe" and st.fe.refinement > QUICK_REFINEMENT:
        ov["stiffness.fe.refinement"] = QUICK_REFINEMENT
    if st.centre_distances > QUICK_CENTRE_DISTANCES:
        ov["stiffness.centre_distances"] = QUICK_CENTRE_DISTANCES
    return case.with_overrides(ov) if ov else case


def _simulation_case(case: Case, quick: bool) -> Case:
    """The case used for the simulations (shorter with ``--quick``)."""
    if not quick:
        return case
    sim = case.simulation
    return case.with_overrides({"simulation.settle_time": min(sim.settle_time, 0.1),
                                "simulation.record_time": min(sim.record_time, 0.3)})


#: Variables a cached simulation record must hold (a damaged entry is rebuilt).
_RECORD_REQUIRED = ("theta_p", "v_yg")


def _simulation_key(case: Case, stiffness_map, model: str) -> str:
    """Cache key of a simulation record: the case text, the map's inputs hash, the model and
    the geardyn version."""
    from .._version import __version__
    from ..cache import cache_key

    return cache_key({"case": case_to_toml(case), "map": stiffness_map.attrs.get("inputs_hash"),
                      "model": model, "geardyn": __version__,
                      "version": SIMULATION_CACHE_VERSION})


def cached_simulation(case: Case, stiffness_map, model: str, cache=None):
    """:func:`geardyn.dynamics.simulate` through the on-disk cache (keyed by the case text, the
    map's inputs hash, the model and the geardyn version)."""
    from ..cache import default_cache
    from ..dynamics import simulate
    from .paper_cache import load_dataset, save_dataset

    cache = cache or default_cache()
    # stored as .npz (:func:`.paper_cache.save_dataset`): the record read back is the one
    # computed, attribute types included, and it is written in milliseconds (a compressed
    # NetCDF took 0.13-0.28 s per record; the cache holds it uncompressed, about twice the bytes)
    ds, _ = cache.get_or_build(
        "simulation", _simulation_key(case, stiffness_map, model), ".npz",
        build=lambda: simulate(case, stiffness_map, model=model),
        save=save_dataset,
        load=lambda path: load_dataset(path, required=_RECORD_REQUIRED))
    return ds


class CachedRecords(Mapping):
    """``(model, state)`` -> simulation record (Dataset), read from the simulation cache at
    each access instead of held in memory.

    The cache's ``.npz`` is the record exactly as computed (:func:`.paper_cache.load_dataset`),
    so every access returns equal data; an entry that went missing or was damaged since (a
    ``geardyn cache prune`` meanwhile) is simulated again through the cache. A run holds one
    or two records at a time instead of all seven (106 MB on the paper's case: the diagnostics
    and measurement stages were the peak of a one-process run's memory). Without a disk cache
    the records are held, as a dict would.
    """

    def __init__(self, cache=None):
        from ..cache import default_cache

        self._cache = cache or default_cache()
        self._jobs: dict = {}
        self._held: dict = {}

    def add(self, key, ds, case: Case, stiffness_map, model: str) -> None:
        """Record ``ds``, the cached simulation of ``model`` on ``case`` and ``stiffness_map``."""
        self._jobs[key] = (case, stiffness_map, model)
        if not self._cache.enabled:
            self._held[key] = ds

    def __getitem__(self, key):
        if key in self._held:
            return self._held[key]
        case, stiffness_map, model = self._jobs[key]
        from .paper_cache import load_dataset

        ckey = _simulation_key(case, stiffness_map, model)
        path = self._cache.path("simulation", ckey, ".npz")
        # its checksum first, as the cache checks it; unreadable or gone, cached_simulation
        # discards and rebuilds it
        with contextlib.suppress(Exception):
            if self._cache.valid(path, ckey):
                return load_dataset(path, required=_RECORD_REQUIRED)
        return cached_simulation(case, stiffness_map, model, cache=self._cache)

    def __iter__(self):
        return iter(self._jobs)

    def __len__(self) -> int:
        return len(self._jobs)


def _fault_angle(case: Case, result: StudyResult) -> float | None:
    """Pinion angle [rad] of the fault events Figs. 8-10 are centred on and mark: where the
    faulty map falls furthest below the healthy one, at 0 mm (for a crack the stiffness stage
    has it). For a fault other than a crack only where that loss reaches :data:`FAULT_DIP`;
    None for a healthy pair or a fault the maps do not show."""
    if "cracked" not in result.maps or not fault_word(case):
        return None
    crack = case.active_crack is not None
    if crack and result.crack_angle_rad is not None:
        return result.crack_angle_rad
    from ..stiffness.plots import fault_dip

    angle, ratio = fault_dip(result.maps["healthy"], result.maps["cracked"], 0.0)
    return angle if crack or ratio < 1.0 - FAULT_DIP else None


#: Variables of a simulation record stored as float32 in ``runs/*.nc``: derived quantities that
#: are only shown (Figs. 8-10) or averaged to 4-5 significant digits, never fed back into a
#: computation; float32 keeps 7 significant digits. The state variables, ``time``, the angles
#: and the three diagnosed signals stay float64: the TSA resamples against ``theta_p`` (tens of
#: rad, where float32 would leave 1e-5 rad of error) and the residuals are 1e-3 to 1e-6 of
#: the signals.
RUN_ENCODING_FLOAT32 = ("pressure_angle", "contact_ratio", "contact_ratio_eq8", "mesh_stiffness",
                        "residual_before", "residual_after")


def _encoding(ds, float32: tuple[str, ...] = ()) -> dict:
    enc = {}
    for name, var in ds.variables.items():
        if var.dtype.kind not in "biuf" or var.ndim == 0:
            continue
        e = dict(NETCDF_COMPRESSION)
        if name in float32 and var.dtype == np.float64:
            e["dtype"] = "float32"
        enc[name] = e
    return enc


def run_file_name(model: str, state: str) -> str:
    """File name of one simulation record in ``runs/``, e.g. ``model_II_cracked.nc``."""
    return f"model_{model}_{state}.nc"


def write_run_netcdf(ds, path: Path) -> None:
    """One simulation record as a compressed NetCDF-4 file (atomic): opens with
    ``xarray.open_dataset`` and is accepted by ``geardyn diagnose``."""
    from ..io import atomic_path, to_netcdf

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path, suffix=".nc") as tmp:
        to_netcdf(ds, tmp, encoding=_encoding(ds, RUN_ENCODING_FLOAT32))


def _write_run_file(ds, path: Path) -> None:
    """:func:`write_run_netcdf` through the cache (:func:`.paper_cache.write_output`): a run
    into another folder copies the bytes an earlier run wrote for the same record."""
    from ..io import to_netcdf
    from .paper_cache import write_output

    def write(tmp: Path) -> None:
        to_netcdf(ds, tmp, encoding=_encoding(ds, RUN_ENCODING_FLOAT32))

    write_output(path, "run", (ds, list(ds.variables)),
                 {"float32": RUN_ENCODING_FLOAT32, "compression": NETCDF_COMPRESSION}, write)


#: The record variables the dynamics figures read (besides ``time``): Fig. 8's design
#: parameters and crack events, Fig. 9's iteration residuals (the start-of-step record).
FIG8_VARIABLES = ("centre_distance_change", "pressure_angle", "contact_ratio",
                  "contact_ratio_eq8", "theta_p")
FIG9_VARIABLES = ("residual_before", "residual_after", "iterations", "mesh_stiffness", "theta_p")


def _variables(ds, names: tuple[str, ...]) -> dict:
    """The time [s] and the data variables ``names`` of the record ``ds``, as a dict of NumPy
    arrays: the same arrays, not copies, so the others go when ``ds`` does. A figure drawn by
    the figure process then unpickles arrays only: that process imports no xarray or pandas
    (0.2 s and about 40 MB, measured 2026-11-27)."""
    return {name: ds[name].values for name in ("time", *names)}


#: Longest wait [s] for a second process compiling the time-step kernel (it takes 5-15 s on a
#: 2-core machine); after it, this process compiles the kernel itself.
KERNEL_COMPILE_WAIT_S = 60.0


def _wait_for_the_kernel(result: StudyResult) -> float:
    """Wait for ``result.kernel_compiler`` to put the time-step kernel into numba's cache,
    rather than compile it here too, drawing held figures meanwhile; at most
    :data:`KERNEL_COMPILE_WAIT_S`. No wait where numba's cache holds the kernel already or the
    process has ended (whatever it did: this process then loads or compiles the kernel itself).

    Both processes compiled it at once in a first ``geardyn run`` until 2026-11-28: the FE
    bodies' process compiles it after the cracked body, and this one reached its simulations
    first (``py-spy`` of a cold run: 7.6 s of compilation here, the kernel's 13.6 s there,
    and this process had drawn none of its held figures).

    Returns
    -------
    float
        The time waited [s].
    """
    import time

    proc = result.kernel_compiler
    if proc is None:
        return 0.0
    from ..dynamics.warm import kernels_compiled

    t0 = time.monotonic()
    deadline = t0 + KERNEL_COMPILE_WAIT_S

    def waiting() -> bool:
        return proc.is_alive() and time.monotonic() < deadline and not kernels_compiled()

    result.figures.draw_held_while(waiting)
    while waiting():
        proc.join(timeout=0.1)
    return time.monotonic() - t0


def simulation_stage(case: Case, out: Path, result: StudyResult) -> None:
    """Model I, I-static and II, cracked and healthy; the paper's flow-chart variant for Fig. 9;
    the model comparison (:func:`model_comparison`).

    Each record is also written to ``runs/model_<M>_<state>.nc`` (compressed, one file per run).
    """
    from ..dynamics import summary as sim_summary
    from ..faults import without_faults
    from . import paper_figures as pf

    sim_case = _simulation_case(case, result.quick)
    _wait_for_the_kernel(result)
    runs = {}  # held for this stage's figures and numbers; the later stages read `records`
    records = CachedRecords()
    jobs = [("I", "cracked"), ("I-static", "cracked"), ("II", "cracked"), ("I", "healthy"),
            ("I-static", "healthy"), ("II", "healthy"), ("II-start", "cracked")]
    rev = 2 * math.pi / (case.load.speed or 114.14)
    scheme_case = sim_case.with_overrides({
        "simulation.stiffness_evaluation": "start",
        "simulation.record_time": min(sim_case.simulation.record_time, 2.2 * rev)})
    total = len(jobs)
    healthy_case = without_faults(sim_case)  # no wear gap on the healthy pair
    for i, (model, state) in enumerate(jobs):
        label = (f"model {model}, {state}" if model != "II-start"
                 else "model II, paper's start-of-step scheme")
        result.emit(f"simulation: {label}", i, total)
        if model == "II-start":
            job = (scheme_case, result.maps[state], "II")
        else:
            job = (sim_case if state == "cracked" else healthy_case, result.maps[state], model)
        ds = cached_simulation(*job)
        runs[(model, state)] = ds
        records.add((model, state), ds, *job)
        path = out / "runs" / run_file_name(model, state)
        _write_run_file(ds, path)
        result.files[f"run {model} {state}"] = path
        result.emit(f"simulation: {label}", i + 1, total)
    result.sims = records

    ds2 = runs[("II", "cracked")]
    summ = {f"model_{m}_{st}": sim_summary(ds) for (m, st), ds in runs.items()}
    result.summary["simulations"] = summ
    result.summary["run_files"] = {f"model_{m}_{st}": f"runs/{run_file_name(m, st)}"
                                   for (m, st) in runs}
    s2 = summ["model_II_cracked"]
    s = result.summary
    s["centre_distance_change_mm"] = s2["mean_centre_distance_change_m"] * 1e3
    s["operating_pressure_angle_deg"] = s2["mean_pressure_angle_deg"]
    s["contact_ratio"] = {"physical": s2["mean_contact_ratio"],
                          "paper_eq8": s2["mean_contact_ratio_eq8"]}
    s["mean_pinion_speed_rad_s"] = s2["mean_pinion_speed_rad_s"]
    s["mean_transmission_error_rad"] = s2["mean_transmission_error_rad"]
    s.setdefault("sources", {})["centre_distance_change_mm"] = (
        "mean over the model II record with the crack (simulation stage)")

    # Figs. 8-10 around the first fault event of the record (its middle when the maps do not
    # locate the fault); the events recur with the faulty map's period (one revolution of the
    # faulty gear)
    ca = _fault_angle(case, result)
    result.crack_angle_rad = ca
    period = result.maps["cracked"].period if ca is not None else 2 * math.pi
    if ca is not None:
        s["fault_event_angle_deg"] = math.degrees(ca)
        s["fault_event_period_deg"] = math.degrees(period)
    t = ds2["time"].values
    tcs = pf.crack_times(ds2, ca, period) if ca is not None else np.array([])
    tc = float(tcs[0]) if tcs.size else float(t[0] + 0.5 * (t[-1] - t[0]))
    half = 0.55 * rev
    w8 = (max(t[0], tc - half), min(t[-1], tc + half))
    faulty, fault = faulty_words(case)
    # each figure gets only the variables it draws (a figure queued for the figure process
    # holds its arguments until drawn: a full run's record is 24 variables, 19 MB)
    result.figures.cached("fig8_design_parameters", pf.fig8_design_parameters,
                          _variables(ds2, FIG8_VARIABLES), ca, w8, fault=fault,
                          period=period)
    ds_s = runs[("II-start", "cracked")]
    ts = ds_s["time"].values
    tcs_s = pf.crack_times(ds_s, ca, period) if ca is not None else np.array([])
    tc_s = float(tcs_s[0]) if tcs_s.size else float(ts[0] + 0.5 * (ts[-1] - ts[0]))
    w9 = (max(ts[0], tc_s - 0.012), min(ts[-1], tc_s + 0.012))
    result.figures.cached("fig9_iteration", pf.fig9_iteration,
                          _variables(ds_s, FIG9_VARIABLES), _variables(ds2, ("residual_before",)),
                          ca, w9, case.simulation.tolerance, period=period)
    result.figures.cached("fig10_stiffness", pf.fig10_stiffness,
                          _variables(runs[("I", "cracked")], ("mesh_stiffness",)),
                          _variables(ds2, ("mesh_stiffness", "theta_p")), ca, w8,
                          ds_i_static=_variables(runs[("I-static", "cracked")],
                                                 ("mesh_stiffness",)), period=period)
    result.summary["model_comparison"] = model_comparison(runs)
    if result.summary["model_comparison"]:
        result.figures.cached("fig_model_comparison", pf.fig_model_comparison,
                              result.summary["model_comparison"], faulty=faulty)


#: Share of the samples whose differences :func:`model_comparison` reports the energy of
#: (``top_share``): the largest 1 % of ``|II - I-static|``.
TOP_SAMPLE_FRACTION = 0.01


def model_comparison(runs: dict) -> dict:
    """How much of the model II - model I difference the static centre-distance shift explains.

    :func:`~.model_compare.compare_models` of the model I, I-static and II records of each state,
    plus, per signal, ``top_share``: the share of the squared difference ``(II - I-static)^2``
    carried by the largest :data:`TOP_SAMPLE_FRACTION` of its samples (near 1 when the
    difference sits in isolated steps, such as a tooth handover that falls in a different time
    step for the two models; about 0.01-0.05 for a difference spread over the record).

    Parameters
    ----------
    runs : dict
        ``(model, state) -> record`` of :func:`geardyn.dynamics.simulate`.

    Returns
    -------
    dict
        ``state -> {"signals": {signal: {"units", "rms_ii_minus_i_static", "rms_ii_minus_i",
        "explained_fraction", "top_share"}}, "static_centre_distance_change_mm": float,
        "units": ..., "definitions": ...}`` (dimensionless ratios, ``units = "1"``), for each
        state whose three records exist.
    """
    from .model_compare import compare_models

    out: dict = {}
    for state in ("cracked", "healthy"):
        keys = [("I", state), ("I-static", state), ("II", state)]
        if not all(k in runs for k in keys):
            continue
        cmp = compare_models(*(runs[k] for k in keys))
        signals = {}
        for i, sig in enumerate(cmp["signal"].values):
            sig = str(sig)
            d = (np.asarray(runs[("II", state)][sig].values, dtype=float)
                 - np.asarray(runs[("I-static", state)][sig].values, dtype=float))
            e = np.sort(d * d)[::-1]
            n_top = max(1, int(math.ceil(TOP_SAMPLE_FRACTION * e.size)))
            tot = float(e.sum())
            signals[sig] = {
                "units": str(cmp["signal_units"].values[i]),
                **{v: float(cmp[v].values[i]) for v in ("rms_ii_minus_i_static",
                                                         "rms_ii_minus_i",
                                                         "explained_fraction")},
                "top_share": float(e[:n_top].sum()) / tot if tot > 0 else float("nan")}
        out[state] = {
            "signals": signals,
            "static_centre_distance_change_mm": 1e3 * float(
                cmp.attrs["static_centre_distance_change"]),
            "units": "1 (ratios); signals' units in 'units'",
            "definitions": {
                **{v: cmp[v].attrs["long_name"] for v in ("rms_ii_minus_i_static",
                                                          "rms_ii_minus_i",
                                                          "explained_fraction")},
                "top_share": f"share of sum (II - I-static)^2 in the largest "
                             f"{100 * TOP_SAMPLE_FRACTION:g} % of the samples"}}
    return out


def _diagnosis_inputs(case: Case, ds) -> dict:
    """The keyword arguments of :func:`geardyn.diagnostics.diagnose` for one record."""
    d = case.diagnostics
    return dict(signals={k: ds[k].values for k in SIGNAL_KEYS}, teeth=case.pinion.teeth,
                angle=ds["theta_p"].values, time=ds["time"].values,
                samples_per_rev=d.samples_per_rev, harmonic=d.harmonic, bandwidth=d.bandwidth,
                residual_preset=d.residual_preset,
                units={"v_yg": "m/s", "omega_p": "rad/s", "transmission_error": "rad"},
                source=f"geardyn simulation, model {ds.attrs.get('model')}",
                doubt_teeth=False)  # the case states them (a worn flank's gap: order 6)


def _diagnose_run(case: Case, ds):
    from ..diagnostics import diagnose

    return diagnose(**_diagnosis_inputs(case, ds))


def paper_tables(cracked: dict) -> tuple[dict, dict]:
    """Tables 2 and 3 of the paper from the diagnoses of the cracked records.

    Parameters
    ----------
    cracked : dict
        ``"I"``, ``"II"`` and optionally ``"I-static"`` -> diagnosis
        (:func:`geardyn.diagnostics.diagnose`) of the cracked record of that model (the paper
        has no I-static: its values are geardyn's only).

    Returns
    -------
    table2, table3 : dict
        ``table[signal][model][statistic]`` (signals by their ``summary.json`` names).
    """
    t2: dict = {}
    t3: dict = {}
    for sig, name in SIGNAL_KEYS.items():
        t2[name], t3[name] = {}, {}
        for m in [m for m in ("I", "I-static", "II") if m in cracked]:
            sd = cracked[m].signals[sig]
            st = sd.statistics
            t2[name][m] = {"mean": st.mean, "std": st.std, "skewness": st.skewness,
                           "kurtosis": st.kurtosis, "crest_factor": st.crest_factor}
            t3[name][m] = {"envelope_kurtosis": sd.envelope_kurtosis,
                           "am_kurtosis": sd.am_kurtosis, "pm_kurtosis": sd.pm_kurtosis,
                           "residual_kurtosis": sd.residual_kurtosis,
                           "pm_mean_deg": float(np.degrees(np.mean(sd.demodulation.pm)))}
    return t2, t3


def _healthy_teeth_differ(case: Case) -> bool:
    """Whether the healthy pair's teeth differ from one another: per-tooth errors (pitch,
    slope, form) or runout of the case's ``[modifications]`` (a tip relief on every tooth
    alike keeps the mesh period; the faults' wear is not the healthy pair's)."""
    from ..faults import without_faults
    from ..modifications import ToothModifications

    m = ToothModifications.from_case(without_faults(case))
    return m.has_runout or m.pinion.has_table or m.gear.has_table


def healthy_baseline_is_periodic(healthy_map, rtol: float = 1e-6) -> bool:
    """Whether every mesh cycle of the healthy map is the same (all teeth alike, no tooth errors).

    Then the healthy steady state repeats every mesh period: its synchronous average holds only
    mesh harmonics, and its residual and difference signals are zero in exact arithmetic (what a
    record holds there is integration error, unsettled start-up transient and finite
    averaging). Metrics that divide by them (NA4* with this baseline, the cracked / healthy
    energy ratio) are then undefined.

    Parameters
    ----------
    healthy_map : StiffnessMap
    rtol : float
        Largest cycle-to-cycle difference, relative to the largest value, still taken as equal.
    """
    arrays = [("k_mb", np.asarray(healthy_map.k_mb))]
    arrays += [(k, np.asarray(v)) for k, v in healthy_map.extra.items()
               if k not in ("load_share", "load_share_exiting")]
    nc = healthy_map.n_cycles
    for _, a in arrays:
        if a.ndim < 2 or a.shape[1] % nc:
            continue
        per = a.reshape(a.shape[0], nc, a.shape[1] // nc, *a.shape[2:])
        scale = float(np.max(np.abs(per))) or 1.0
        if float(np.max(np.abs(per - per[:, :1]))) > rtol * scale:
            return False
    return True


#: Why NA4* and the energy-ratio change are undefined for an ideal healthy baseline.
UNDEFINED_BASELINE_REASON = (
    "the healthy pair's teeth are all alike (its stiffness map repeats every mesh "
    "cycle), so its steady response repeats every mesh period and its residual and difference "
    "signals are zero in exact arithmetic; the healthy record's values there are integration "
    "error, unsettled start-up transient and finite averaging, and a ratio to them is a number "
    "without meaning")


def diagnostics_stage(case: Case, out: Path, result: StudyResult) -> None:
    """The paper's diagnostics on the three signals; Tables 2, 3; healthy vs cracked."""
    from ..cache import default_cache
    from ..diagnostics import condition_metrics, residual
    from ..diagnostics.metrics import central_moment
    from . import paper_figures as pf
    from .paper_cache import cached_diagnosis, diagnosis_key, fingerprint
    from .paper_result import Deferred

    z = case.pinion.teeth
    cache = default_cache()
    diags, inputs, keys_of = {}, {}, {}
    keys = [k for k in result.sims if k[0] in ("I", "II", "I-static")]
    drawn = (("I", "cracked"), ("II", "cracked"))  # the diagnoses the figures show
    for i, key in enumerate(keys):
        result.emit(f"diagnostics: model {key[0]}, {key[1]}", i, len(keys))
        # through the cache, keyed by the record's signals and the settings (issue 16): a run of
        # the same inputs into another folder diagnoses nothing again
        inputs[key] = _diagnosis_inputs(case, result.sims[key])
        keys_of[key] = diagnosis_key(inputs[key])
        diags[key], _ = cached_diagnosis(inputs[key], keys_of[key], cache)
        result.emit(f"diagnostics: model {key[0]}, {key[1]}", i + 1, len(keys))
    result.diagnoses = diags  # without the PWVD distributions
    cracked = {m: diags[(m, "cracked")] for m in ("I", "II")}

    # the figures know the diagnoses by their cache keys; the PWVD figures compute the two
    # distributions they draw when they are drawn (40 MB each: holding all twelve of the two
    # cracked diagnoses was the peak of a cold run's memory)
    cracked_figs = Deferred(fingerprint("cracked diagnoses", [keys_of[k] for k in drawn]),
                            lambda: cracked)

    t2, t3 = paper_tables({**cracked, **({"I-static": diags[("I-static", "cracked")]}
                                         if ("I-static", "cracked") in diags else {})})
    result.summary["table2"] = t2
    result.summary["table3"] = t3
    # their units, as results.nc's statistic2_units / statistic3_units give them: a mean and an
    # STD in the signal's unit, the shape statistics and the kurtoses dimensionless, a level in
    # degrees where its name says so
    sig_units = {name: cracked["II"].signals[sig].unit for sig, name in SIGNAL_KEYS.items()}
    result.summary["table_units"] = {
        "table2": {g: {k: sig_units[g] if k in ("mean", "std") else "1"
                       for k in next(iter(t2[g].values()), {})} for g in t2},
        "table3": {g: {k: "deg" if k.endswith("_deg") else "1"
                       for k in next(iter(t3[g].values()), {})} for g in t3}}

    # where the crack shows: the peak of the narrowband envelope, per signal and model
    angles = []
    for m in ("I", "II"):
        for sig in SIGNAL_KEYS:
            dem = cracked[m].signals[sig].demodulation
            a = dem.angle[int(np.argmax(dem.envelope))] - dem.angle[0]
            angles.append(math.degrees(a) % 360.0)
    result.summary["crack_angle_deg"] = float(np.median(angles))
    from .paper_values import fault_gears, gear_fault_averaged_out

    averaged = gear_fault_averaged_out(case)
    if averaged:  # a gear-side fault is not located by the pinion's TSA: no angle claimed
        result.summary["gear_fault_averaged_out"] = averaged
        if "pinion" not in fault_gears(case):
            result.summary["crack_angle_deg"] = None
    result.summary["crack_angle_by_signal_deg"] = angles
    result.summary["crack_angle_resolution_deg"] = 360.0 / (2 * case.diagnostics.bandwidth + 1)

    # healthy vs cracked condition metrics (NA4* with the healthy residual as baseline)
    # the healthy record repeats every mesh period only if its map does and its teeth are all
    # alike: tooth errors or runout (the healthy pair keeps them) make a real baseline (the
    # tooth-error example's NA4* was "undefined" for teeth "all alike": a user audit)
    periodic = (healthy_baseline_is_periodic(result.maps["healthy"])
                and not _healthy_teeth_differ(case))
    detect: dict = {}
    # model I-static too (geardyn's addition): whether a metric sees the fault without model
    # II's iteration is the question the model study asks
    for m in [m for m in ("I", "I-static", "II")
              if (m, "healthy") in diags and (m, "cracked") in diags]:
        for sig, name in SIGNAL_KEYS.items():
            h = diags[(m, "healthy")].signals[sig].tsa.average
            c = diags[(m, "cracked")].signals[sig].tsa.average
            v0 = central_moment(residual(h, teeth=z, preset="zakrajsek"), 2)
            mh = condition_metrics(h, teeth=z, na4_baseline_variance=v0)
            mc = condition_metrics(c, teeth=z, na4_baseline_variance=v0)
            row = {"healthy": {k: float(getattr(mh, k)) for k in CONDITION_METRICS},
                   "cracked": {k: float(getattr(mc, k)) for k in CONDITION_METRICS}}
            if periodic:
                for state in ("healthy", "cracked"):
                    row[state]["NA4star"] = None
            detect.setdefault(name, {})[m] = row
    result.summary["condition_metrics"] = detect
    result.summary["condition_metrics_undefined"] = (
        {"NA4star": UNDEFINED_BASELINE_REASON,
         "EnergyRatio cracked / healthy": UNDEFINED_BASELINE_REASON} if periodic else {})

    # Figs. 11-23
    F = result.figures
    F.cached("fig11_tsa", pf.fig_tsa, cracked_figs)
    F.cached("fig12_spectra", pf.fig_spectra, cracked_figs, z)
    F.cached("fig13_residuals", pf.fig_residuals, cracked_figs)
    max_order = 6 * z
    F.cached("fig14_pwvd_tsa_gear", pf.fig_pwvd_pair, cracked_figs, "v_yg", "tsa", z, max_order)
    numbers = {"v_yg": (15, 16, 17), "omega_p": (18, 19, 20), "transmission_error": (21, 22, 23)}
    for sig, (a, b, c) in numbers.items():
        F.cached(f"fig{a}_pwvd_residual_{sig}", pf.fig_pwvd_pair, cracked_figs, sig, "residual",
                 z, max_order)
        F.cached(f"fig{b}_demodulation_{sig}", pf.fig_demodulation_pair, cracked_figs, sig)
        F.cached(f"fig{c}_analytic_{sig}", pf.fig_analytic_pair, cracked_figs, sig)


def _without_distributions(diag):
    """``diag`` with each signal's PWVD distributions emptied (angles and orders kept)."""
    from .paper_cache import without_distributions

    return without_distributions(diag)


def measurement_stage(case: Case, out: Path, result: StudyResult) -> None:
    """The paper's indicators on a realistic measurement (:mod:`.paper_measurement`)."""
    from . import paper_figures as pf
    from .paper_measurement import measurement_stage as run_stage
    from .paper_measurement import reproduce_commands

    sim_case = _simulation_case(case, result.quick)
    run_stage(case, sim_case, result, simulate=cached_simulation)
    m = result.summary["measurement"]
    if "skipped" in m:
        result.notes.append(f"Realistic-measurement section skipped: {m['skipped']}.")
    else:  # the realistic record's own length, as geardyn measure would measure it
        rec = m["records"]["errors+noise|healthy"]
        m["reproduce"] = reproduce_commands(str(out / "case.toml"), case, sim_case,
                                            _map_case(case, result.quick), rec["record_s"])
    if "skipped" not in m and result.measured_tsa:
        result.figures.cached("fig24_measured_tsa", pf.fig_measured_tsa, result.measured_tsa,
                              m["model"], faulty=faulty_words(case)[0])


def _report_stage(case: Case, out: Path, result: StudyResult) -> None:
    from .paper_report import report_stage

    report_stage(case, out, result)


STAGES: list[tuple[str, Callable[[Case, Path, StudyResult], None]]] = [
    ("geometry", geometry_stage),
    ("stiffness", stiffness_stage),
    ("simulation", simulation_stage),
    ("diagnostics", diagnostics_stage),
    ("measurement", measurement_stage),
    ("report", _report_stage),
]


def _validate(result: StudyResult) -> None:
    """Recompute the checks and the comparisons with the paper from the summary so far."""
    result.summary.update(validation_tables(result.summary, paper_case=result.paper_case))


def _quick_settings(case: Case, quick: bool) -> tuple[Case, list[dict]]:
    """The case a run simulates and maps with, and the settings ``--quick`` changed in it.

    Parameters
    ----------
    case : Case
        The user's case (as ``case.toml`` holds it).
    quick : bool
        Whether the run is a ``--quick`` one.

    Returns
    -------
    used : Case
        ``case`` with the shorter records of :func:`_simulation_case` and the coarser maps of
        :func:`quick_map_case`; ``case`` itself without ``--quick``.
    changed : list of dict
        ``{"key", "case", "used"}`` (SI values) for every setting ``--quick`` changed, e.g.
        ``simulation.record_time`` 1.0 s -> 0.3 s; empty without ``--quick`` or where the case
        is already that short and coarse.
    """
    used = _simulation_case(_map_case(case, quick), quick)
    if used is case:
        return case, []
    _, numerical = case_differences(used, reference=case)  # resolutions only: NUMERICAL_KEYS
    return used, [{"key": d["key"], "case": d["paper"], "used": d["case"]} for d in numerical]


def run_paper_study(case: Case | None = None, out: str | Path = "geardyn-out", *,
                    quick: bool = False, stiffness: str | None = None,
                    progress: Progress | None = None) -> StudyResult:
    """Run the paper's case study, or the same study of another case, into ``out``.

    The results are compared with the paper's only when the case's physical inputs are the
    paper's (the stiffness method and numerical resolution may differ); otherwise the report is
    titled by the case and lists what differs.

    Parameters
    ----------
    case : Case, optional
        Default: the paper's case.
    out : path-like
        Output folder (created).
    quick : bool
        Shorter simulations and coarser maps, for a fast look; the summary lists the settings
        it changed (``quick_settings``) and counts them among the ``numerical_differences``
        (marked ``without_quick``), never among the physical ones: ``case.toml`` stays the
        case as given.
    stiffness : {"fe", "pem"}, optional
        Stiffness method; default the case's.
    progress : callable, optional
        ``progress(stage, done, total)``; see :mod:`geardyn.studies.paper_result` for the calls.

    Returns
    -------
    StudyResult
    """
    case = case or paper_case()
    if stiffness is not None:
        case = case.with_overrides({"stiffness.method": stiffness})
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    # the paper-case flag from the case's physical inputs; the numerical settings as the run
    # uses them (with --quick: the shorter records and coarser maps, marked "without_quick")
    inputs, _ = case_differences(case)
    used, quick_changed = _quick_settings(case, quick)
    _, numerical = case_differences(used)
    without_quick = {d["key"]: d["case"] for d in quick_changed}
    for d in numerical:
        if d["key"] in without_quick:
            d["without_quick"] = without_quick[d["key"]]
    result = StudyResult(out=out, progress=progress, quick=quick, paper_case=not inputs,
                         differences=inputs)
    result.figures = FigureStore(_figure_process(result))
    result.summary.update({"case": case.name, "quick": quick,
                           "stiffness_method": case.stiffness.method, "complete": False,
                           "paper_case": not inputs, "differences_from_paper": inputs,
                           "numerical_differences": numerical, "quick_settings": quick_changed})
    if case.load.law == "linear" and case.load.speed:
        result.summary["calibrated_speed_rad_s"] = float(case.load.speed)
    write_text_atomic(out / "case.toml", case_to_toml(case))
    t_start = time.perf_counter()
    try:
        for i, (name, stage) in enumerate(STAGES):
            result.emit(name, i, len(STAGES))
            t0 = time.perf_counter()
            stage(case, out, result)
            # what the stage freed goes back to the operating system, not only to this
            # process's allocator: 40-75 MB a stage, while the figure process may be drawing
            # (geardyn.heap)
            release_free_memory()
            result.seconds[name] = time.perf_counter() - t0
            result.stages.append(name)
            result.summary["stages"] = list(result.stages)
            result.summary["run_time_s"] = dict(result.seconds)
            _validate(result)
            write_json_atomic(out / "summary.json", result.summary)
    finally:
        result.figures.close()  # the figure process, if any, stopped (an error, Ctrl-C)
    result.emit("done", len(STAGES), len(STAGES))
    result.summary["complete"] = True
    result.summary["run_time_s"] = {**result.seconds, "total": time.perf_counter() - t_start}
    write_json_atomic(out / "summary.json", result.summary)
    return result
