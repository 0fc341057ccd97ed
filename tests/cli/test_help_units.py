"""Units in square brackets survive in every command's ``--help``: rich markup used to eat
``[um]`` and ``[rad]`` in command descriptions (``geardyn static-te --help`` read "along the
line of action  and as pinion rotation ,")."""

from __future__ import annotations

import os
import re

import typer

from geardyn.cli import _literal_brackets, app

from .._cli_fork import run_geardyn

BRACKETED = re.compile(r"\[[^\[\]\n]+\]")


def _commands(command=None, path=()):
    """(path, click command) of every command and subcommand, docstrings as written."""
    command = typer.main.get_command(app) if command is None else command
    for name, sub in (getattr(command, "commands", None) or {}).items():
        yield path + (name,), sub
        yield from _commands(sub, path + (name,))


COMMANDS = {" ".join(path): sub for path, sub in _commands()}


def _units(command) -> set[str]:
    """Every ``[...]`` of the command's own help and of its options' help."""
    texts = [command.help or "", command.epilog or ""]
    texts += [getattr(p, "help", None) or "" for p in command.params]
    return {m for t in texts for m in BRACKETED.findall(" ".join(t.split()))}


def _flat(text: str) -> str:
    return " ".join(text.replace("│", " ").split())


def test_the_walk_finds_the_commands_and_their_units():
    assert {"geometry", "static-te", "cache info", "config show"} <= set(COMMANDS)
    assert {"[um]", "[rad]"} <= _units(COMMANDS["static-te"])
    assert "[MB]" in _units(COMMANDS["cache info"])


def test_escaping_is_idempotent_and_leaves_other_text_alone():
    assert _literal_brackets("line of action [um] and rotation [rad]") == \
        "line of action \\[um] and rotation \\[rad]"
    assert _literal_brackets("already \\[s] escaped") == "already \\[s] escaped"
    assert _literal_brackets(_literal_brackets("a [N/m] b")) == "a \\[N/m] b"
    assert _literal_brackets("no units") == "no units"


def test_every_bracketed_unit_of_every_command_is_in_its_help(monkeypatch):
    """Each command's ``--help`` as ``main()`` renders it (the tidied command, in-process: one
    interpreter for all of them; ``test_static_te_description_keeps_its_units`` runs the real
    CLI)."""
    import contextlib
    import io

    from geardyn.cli import _tidy_help

    monkeypatch.setenv("COLUMNS", "400")
    command = typer.main.get_command(app)
    _tidy_help(command, {"help_option_names": ["-h", "--help"]})
    for name in sorted(COMMANDS):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            code = command.main([*name.split(), "--help"], prog_name="geardyn",
                                standalone_mode=False)
        assert code in (0, None), (name, buf.getvalue())
        shown = _flat(buf.getvalue())
        # the description's opening words as written (brackets included), then every unit
        first = _flat(COMMANDS[name].help or "")[:60]
        assert first in shown, (name, first, shown[:400])
        missing = sorted(u for u in _units(COMMANDS[name]) if u not in shown)
        assert not missing, f"geardyn {name} --help lost {missing}"


def test_static_te_description_keeps_its_units():
    r = run_geardyn(["static-te", "--help"], capture_output=True, text=True, timeout=120,
                    env={**os.environ, "COLUMNS": "400"})
    assert r.returncode == 0, r.stderr
    assert "along the line of action [um] and as pinion rotation [rad]," in _flat(r.stdout)
