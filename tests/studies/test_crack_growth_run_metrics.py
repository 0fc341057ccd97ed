"""NA4 and NB4 over a crack-growth run (:func:`geardyn.studies.crack_growth._run_metrics`).

Oracle: the closed form of the running NA4 of residuals ``(M/3) sin 10 theta`` (record M of a
run): m4 = (M/3)^4 3/8 and m2_i = (i/3)^2 / 2, so NA4_M = 1.5 M^6 / (sum_{i<=M} i^2)^2, which
gives the values listed in the design notes' diagnostic conventions (1.5, 3.84, 5.579, 6.827).
NB4 is the same statistic of the envelope of the band about the first mesh harmonic: a mesh
tone amplitude-modulated by ``1 + (M/6) sin 3 theta`` has the envelope ``1 + (M/6) sin 3
theta``, whose running NA4 is the same sequence.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import geardyn
from geardyn.studies.crack_growth import _run_metrics, _squared_unit

Z = 19
TH = np.arange(2048) * 2 * np.pi / 2048


def _closed_form(m: int) -> float:
    return 1.5 * m**6 / sum(i * i for i in range(1, m + 1)) ** 2


def test_closed_form_is_the_design_notes_sequence():
    assert [round(_closed_form(m), 3) for m in range(1, 5)] == [1.5, 3.84, 5.579, 6.827]


def test_na4_over_the_run_skips_a_failed_sample():
    case = geardyn.paper_case()
    assert case.diagnostics.residual_preset == "paper"  # removes the mesh harmonics only
    tsas = [m / 3 * np.sin(10 * TH) + 0.5 * np.cos(Z * TH) for m in (1, 2, 3, 4)]
    tsas.insert(1, None)  # the second record failed: NaN, and not part of the history
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the unmodulated tone's envelope has no variance
        out = _run_metrics(case, tsas, Z)
    want = [_closed_form(1), np.nan, _closed_form(2), _closed_form(3), _closed_form(4)]
    np.testing.assert_allclose(out["NA4_run"], want, rtol=1e-9)
    var = [(m / 3) ** 2 / 2 for m in (1, 2, 3, 4)]
    np.testing.assert_allclose(out["residual_variance"], [var[0], np.nan, *var[1:]], rtol=1e-9)


def test_nb4_over_the_run_is_na4_of_the_envelope():
    case = geardyn.paper_case()
    tsas = [np.cos(Z * TH) * (1 + m / 6 * np.sin(3 * TH)) for m in (1, 2, 3, 4)]
    out = _run_metrics(case, tsas, Z)
    np.testing.assert_allclose(out["NB4_run"], [_closed_form(m) for m in (1, 2, 3, 4)],
                               rtol=1e-9)


@pytest.mark.parametrize(("unit", "want"), [("m/s", "(m/s)^2"), ("rad", "rad^2"), ("", "1"),
                                            ("1", "1"), ("m/s^2", "(m/s^2)^2")])
def test_variance_units(unit, want):
    assert _squared_unit(unit) == want
