"""MATLAB readers (issue 17.2, 19.4): the MATLAB class decides what is a signal.

The v7.3 file is written with h5py in MATLAB's own layout (an HDF5 file behind a 512-byte
user block holding MATLAB's text header; every variable carries a ``MATLAB_class``
attribute; arrays are stored column-major, so an n x 1 column is an HDF5 (1, n) dataset; a
``char`` is uint16 code points; an empty array is a dataset holding its dimensions with
``MATLAB_empty = 1``; a struct is a group with ``MATLAB_fields``). Before, the h5py-only reader
took ``'m/s'`` for a channel [109, 47, 115], the empty array for a channel [0, 0], and dropped
the struct.
"""

from __future__ import annotations

import warnings

import h5py
import numpy as np
import pytest
import scipy.io

from geardyn.diagnostics import load_measurement, read_table
from geardyn.errors import DataFileError, InputError

N = 1000
T = np.arange(N) / 1000.0
ACCEL = np.sin(2 * np.pi * 7 * T) + 0.1 * T
TACH = np.where(np.mod(T, 0.1) < 0.02, 5.0, 0.0)


def _char(group, name, text):
    ds = group.create_dataset(name, data=np.array([[ord(c)] for c in text], dtype=np.uint16))
    ds.attrs["MATLAB_class"] = np.bytes_("char")
    ds.attrs["MATLAB_int_decode"] = np.int32(2)


def _double(group, name, value):
    value = np.atleast_2d(np.asarray(value, dtype=np.float64))
    # MATLAB writes column-major: an n x 1 column (what `x(:)` gives) is HDF5 shape (1, n)
    ds = group.create_dataset(name, data=value if value.shape[0] == 1 else value.T)
    ds.attrs["MATLAB_class"] = np.bytes_("double")


def _struct(group, name, fields):
    g = group.create_group(name)
    g.attrs["MATLAB_class"] = np.bytes_("struct")
    names = np.empty(len(fields), dtype=object)
    for i, key in enumerate(fields):
        names[i] = np.array(list(key.encode()), dtype="S1")
    g.attrs.create("MATLAB_fields", names, dtype=h5py.vlen_dtype(np.dtype("S1")))
    for key, value in fields.items():
        if isinstance(value, str):
            _char(g, key, value)
        else:
            _double(g, key, value)


def write_v73(path, *, struct_fields=None, tach=TACH):
    """A MATLAB v7.3 MAT-file as MATLAB lays it out (see the module docstring)."""
    with h5py.File(path, "w", userblock_size=512) as f:
        _double(f, "accel", ACCEL[:, None])
        _double(f, "tach", np.asarray(tach)[:, None])
        _char(f, "units", "m/s")
        empty = f.create_dataset("nothing", data=np.array([0, 0], dtype=np.uint64))
        empty.attrs["MATLAB_class"] = np.bytes_("double")
        empty.attrs["MATLAB_empty"] = np.uint8(1)
        _struct(f, "info", struct_fields or {"fs": 1000.0, "rig": "test rig"})
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Nov 23 12:00:00 2026 " \
             b"HDF5 schema 1.00 ."
    with open(path, "r+b") as fh:  # MATLAB's 128-byte header: text, subsystem, version, endian
        fh.write(header.ljust(116) + b"\0" * 8 + b"\x00\x02" + b"IM")


def test_v73_with_char_empty_struct_reads_exactly_the_two_channels(tmp_path):
    path = tmp_path / "rec73.mat"
    write_v73(path)
    assert scipy.io.matlab.matfile_version(str(path))[0] == 2  # really a v7.3 file
    table = read_table(path)
    assert table.names == ["accel", "tach"]
    np.testing.assert_array_equal(table.columns["accel"], ACCEL)
    np.testing.assert_array_equal(table.columns["tach"], TACH)
    assert table.scalars == {"info.fs": 1000.0}  # a struct's numeric scalar field, dotted


def test_v73_struct_vector_field_is_a_channel_by_dotted_name(tmp_path):
    path = tmp_path / "struct73.mat"
    speed = np.linspace(10.0, 12.0, N)
    write_v73(path, struct_fields={"fs": 1000.0, "speed": speed[:, None], "rig": "A"})
    table = read_table(path)
    assert table.names == ["accel", "info.speed", "tach"]
    np.testing.assert_array_equal(table.get("info.speed"), speed)
    # picked by name through the measurement loader, fs from the struct is not guessed
    with pytest.warns(UserWarning, match="not resolved"):  # a sampled square pulse
        m = load_measurement(path, signal="info.speed", fs=table.scalars["info.fs"],
                             tach="tach", tach_threshold=2.5)
    np.testing.assert_array_equal(m.signals["info.speed"], speed)


def test_v5_file_with_the_same_content_reads_the_same(tmp_path):
    path = tmp_path / "rec5.mat"
    scipy.io.savemat(path, {"accel": ACCEL[:, None], "tach": TACH, "units": "m/s",
                            "nothing": np.zeros((0, 0)),
                            "info": {"fs": 1000.0, "speed": np.ones(N), "rig": "A"},
                            "cells": np.array(["a", "bc"], dtype=object)})
    table = read_table(path)
    assert table.names == ["accel", "tach", "info.speed"]
    np.testing.assert_array_equal(table.columns["accel"], ACCEL)
    assert table.scalars == {"info.fs": 1000.0}


def test_only_text_and_empty_variables_is_a_clear_error(tmp_path):
    path = tmp_path / "text.mat"
    scipy.io.savemat(path, {"units": "m/s", "nothing": np.zeros((0, 0))})
    with pytest.raises(DataFileError, match="text, empty arrays"):
        read_table(path)


def test_signal_and_tach_of_different_length_are_named_as_such(tmp_path):
    """Issue 19.4: not reported as a tach threshold problem."""
    path = tmp_path / "short_tach.mat"
    scipy.io.savemat(path, {"accel": ACCEL, "tach": TACH[:900], "fs": 1000.0})
    with pytest.raises(InputError) as info:
        load_measurement(path, signal="accel", tach="tach")
    msg = str(info.value)
    assert "900 samples" in msg and "'accel' (1000 samples)" in msg
    assert "threshold" not in msg
    # the same for v7.3
    path73 = tmp_path / "short_tach73.mat"
    write_v73(path73, tach=TACH[:900])
    with pytest.raises(InputError, match="900 samples"):
        load_measurement(path73, signal="accel", fs=1000.0, tach="tach")


def test_reader_warnings_are_not_shown_before_a_clean_error(tmp_path):
    """scipy warns about a duplicated variable name, then fails on the truncated tail: the user
    gets the error only. On success the warning is passed on."""
    path = tmp_path / "dup.mat"
    scipy.io.savemat(path, {"aaaa": ACCEL, "bbbb": ACCEL, "cccc": ACCEL},
                     do_compression=False)
    raw = bytearray(path.read_bytes())
    i = raw.find(b"bbbb")
    raw[i:i + 4] = b"aaaa"
    path.write_bytes(bytes(raw))
    with pytest.warns(UserWarning, match="Duplicate variable name"):
        assert read_table(path).names == ["aaaa", "cccc"]
    bad = tmp_path / "duptrunc.mat"
    bad.write_bytes(bytes(raw[:-300]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(DataFileError, match="not a readable MATLAB file"):
            read_table(bad)
    assert [str(w.message) for w in caught] == []


def test_corrupt_v73_is_a_data_file_error(tmp_path):
    path = tmp_path / "bad73.mat"
    write_v73(path)
    raw = path.read_bytes()
    path.write_bytes(raw[: len(raw) // 3])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(DataFileError, match="v7.3"):
            read_table(path)
    assert [str(w.message) for w in caught] == []
