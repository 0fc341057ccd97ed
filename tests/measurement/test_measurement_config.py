"""The [measurement] section: defaults with sources, units, round trip, the example's partial case."""

from __future__ import annotations

from pathlib import Path

import pytest

from geardyn.config import case_to_toml, load_case, paper_case
from geardyn.errors import InputError
from geardyn.studies.measure import chain_from_config

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "measure" / "case.toml"


def test_paper_case_measurement_defaults_have_sources():
    case = paper_case()
    m = case.measurement
    assert m.fs == 50_000.0 and m.mode_frequencies == [3000.0]
    assert m.mode_damping_ratios == [0.05] and m.snr == 20.0
    assert m.adc_range == pytest.approx(50 * 9.80665) and m.tach_jitter == pytest.approx(1e-6)
    for key in ("fs", "mode_frequencies", "mode_damping_ratios", "mode_gains", "snr", "adc_bits",
                "adc_range", "tach_pulses_per_rev", "tach_jitter", "seed"):
        assert f"measurement.{key}" in case.provenance, key
    chain = chain_from_config(m)
    assert chain.sensor.antialias_cutoff == pytest.approx(20_000.0)
    assert 0.03 < chain.lead_in() < 0.05


def test_units_and_round_trip(tmp_path):
    case = paper_case(['measurement.fs="25.6 kHz"', 'measurement.noise_level="0.01 g_n"',
                       "measurement.tach_jitter='2 us'"]).with_overrides(
        {"measurement.snr": float("inf"), "measurement.adc_bits": 0})
    assert case.measurement.fs == 25_600.0
    assert case.measurement.noise_level == pytest.approx(0.0980665)
    assert case.measurement.tach_jitter == pytest.approx(2e-6)
    chain = chain_from_config(case.measurement)
    assert chain.sensor.adc_bits is None and chain.sensor.snr == float("inf")
    assert chain.sensor.noise_level == pytest.approx(0.0980665)
    p = tmp_path / "c.toml"
    p.write_text(case_to_toml(case))
    back = load_case(p)
    assert back.model_dump(exclude={"provenance"}) == case.model_dump(exclude={"provenance"})


def test_bad_sections_name_the_field():
    with pytest.raises(InputError, match="mode_gains"):
        paper_case(["measurement.mode_gains=[[1.0]]"])
    with pytest.raises(InputError, match="measurement.fs"):
        paper_case(['measurement.fs="3 m"'])
    with pytest.raises(InputError, match="measurement.snr"):
        chain_from_config(paper_case(["measurement.snr=-1"]).measurement)
    with pytest.raises(InputError, match="measurement.fs"):
        chain_from_config(paper_case(["measurement.fs=4000"]).measurement)


def test_example_case_changes_only_the_measurement():
    ex = load_case(EXAMPLE)
    base = paper_case()
    assert ex.measurement != base.measurement
    same = ex.model_copy(update={"measurement": base.measurement, "name": base.name,
                                 "description": base.description})
    assert same.model_dump(exclude={"provenance"}) == base.model_dump(exclude={"provenance"})
    chain = chain_from_config(ex.measurement)
    assert chain.sensor.fs == 51_200.0 and len(chain.path.modes) == 2
