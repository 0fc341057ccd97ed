"""The measurement study: simulate a case, then record it as a housing accelerometer would.

:func:`measure` composes :func:`geardyn.dynamics.simulate` and
:class:`geardyn.measurement.MeasurementChain`; it adds no physics. The simulation is lengthened by
the chain's lead-in and tail (a few tens of milliseconds with the default housing mode) so that
the record is exactly ``case.simulation.record_time`` long and free of start-up transients of the
transfer path.

The bearing forces on the housing are not part of the simulation record; they follow from the
recorded gear centre motions and the case's bearing stiffness and damping (paper eqs. 10, 12;
:func:`geardyn.measurement.bearing_forces`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config import Case, MeasurementConfig
from ..measurement import FRFTable, MeasurementChain, ModalPath, Mode, Sensor, Tachometer
from ..measurement.chain import Measured

__all__ = ["measure", "chain_from_config", "housing_forces", "MeasureResult"]


def chain_from_config(cfg: MeasurementConfig | None) -> MeasurementChain:
    """The chain of a case's ``[measurement]`` section (its defaults when ``None``).

    Raises
    ------
    InputError
        Inconsistent settings, e.g. ``fs`` not above twice the highest mode (field named).
    """
    cfg = cfg if cfg is not None else MeasurementConfig()
    if cfg.frf_table is not None:
        path = FRFTable.from_csv(Path(cfg.frf_table), settling=cfg.frf_settling_time)
    else:
        path = ModalPath(tuple(Mode(float(f), float(z), tuple(float(x) for x in g))
                               for f, z, g in zip(cfg.mode_frequencies, cfg.mode_damping_ratios,
                                                  cfg.mode_gains, strict=True)))
    order = cfg.antialias_order
    cutoff = None if order == 0 else (cfg.antialias_cutoff if cfg.antialias_cutoff is not None
                                      else 0.4 * cfg.fs)
    sensor = Sensor(fs=cfg.fs, resonance=cfg.accelerometer_resonance,
                    resonance_damping=cfg.accelerometer_damping_ratio, antialias_cutoff=cutoff,
                    antialias_order=max(order, 1), adc_bits=cfg.adc_bits or None,
                    adc_full_scale=cfg.adc_range, snr=cfg.snr, noise_level=cfg.noise_level)
    tach = Tachometer(shaft=cfg.tach_shaft, pulses_per_rev=cfg.tach_pulses_per_rev,
                      jitter=cfg.tach_jitter, offset=cfg.tach_offset, amplitude=cfg.tach_amplitude,
                      rise_time=cfg.tach_rise_time)
    return MeasurementChain(path=path, sensor=sensor, tach=tach, seed=cfg.seed)


def simulated_case(case: Case, chain: MeasurementChain) -> Case:
    """The case :func:`measure` simulates: ``simulation.record_time`` lengthened by the chain's
    lead-in and tail (:meth:`MeasurementChain.input_duration`)."""
    sim_cfg = case.simulation
    length = chain.input_duration(sim_cfg.record_time, sim_cfg.dt * sim_cfg.decimation)
    return case.model_copy(update={"simulation": sim_cfg.model_copy(
        update={"record_time": length})})


def housing_forces(case: Case, stiffness_map, ds) -> np.ndarray:
    """Bearing forces on the housing [N], shape ``(2, n)`` (pinion, gear), of a simulation
    record ``ds`` of ``case`` (paper eqs. 10, 12: ``k_y y + q_y y'`` with the case's bearing
    stiffness and damping; :func:`geardyn.measurement.bearing_forces`)."""
    from ..dynamics import DynamicModel
    from ..measurement import bearing_forces

    dyn = DynamicModel.from_case(case, stiffness_map)
    fp = bearing_forces(ds["y_p"].values, ds["v_yp"].values, dyn.K0[1, 1], dyn.damping["q_yp"])
    fg = bearing_forces(ds["y_g"].values, ds["v_yg"].values, dyn.K0[3, 3], dyn.damping["q_yg"])
    return np.vstack([fp, fg])


@dataclass
class MeasureResult:
    """Output of :func:`measure`.

    Attributes
    ----------
    record : xarray.Dataset
        The DAQ record (:mod:`geardyn.measurement.record` layout).
    simulation : xarray.Dataset
        The (lengthened) simulation it was made from.
    measured : Measured
        The chain's arrays, including the noise-free channel and exact pulse times.
    chain : MeasurementChain
    """

    record: object
    simulation: object
    measured: Measured
    chain: MeasurementChain

    def exact_angle(self) -> np.ndarray:
        """The simulated angle [rad] of the tachometer's shaft at the record's samples (for
        checks only: a real record has no such channel)."""
        sim = self.simulation
        name = "theta_p" if self.chain.tach.shaft == "pinion" else "theta_g"
        t = np.asarray(sim["time"].values) - float(sim["time"].values[0])
        ts = self.measured.start_time - float(sim["time"].values[0]) + self.measured.time
        return np.interp(ts, t, np.asarray(sim[name].values))


def measure(case: Case, stiffness_map=None, *, model: str | None = None, cracked: bool = True,
            progress: Callable[[int, int], None] | None = None) -> MeasureResult:
    """Simulate ``case`` and record its housing acceleration and tachometer.

    Parameters
    ----------
    case : Case
        Parameters; ``case.measurement`` the chain (defaults when absent),
        ``case.simulation.record_time`` the record length [s].
    stiffness_map : StiffnessMap, optional
        Default ``geardyn.stiffness.build_map(case, cracked=cracked)``.
    model : {"I", "I-static", "II"}, optional
        Default ``case.simulation.model`` (see :func:`geardyn.dynamics.simulate`).
    cracked : bool
        Passed to ``build_map`` when no map is given.
    progress : callable, optional
        ``progress(steps_done, steps_total)`` from the simulation.

    Returns
    -------
    MeasureResult
    """
    from .. import _version
    from ..config import case_to_toml
    from ..dynamics import simulate
    from ..errors import InputError, check_flag
    from ..measurement.record import to_dataset

    if not isinstance(case, Case):  # as simulate() says it, before the chain reads the case
        raise InputError("case", case, "a geardyn.config.Case (geardyn.load_case(path) or "
                                       f"geardyn.paper_case()), not a {type(case).__name__}")
    cracked = check_flag(cracked, "cracked")
    chain = chain_from_config(case.measurement)
    if stiffness_map is None:
        from ..stiffness import build_map

        stiffness_map = build_map(case, cracked=cracked)
    sim_cfg = case.simulation
    long_case = simulated_case(case, chain)
    ds = simulate(long_case, stiffness_map, model=model, cracked=cracked, progress=progress)
    shaft = "p" if chain.tach.shaft == "pinion" else "g"
    m = chain.measure(ds["time"].values, housing_forces(case, stiffness_map, ds),
                      ds[f"theta_{shaft}"].values,
                      ds[f"omega_{shaft}"].values, record_time=sim_cfg.record_time)
    cfg = case.measurement if case.measurement is not None else MeasurementConfig()
    attrs = {
        "case": case.name,
        "case_toml": case_to_toml(case),
        "noise_seed": int(chain.seed),
        "seed_streams": "numpy SeedSequence(noise_seed).spawn(2): noise, tachometer jitter",
        "snr_requested": float(cfg.snr) if cfg.snr is not None else "none",
        "transfer_path": chain.path.describe(),
        "antialias": (f"zero-phase Butterworth magnitude, order {chain.sensor.antialias_order}, "
                      f"cutoff {chain.sensor.antialias_cutoff:.6g} Hz"
                      if chain.sensor.antialias_cutoff is not None else "none"),
        "accelerometer_resonance": (float(chain.sensor.resonance)
                                    if chain.sensor.resonance is not None else "none"),
        "adc": (f"{chain.sensor.adc_bits} bits, +/- {chain.sensor.adc_full_scale:.6g} m/s^2"
                if chain.sensor.adc_bits is not None else "none"),
        "tach_shaft": chain.tach.shaft,
        "pinion_teeth": int(case.pinion.teeth),
        "gear_teeth": int(case.gear.teeth),
        "tach_pulses_per_rev": int(chain.tach.pulses_per_rev),
        "tach_jitter": float(chain.tach.jitter),
        "simulation_model": str(ds.attrs.get("model", "")),
        "stiffness_method": str(ds.attrs.get("stiffness_method", "")),
        "stiffness_cracked": int(ds.attrs.get("stiffness_cracked", 0)),
        "start_time_in_simulation": float(m.start_time),
        "geardyn_version": _version.__version__,
    }
    return MeasureResult(record=to_dataset(m, attrs), simulation=ds, measured=m, chain=chain)
