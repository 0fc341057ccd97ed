"""The terminal summary of ``geardyn run`` says what the report says: a case that is not the
paper's is compared with nothing and its fault need not be a crack; the paper's case is compared
with the paper."""

from __future__ import annotations

from pathlib import Path

from geardyn.cli.run import _print_summary

BASE = {"centre_distance_change_mm": 1.0852, "operating_pressure_angle_deg": 21.19,
        "contact_ratio": {"physical": 1.4175, "paper_eq8": 1.4286},
        "mean_pinion_speed_rad_s": 114.14, "mean_transmission_error_rad": 0.048,
        "crack_angle_deg": 182.6, "stages": ["geometry", "report"],
        "run_time_s": {"total": 13.2},
        "measurement": {"model": "II", "indicators": {"errors+noise": {
            "healthy": {"FM4": 5.6, "NA4star": 5.9, "EnergyRatio": 0.47},
            "cracked": {"FM4": 6.0, "NA4star": 8.0, "EnergyRatio": 0.50}}},
            "detections": {"errors+noise": {"FM4": {"detected": False}}}}}


def _text(capsys, summary) -> str:
    _print_summary(summary, Path("out"))
    out = capsys.readouterr()
    return " ".join((out.out + out.err).split())


def test_a_users_case_is_compared_with_nothing_and_says_fault(capsys):
    s = {**BASE, "paper_case": False, "validation": [],
         "differences_from_paper": [{"key": "crack.enabled"}, {"key": "faults"}]}
    text = _text(capsys, s)
    assert "not the paper's case (crack.enabled, faults): nothing is compared" in text
    assert "validation against the paper" not in text and "paper" not in text.split(
        "nothing is compared with the paper")[0].replace("paper's case", "")
    assert "~170" not in text and "fault seen at" in text and "crack" not in text.replace(
        "crack.enabled", "")
    assert "FM4 healthy 5.6 / faulty 6" in text and "fault seen by: none" in text


def test_the_papers_case_is_validated_against_the_paper(capsys):
    s = {**BASE, "paper_case": True, "validation": [
        {"pass": True, "quantity": "a", "geardyn": 1.0, "paper": 1.0},
        {"pass": False, "quantity": "b", "geardyn": 2.0, "paper": 1.0}]}
    text = _text(capsys, s)
    assert "validation against the paper: 1/2 within tolerance" in text
    assert "~170" in text and "crack seen at" in text and "outside tolerance: b" in text
    assert "FM4 healthy 5.6 / cracked 6" in text and "crack seen by: none" in text
