"""The sweep's client holds its event loop's log records, its shutdown included: replayed after
a normal end, dropped after Ctrl-C (distributed logs a NameError traceback from its loop thread
when an interrupt lands while the client waits: tests/sweep/test_kill_resume.py failed on it
once in CI)."""

from __future__ import annotations

import logging
import threading

import pytest

from geardyn.studies.sweep.execute import _loop_logs_held


@pytest.fixture()
def restore_levels():
    names = ("tornado.application", "tornado.general", "asyncio", "distributed")
    before = {n: logging.getLogger(n).level for n in names}
    yield
    for n, level in before.items():
        logging.getLogger(n).setLevel(level)


def _log_from_another_thread(message: str) -> None:
    t = threading.Thread(target=lambda: logging.getLogger("tornado.application").error(message))
    t.start()
    t.join()


def test_records_of_a_normal_block_are_replayed_in_order(caplog, restore_levels):
    with caplog.at_level(logging.INFO):
        with _loop_logs_held():
            _log_from_another_thread("first")
            logging.getLogger("asyncio").warning("second")
            assert not [r for r in caplog.records if r.name in ("tornado.application", "asyncio")]
        got = [r.getMessage() for r in caplog.records if r.name in ("tornado.application",
                                                                    "asyncio")]
    assert got == ["first", "second"]


def test_records_around_a_ctrl_c_are_dropped_and_the_loggers_restored(caplog, restore_levels):
    """Records of the block and of its shutdown (a ``finally`` inside it, as the client's close
    is) are dropped after a Ctrl-C; afterwards the loggers log again (no lasting change)."""
    with caplog.at_level(logging.INFO), pytest.raises(KeyboardInterrupt):
        with _loop_logs_held():
            try:
                _log_from_another_thread("Exception in callback: NameError")
                raise KeyboardInterrupt
            finally:
                _log_from_another_thread("during the cluster's shutdown")
    assert not [r for r in caplog.records if r.name == "tornado.application"]
    with caplog.at_level(logging.INFO):
        _log_from_another_thread("a later sweep's error")
    assert [r.getMessage() for r in caplog.records if r.name == "tornado.application"] == \
        ["a later sweep's error"]
