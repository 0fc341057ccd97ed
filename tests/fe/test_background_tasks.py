"""Work left to a second process (``tasks_in_background``) and the check that tells whether the
time-step kernel needs compiling (``kernels_compiled``), which ``geardyn run --quick`` uses to
compile the kernel in a second process on a first run after an install (issue 16.6)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from geardyn.stiffness.fe.background import FE_PROCESSES_ENV, tasks_in_background

MARK_ENV = "GEARDYN_TEST_BACKGROUND_MARK"


def write_mark() -> None:
    """A task: write the process id into the file named by the environment."""
    with open(os.environ[MARK_ENV], "w", encoding="ascii") as fh:
        fh.write(str(os.getpid()))


def fail() -> None:
    raise RuntimeError("a task that fails")


def test_the_tasks_run_in_another_process(tmp_path, monkeypatch):
    mark = tmp_path / "mark"
    monkeypatch.setenv(MARK_ENV, str(mark))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    proc = tasks_in_background((write_mark,))
    assert proc is not None
    proc.join(timeout=60)
    assert proc.exitcode == 0
    assert int(mark.read_text()) == proc.pid != os.getpid()


def test_a_failing_task_ends_the_process_quietly_and_the_rest_is_not_run(tmp_path, monkeypatch,
                                                                        capfd):
    mark = tmp_path / "mark"
    monkeypatch.setenv(MARK_ENV, str(mark))
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    proc = tasks_in_background((fail, write_mark))
    proc.join(timeout=60)
    assert proc.exitcode == 1 and not mark.exists()
    assert "Traceback" not in capfd.readouterr().err


def test_no_second_process_where_one_is_asked_for(tmp_path, monkeypatch):
    monkeypatch.setenv(MARK_ENV, str(tmp_path / "mark"))
    monkeypatch.setenv(FE_PROCESSES_ENV, "0")
    assert tasks_in_background((write_mark,)) is None
    monkeypatch.setenv(FE_PROCESSES_ENV, "1")
    assert tasks_in_background(()) is None
    assert not (tmp_path / "mark").exists()


@pytest.mark.slow
def test_kernels_compiled_before_and_after_compiling_them(tmp_path):
    """In a fresh numba cache the kernel is not compiled; after ``compile_kernels`` it is, and a
    new process (which only loads it) says so too. Compiling it compiled each of the kernel's
    functions for typed arguments only: no second copy for a literal constant argument
    (``Literal[int](0)``, which numba's type inference asks for when a variable starts as a
    constant) or a read-only array."""
    code = textwrap.dedent("""
        import sys
        import numba
        from numba.core import types
        from geardyn.dynamics import _kernel
        from geardyn.dynamics.warm import compile_kernels, kernels_compiled
        before = kernels_compiled()
        if sys.argv[1] == "compile":
            compile_kernels()
        print(before, kernels_compiled())
        if sys.argv[1] == "compile":
            for name, f in vars(_kernel).items():
                if isinstance(f, numba.core.registry.CPUDispatcher):
                    for sig in f.signatures:
                        if any(isinstance(a, types.Literal)
                               or (isinstance(a, types.Array) and not a.mutable) for a in sig):
                            print("special:", name, sig)
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    first = subprocess.run([sys.executable, "-c", code, "compile"], env=env, text=True,
                           capture_output=True, timeout=300)
    assert first.returncode == 0, first.stderr
    assert first.stdout.splitlines() == ["False True"]
    again = subprocess.run([sys.executable, "-c", code, "look"], env=env, text=True,
                           capture_output=True, timeout=300)
    assert again.stdout.split() == ["True", "True"], again.stderr


@pytest.mark.parametrize("compiled", [True, False])
def test_quick_compiles_the_kernel_in_a_second_process_only_when_numba_has_not(monkeypatch,
                                                                               compiled):
    """``geardyn run --quick``: with the kernel not yet compiled, a second process compiles it
    and this one builds the coarse bodies; once compiled, the second process builds the faulty
    bodies and ends with them (loading the kernel there would not load it here), and a compiler
    is among the processes the figure process waits for. A full run does not ask numba's cache
    (that would import numba into this process before its bodies): its bodies' process
    compiles the kernel after the bodies, or loads it where numba has it, named by module and
    function so that nothing of the kernel is imported here."""
    import geardyn
    from geardyn.dynamics import warm
    from geardyn.stiffness.fe import background as bg
    from geardyn.studies import paper
    from geardyn.studies.paper_result import StudyResult

    calls = []
    monkeypatch.setattr(warm, "kernels_compiled", lambda: calls.append("asked") or compiled)
    monkeypatch.setattr(bg, "tasks_in_background", lambda tasks: calls.append(("tasks", tasks))
                        or "a process")
    monkeypatch.setattr(bg, "faulty_bodies_in_background",
                        lambda case, **kw: calls.append(("bodies", sorted(kw.items()))))
    case = geardyn.paper_case().with_overrides({"stiffness.method": "fe"})
    for quick in (True, False):
        result = StudyResult(out=None, quick=quick)
        paper._faulty_bodies_in_background(case, result)
        assert result.kernel_compiler == (None if compiled or not quick else "a process")
        assert result.background == ([] if compiled or not quick else ["a process"])
    from geardyn.studies.paper_result import fe_mesh_figure_task, kernels_and_mesh_figure_task

    def is_task(t, func) -> bool:  # functools.partial(func, case, cracked)
        return t.func is func and t.args == (case, True) and not t.keywords

    if compiled:  # then the mesh figure of the cracked body it holds
        quick_calls = calls[:2]
        assert quick_calls[0] == "asked" and quick_calls[1][0] == "bodies"
        assert [k for k, _ in quick_calls[1][1]] == ["progress", "then"]
        (task,) = dict(quick_calls[1][1])["then"]
        assert is_task(task, fe_mesh_figure_task)
    else:
        quick_calls = calls[:3]
        assert quick_calls == ["asked", ("tasks", (warm.compile_kernels,)),
                               ("bodies", [("progress", None), ("second_process", False)])]
    # the full run: the bodies' process, then the kernel (compiled or loaded) and the mesh
    # figure, in the order that process chooses (kernels_and_mesh_figure_task), not asked here
    ((kind, kwargs),) = calls[len(quick_calls):]
    assert kind == "bodies" and [k for k, _ in kwargs] == ["progress", "then"]
    (task,) = dict(kwargs)["then"]
    assert is_task(task, kernels_and_mesh_figure_task)
