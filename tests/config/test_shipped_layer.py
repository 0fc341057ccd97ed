"""The shipped cases are parsed once per text and handed out as copies
(``geardyn.config.loading._shipped_layer``): what a caller changes never reaches the next
caller, and an edited file is parsed again."""

from __future__ import annotations

import geardyn
from geardyn.config import loading


def test_each_caller_gets_its_own_copy():
    a = loading._shipped_layer(loading.PAPER_CASE, ())
    b = loading._shipped_layer(loading.PAPER_CASE, ())
    assert a is not b and a.data is not b.data and a.data == b.data and a.prov == b.prov
    a.data["motor"]["torque"] = "1 N m"
    a.prov["motor.torque"] = "changed here"
    c = loading._shipped_layer(loading.PAPER_CASE, ())
    assert c.data == b.data and c.prov == b.prov
    # and through the public loader: an override of one case is not the next case's value
    assert geardyn.paper_case({"motor.torque": 77.0}).motor.torque == 77.0
    assert geardyn.paper_case().motor.torque == 100.0


def test_an_edited_shipped_file_is_parsed_again(monkeypatch):
    real = loading.resources.files("geardyn.cases").joinpath(
        f"{loading.PAPER_CASE}.toml").read_text("utf-8")
    assert "\ntorque = " in real
    edited = real.replace("\ntorque = ", "\ntorque = 123.0 # was: ", 1)

    class _File:
        def __init__(self, text):
            self._text = text

        def read_text(self, encoding):
            return self._text

    class _Folder:
        def __init__(self, text):
            self._text = text

        def joinpath(self, name):
            return _File(self._text)

    before = loading._shipped_layer(loading.PAPER_CASE, ())
    monkeypatch.setattr(loading.resources, "files", lambda package: _Folder(edited))
    after = loading._shipped_layer(loading.PAPER_CASE, ())
    assert after.data != before.data
    assert after.data["motor"]["torque"] == 123.0 != before.data["motor"]["torque"]
