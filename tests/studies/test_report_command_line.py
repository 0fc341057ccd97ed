"""The report's "Command line" is one a user can type again (the QA saw
``/work/main/src/geardyn/__main__.py run ...`` for ``python -m geardyn run ...``)."""

from __future__ import annotations

import shlex

from geardyn.studies.paper_report import command_line


def test_the_cli_reads_as_geardyn_with_its_arguments_quoted():
    args = ["run", "--set", "simulation.dt=5e-6 s", "-o", "out dir"]
    for argv0 in ("/x/site-packages/geardyn/__main__.py", "/usr/local/bin/geardyn",
                  "C:/Python/Scripts/geardyn.exe"):
        text = command_line([argv0, *args])
        assert text == "geardyn run --set 'simulation.dt=5e-6 s' -o 'out dir'"
        assert shlex.split(text)[1:] == args  # the shell gives the same arguments back


def test_a_script_is_named_as_a_library_call():
    assert command_line(["study.py", "--fast"]) == "(library call from study.py --fast)"
    assert command_line(["/x/other/__main__.py"]) == "(library call from /x/other/__main__.py)"
    assert command_line([]) == command_line([""]) == "(library call)"
