"""Every check of a case that needs neither a simulation nor an expensive computation
(``geardyn config validate``), in one place that the commands call too.

:func:`check_case` runs, in order, the checks the later stages would run anyway, so that a case
``config validate`` accepts is not refused by ``simulate`` or ``measure`` before they step
(issue 13: a 50 mm crack passed validation and failed at simulation; QA: ``simulation.dt = 5``,
``measurement.fs = "10 Hz"`` and ``measurement.snr = -500`` passed validation). It adds no
physics of its own; each check is the stage's own code:

1. the faults' geometry (:func:`geardyn.faults.check_faults`, as :func:`geardyn.load_case`
   runs it) and the gear pair (:meth:`geardyn.config.Case.gear_pair`: teeth, radii, bore,
   profile shift);
2. the operating geometry over the stiffness map's centre-distance range
   (:meth:`geardyn.geometry.GearPair.operating`: contact ratio >= 1, centre distance above the
   base-radius sum), reported on ``stiffness.centre_distance_min``/``_max``;
3. the stiffness method's own model: for ``pem``, :class:`geardyn.stiffness.pem.PEMModel` (crack
   tooth number, the crack geometry of :func:`geardyn.stiffness.pem.crack_geometry` through the
   cracked tooth section, pointed teeth) and its ``check_range`` (interference over the range);
   for ``fe``, :class:`geardyn.stiffness.fe.model.FESettings` (mesh size resolves the Hertz
   patch, element sizes) and :func:`geardyn.stiffness.fe.mesh.crack_segment` (the crack stays in
   the tooth and the rim);
4. the load laws (the steady speed and the calibration of the output law of
   :mod:`geardyn.dynamics.model`);
5. the bounded-work check of the simulation (step count and record size,
   :func:`geardyn.run_limits.check_bounded_work`);
6. the model options (:func:`geardyn.dynamics.newmark.check_model_options`: friction needs
   the transverse model, which has no HHT and no load family), the faults the stiffness method cannot model
   (:func:`geardyn.faults.check_method`) and the load family's torques
   (:func:`geardyn.stiffness.build_load_family`);
7. the set-up of the simulation on the case's stiffness map: :func:`geardyn.dynamics.simulate`
   itself runs on a one-step copy of the case and is stopped at its first progress report,
   before the first time step, so every check it makes before stepping runs (the time-step
   limit from the highest natural frequency of the largest mesh stiffness, the static operating
   point and the map's coverage of it, the speed profile, the tooth modifications, the kernel
   set-up; the transverse model's bearing modes). A PEM map costs about 0.1 s (measured on the
   paper's case; the eigenvalue problem and the set-up about 0.01 s) and is computed, not
   stored in the cache; an FE map costs seconds to minutes, so it is only used when it is
   already in the cache (``geardyn stiffness`` or a simulation puts it there; with
   ``stiffness.fe.torques``, the map of each torque too). Without it, the time step is checked
   against a bound that needs no map (10 steps a period of the mesh frequency and of the
   highest natural frequency without mesh stiffness: the map can only lower the limit), the
   speed profile and the map range's coverage of the static centre distance are checked, and
   :func:`check_case` returns a note saying what was not checked;
8. the measurement chain of ``geardyn measure`` (:func:`check_measurement`: the sensor and
   transfer path settings, the sample rate against the simulation's rate ``1/(dt
   decimation)``, the lengthened simulation's bounded work). With no ``[measurement]`` section a
   failure of the default chain is a note, not an error (only ``measure`` uses it).
"""

from __future__ import annotations

import math

__all__ = ["check_case", "check_measurement", "UNCHECKED_WITHOUT_FE_MAP"]

#: What :func:`check_case` cannot check for an FE case whose map is not in the cache.
UNCHECKED_WITHOUT_FE_MAP = (
    "the time-step limit from the largest mesh stiffness (checked only against the mesh "
    "frequency and the modes without mesh stiffness), the mesh stiffness at the static "
    "operating point, the tooth modifications and the kernel set-up")


def _relabel(exc, field: str):
    """The same error on a case field (keeps GeometryError vs InputError)."""
    return type(exc)(field, exc.value, exc.allowed)


def check_case(case, *, cache=None) -> list[str]:
    """Run every check of ``case`` that needs neither a simulation nor an expensive computation.

    Parameters
    ----------
    case : geardyn.config.Case
    cache : geardyn.cache.Cache, optional
        Where an FE map is looked up (never built or stored); default
        :func:`geardyn.cache.default_cache`. (The simulation's set-up reads the maps of a load
        family, ``stiffness.fe.torques``, from the default cache.)

    Returns
    -------
    list of str
        Notes naming what could not be checked (empty when every check ran): the checks that
        need an FE map that is not in the cache, and a default measurement chain that
        ``geardyn measure`` would refuse.

    Raises
    ------
    geardyn.errors.InputError
        (or its subclass GeometryError) naming the case field (``crack.depth``,
        ``stiffness.fe.mesh_size``, ``simulation.dt``, ``measurement.fs``, ...), the value and
        what is allowed.
    """
    from .errors import GeometryError, InputError
    from .stiffness import centre_distance_grid

    if case.faults:  # as load_case runs them (config show and validate load without them)
        from .faults import check_faults

        check_faults(case)
    pair = case.gear_pair()
    dd = centre_distance_grid(case)
    ends = (("stiffness.centre_distance_min", float(dd[0])),
            ("stiffness.centre_distance_max", float(dd[-1])))
    for field, d in ends:
        try:
            pair.operating(d)
        except GeometryError as exc:
            raise _relabel(exc, field) from None

    crack = case.active_crack
    if crack is not None:
        z = pair.pinion.teeth if crack.gear == "pinion" else pair.gear.teeth
        if crack.tooth >= z:
            raise InputError("crack.tooth", crack.tooth,
                             f"a tooth number in [0, {z - 1}] of the {crack.gear}")
    if case.stiffness.method == "pem":
        _check_pem(case, dd)
    else:
        _check_fe(case, pair, crack)

    _check_loads(case, pair)
    from .run_limits import check_bounded_work

    check_bounded_work(case)
    notes = _check_dynamics(case, cache)
    try:
        check_measurement(case)
    except InputError as exc:
        if case.measurement is not None:
            raise
        notes.append(f"'geardyn measure' would refuse the default [measurement] chain with "
                     f"this case: {exc}")
    return notes


def check_measurement(case):
    """Check what ``geardyn measure`` needs beyond the simulation; return the chain.

    The chain of the case's ``[measurement]`` section (its defaults when absent,
    :func:`geardyn.studies.measure.chain_from_config`: transfer path, sensor, ADC, noise, SNR,
    tachometer), its sample rate against the simulation's rate ``1/(dt decimation)``
    (:meth:`geardyn.measurement.MeasurementChain.check_input_rate`, which the chain checks again
    on the simulated record), and the bounded work of the simulation lengthened by the chain's
    lead-in and tail (:func:`geardyn.studies.measure.simulated_case`).

    Returns
    -------
    geardyn.measurement.MeasurementChain

    Raises
    ------
    geardyn.errors.InputError
        Naming the ``measurement.*`` (or ``simulation.*``) field.
    """
    from .run_limits import check_bounded_work
    from .studies.measure import chain_from_config, simulated_case

    chain = chain_from_config(case.measurement)
    sim = case.simulation
    chain.check_input_rate(1.0 / (sim.dt * sim.decimation))
    check_bounded_work(simulated_case(case, chain))
    return chain


def _check_pem(case, dd) -> None:
    from .errors import GeometryError
    from .stiffness.pem import PEMModel

    pem = PEMModel.from_case(case, cracked=True)  # builds the cracked section: crack geometry
    try:
        pem.check_range(dd)
    except GeometryError as exc:  # named as the map builder names it, with the start that works
        from .stiffness import _grid_error

        raise _grid_error(case, dd, exc) from None


def _check_fe(case, pair, crack) -> None:
    from .stiffness.fe.mesh import CrackGeometry, crack_segment
    from .stiffness.fe.model import FESettings

    settings = FESettings.from_case(case)
    settings.check()
    settings.mesh_settings()  # element sizes in order
    if crack is not None:
        gear = pair.pinion if crack.gear == "pinion" else pair.gear
        crack_segment(gear, CrackGeometry(depth=float(crack.depth), angle=float(crack.angle)))


def _check_loads(case, pair) -> None:
    from .dynamics import model as dm

    law_in = dm._input_law(case)
    dm._output_law_and_speed(case, law_in, pair.pinion.base_radius, pair.gear.base_radius,
                             case.pinion.torsional_damping, case.gear.torsional_damping)


# ------------------------------------------------------------------ the simulation's set-up
class _NotCached(Exception):
    """An FE map that is not in the cache (it is never built here)."""


class _SetUpDone(Exception):
    """Raised by the progress callback at the first report, before the first time step."""


def _cached_only(cache):
    """A view of ``cache`` that returns valid entries and raises :class:`_NotCached` instead of
    building (and never stores)."""
    from .cache import Cache, default_cache

    base = cache if cache is not None else default_cache()

    class CachedOnly(Cache):
        def get_or_build(self, kind, key, suffix, build, save, load):
            path = self.path(kind, key, suffix)
            if self.enabled and self.valid(path, key):
                try:
                    return load(path), True
                except Exception:  # unreadable entry: as if missing (simulate rebuilds it)
                    pass
            raise _NotCached(kind)

    return CachedOnly(base.root, base.enabled)


def _check_dynamics(case, cache) -> list[str]:
    """Checks 6-7 of the module docstring; the notes of what was not checked."""
    from .dynamics.newmark import check_model_options
    from .faults import check_method
    from .stiffness import build_load_family, build_map, centre_distance_grid

    check_model_options(case)
    method = case.stiffness.method
    check_method(case, method)  # as build_map does
    if method == "pem":  # cheap (about 0.1 s): computed as build_map does, not stored
        from .stiffness.pem import pem_map

        stiffness_map = pem_map(case, centre_distance_grid(case), cracked=True)
    else:
        lookup = _cached_only(cache)
        try:
            build_load_family(case, cracked=True, cache=lookup)  # checks its torques first
            stiffness_map = build_map(case, method="fe", cracked=True, cache=lookup)
        except _NotCached:
            _check_without_map(case)
            return [f"the FE map of this case is not in the cache, so these were not checked: "
                    f"{UNCHECKED_WITHOUT_FE_MAP}; build it with 'geardyn stiffness' (or a "
                    f"simulation; seconds to minutes), then validate again"]
    _set_up_simulation(case, stiffness_map)
    return []


def _set_up_simulation(case, stiffness_map) -> None:
    """Run :func:`geardyn.dynamics.simulate` on a one-step copy of ``case`` up to its first
    progress report (before the first step): every check it makes before stepping."""
    from .dynamics import simulate

    sim = case.simulation
    one_step = case.model_copy(update={"simulation": sim.model_copy(
        update={"settle_time": 0.0, "record_time": sim.dt})})

    def stop(done: int, total: int) -> None:
        raise _SetUpDone

    try:
        simulate(one_step, stiffness_map, cracked=True, progress=stop)
    except _SetUpDone:
        pass


class _NoMesh:
    """A stand-in map on the case's centre-distance grid for the checks that read no stiffness
    value: ``k`` everywhere [N/m] (0: the model's matrices without the mesh)."""

    def __init__(self, dd, k: float = 0.0):
        import numpy as np

        self.dd = np.asarray(dd, float)
        self.period = 2.0 * math.pi
        self.k = float(k)
        self.k_mb = np.full((1, 1), self.k)

    def __call__(self, theta, dd=0.0):
        import numpy as np

        shape = np.broadcast(np.asarray(theta, float), np.asarray(dd, float)).shape
        return np.full(shape, self.k)

    def covers(self, dd: float) -> bool:
        from .stiffness.map import StiffnessMap

        return StiffnessMap.covers(self, dd)


def _check_without_map(case) -> None:
    """What of the set-up needs no map: the time step against the mesh frequency and the
    highest natural frequency without mesh stiffness (adding the mesh stiffness only raises the
    frequencies, so a step refused here is refused by ``simulate`` too), the transverse
    model's bearing modes, the speed profile, and the static state's checks that read no
    stiffness value (the mesh is loaded; the map's range covers the static centre distance)."""
    from .dynamics.model import (
        MIN_STEPS_PER_PERIOD,
        DynamicModel,
        max_time_step,
        static_equilibrium,
    )
    from .dynamics.newmark import _speed_profile, case_arithmetic
    from .errors import InputError
    from .stiffness import centre_distance_grid

    sim = case.simulation
    no_mesh = _NoMesh(centre_distance_grid(case))
    with case_arithmetic(case):
        if sim.dynamics == "transverse":
            from .dynamics.transverse import TransverseModel, _check_x_modes

            tm = TransverseModel.from_case(case, no_mesh)
            dyn = tm.base
            _check_x_modes(tm, sim.dt)
        else:
            dyn = DynamicModel.from_case(case, no_mesh)
        dt_max, f_max, f_mesh = max_time_step(dyn, no_mesh)
        if not (math.isfinite(sim.dt) and 0 < sim.dt <= dt_max * (1 + 1e-12)):
            raise InputError("simulation.dt", sim.dt,
                             f"a time step <= {dt_max:.4g} s at the most: at least "
                             f"{MIN_STEPS_PER_PERIOD} steps per period of the mesh frequency "
                             f"{f_mesh:.5g} Hz and of the highest natural frequency without mesh "
                             f"stiffness {f_max:.5g} Hz (the FE map's mesh stiffness lowers the "
                             f"limit further)")
        _speed_profile(case, dyn)
        # any positive stiffness: the static state's values are not used, only its checks
        static_equilibrium(dyn, _NoMesh(no_mesh.dd, k=1.0), which=sim.model)
