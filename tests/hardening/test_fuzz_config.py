"""Property-based fuzzing of case files and ``--set`` overrides through the real CLI.

Every generated input must end in a valid result (exit 0) or a clean error: exit code 2, one
line naming the field and what is allowed, and no traceback. The number tried per command family
is reported in the session summary.
"""

from __future__ import annotations

import json
import os

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.config import Case, case_to_toml, paper_case

runner = CliRunner()

#: Examples per test: 300 in the everyday suite and CI, any number with ``GEARDYN_FUZZ_EXAMPLES``
#: (1000 for a thorough run before a release).
FUZZ_EXAMPLES = int(os.environ.get("GEARDYN_FUZZ_EXAMPLES", "300"))


def _leaf_keys() -> list[str]:
    data = json.loads(json.dumps(paper_case().model_dump(mode="json", exclude={"provenance"})))
    out: list[str] = []

    def walk(node, prefix):
        for k, v in node.items():
            key = f"{prefix}.{k}" if prefix else k
            if isinstance(v, dict):
                walk(v, key)
            else:
                out.append(key)

    walk(data, "")
    return out


KEYS = _leaf_keys()
UNITS = ["", " m", " mm", " um", " deg", " rad", " kg", " N", " N m", " N/m", " GPa", " s",
         " ms", " Hz", " rpm", " kg m^2", " furlong", " N m/rad", " %"]

values = st.one_of(
    st.integers(-10**12, 10**12).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.tuples(st.floats(-1e9, 1e9, allow_nan=False), st.sampled_from(UNITS)).map(
        lambda t: f'"{t[0]!r}{t[1]}"'),
    st.sampled_from(["true", "false", "[]", "[1, 2]", "{}", '""', '"pinion"', '"tip"', '"II"',
                     "nan", "inf", "-inf", "1e308", "-0.0"]),
    st.text(max_size=15),
)
keys = st.one_of(st.sampled_from(KEYS), st.sampled_from(KEYS).map(lambda k: k + "x"),
                 st.text(alphabet="abcdefghijklmnop._", min_size=1, max_size=20))


def check(result) -> None:
    out = result.output
    assert result.exit_code in (0, 2), (result.exit_code, out, result.exception)
    assert "Traceback" not in out
    if result.exit_code == 2:
        assert "error:" in out or "Error" in out  # ours, or typer's usage error
        assert result.exception is None or isinstance(result.exception, SystemExit)


@pytest.mark.slow
@settings(max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(key=keys, value=values)
def test_geometry_with_fuzzed_overrides(key, value, fuzz_counter):
    fuzz_counter["geometry --set"] += 1
    result = runner.invoke(app, ["geometry", "--json", "--set", f"{key}={value}"])
    check(result)
    if result.exit_code == 2 and "error:" in result.output:
        assert "allowed" in result.output


@pytest.fixture(scope="module")
def base_text() -> str:
    return case_to_toml(paper_case())


@pytest.mark.slow
@settings(max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_config_validate_with_fuzzed_files(data, base_text, tmp_path_factory, fuzz_counter):
    """Mutated case files: deleted lines, replaced values, truncation, garbage bytes."""
    fuzz_counter["config validate FILE"] += 1
    lines = base_text.splitlines()
    op = data.draw(st.sampled_from(["delete", "replace", "truncate", "garbage", "duplicate"]))
    i = data.draw(st.integers(0, len(lines) - 1))
    if op == "delete":
        lines.pop(i)
        text = "\n".join(lines)
    elif op == "replace":
        key = lines[i].split("=", 1)[0].strip() if "=" in lines[i] else "x"
        lines[i] = f"{key} = {data.draw(values)}"
        text = "\n".join(lines)
    elif op == "truncate":
        text = base_text[: data.draw(st.integers(0, len(base_text)))]
    elif op == "garbage":
        text = base_text[:i * 10] + data.draw(st.text(max_size=30)) + base_text[i * 10:]
    else:
        lines.insert(i, lines[i])
        text = "\n".join(lines)
    path = tmp_path_factory.mktemp("fuzz") / "case.toml"
    # surrogates from the text strategy are written as invalid UTF-8 on purpose
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    result = runner.invoke(app, ["config", "validate", str(path)])
    check(result)


def test_schema_lists_every_section():
    assert set(Case.model_json_schema()["properties"]) >= {"pair", "pinion", "gear", "simulation"}
