"""Case-file limits (issue 19.3-4): size, nesting, non-regular files, encoding, message length."""

from __future__ import annotations

import os

import pytest

from geardyn.config import MAX_CASE_BYTES, MAX_NESTING

from ._cli import assert_clean_error, cli, cli_proc


@pytest.mark.timeout(60)
def test_dev_zero_stops_at_once():
    """``config validate /dev/zero`` read for ever."""
    assert_clean_error(cli("config", "validate", "/dev/zero"), "/dev/zero", "not a regular file")
    assert_clean_error(cli("simulate", "--config", "/dev/zero", "--out", "unused.nc"),
                       "not a regular file")


@pytest.mark.slow
def test_dev_zero_in_a_subprocess():
    assert_clean_error(cli_proc("config", "validate", "/dev/zero"), "/dev/zero",
                       "not a regular file")


@pytest.mark.timeout(60)
def test_a_fifo_without_writer_does_not_block(tmp_path):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    assert_clean_error(cli("config", "validate", str(fifo)), "not a regular file")


def test_a_directory_is_named(tmp_path):
    assert_clean_error(cli("config", "validate", str(tmp_path)), "is a directory")


def test_oversized_file_is_refused_before_parsing(tmp_path):
    p = tmp_path / "big.toml"
    p.write_text('description = "' + "x" * (MAX_CASE_BYTES + 10) + '"\n')
    line = assert_clean_error(cli("config", "validate", str(p)), f"{MAX_CASE_BYTES} bytes")
    assert "xxxxxxxxxx" not in line


@pytest.mark.slow
def test_sixteen_megabyte_file_is_refused(tmp_path):
    p = tmp_path / "huge.toml"
    with open(p, "w") as fh:
        fh.write('[pinion]\nteeth = "')
        fh.write("9" * 16_000_000)
        fh.write('"\n')
    assert_clean_error(cli_proc("config", "validate", str(p)), "bytes")


def test_long_value_is_not_echoed_whole(tmp_path):
    """An error on a 200 kB value prints one short line (a 16 MB input was echoed whole)."""
    p = tmp_path / "long.toml"
    p.write_text('[pinion]\nteeth = "' + "9" * 200_000 + '"\n')
    line = assert_clean_error(cli("config", "validate", str(p)), "pinion.teeth", "…")
    assert len(line) < 300
    line = assert_clean_error(cli("config", "show", "--set", "pinion.teeth=" + "x" * 50_000),
                              "pinion.teeth")
    assert len(line) < 300


@pytest.mark.parametrize("text", [
    "a = " + "[" * 100_000 + "]" * 100_000 + "\n",
    "a = " + "[" * (MAX_NESTING + 1) + "]" * (MAX_NESTING + 1) + "\n",
    "a = " + "{b = " * 5000 + "1" + "}" * 5000 + "\n",
    ".".join(["k"] * 20_000) + " = 1\n",
    "[" + ".".join(["k"] * 40) + "]\n",
    'a = { ' + ".".join(['"k"'] * 40) + " = 1 }\n",
], ids=["array-100000", "array-17", "inline-5000", "dotted-20000", "header-40", "inline-key-40"])
def test_deep_nesting_is_refused(tmp_path, text):
    p = tmp_path / "deep.toml"
    p.write_text(text)
    assert_clean_error(cli("config", "validate", str(p)), "nests")


def test_brackets_inside_strings_and_comments_do_not_count(tmp_path):
    p = tmp_path / "ok.toml"
    p.write_text('# [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\n'
                 'description = "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[ \\" [[[[[[[[[[[[[[[[[["\n'
                 "name = '[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[['\n"
                 'extends = """xue_howard"""\n')
    r = cli("config", "validate", str(p))
    assert r.exit_code == 0, r.output


def test_non_utf8_bytes_name_the_file(tmp_path):
    p = tmp_path / "latin1.toml"
    p.write_bytes('description = "Zürich"\n'.encode("latin-1"))
    assert_clean_error(cli("config", "validate", str(p)), str(p), "not UTF-8", "0xfc")


def test_set_value_nested_too_deep():
    assert_clean_error(cli("config", "show", "--set", "name=" + "[" * 5000 + "]" * 5000),
                       "name")
