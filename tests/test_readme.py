"""The README's Python example runs as written (the README and CI share one code path)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.mark.slow
def test_readme_python_example_runs(capsys):
    text = README.read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "the README has a Python example"
    for code in blocks:
        exec(compile(code, str(README), "exec"), {"__name__": "__readme__"})  # noqa: S102
    out = capsys.readouterr().out
    assert "tsa" in out and "residual" in out  # the kurtosis dict was printed


def test_readme_names_the_two_setup_commands():
    text = README.read_text()
    assert 'python3 -m pip install . && geardyn run' in text
    assert 'python3 -m pip install ".[test]" && python3 -m pytest' in text
    ci = (README.parent / ".ci" / "run").read_text()
    assert 'python3 -m pip install ".[test]" && python3 -m pytest' in ci
