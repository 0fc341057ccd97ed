"""Test-session settings: a private cache folder and a non-interactive matplotlib backend."""

from __future__ import annotations

import os
import shutil
import tempfile

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
# FE bodies in one process (tests/fe/test_background_bodies.py turns the second one on): two
# test workers each starting a second FE process would oversubscribe the CI machine's two cores
os.environ.setdefault("GEARDYN_FE_PROCESSES", "0")


def _typer_shape(app) -> tuple:
    """What typer's ``get_command`` reads of a Typer app: its callback, its commands (with their
    callbacks) and its sub-apps, recursively (object identities: a command or sub-app added,
    removed or replaced is another shape)."""
    return (id(app.registered_callback), id(app.info.callback),
            tuple((id(c), id(c.callback)) for c in app.registered_commands),
            tuple((id(g), _typer_shape(g.typer_instance)) for g in app.registered_groups
                  if g.typer_instance is not None))


def _memoise_typer_get_command() -> None:
    """typer's ``CliRunner.invoke`` converts the Typer app into its click command tree on every
    call: 25-45 ms of each in-process CLI run (cProfile, 2026-11-26: 5.5 s of the 14 s of 120
    fuzzed ``simulate``/``stiffness`` runs), a few thousand times in the suite. The conversion
    depends only on the app's shape (see :func:`_typer_shape`), so the tests reuse the click tree
    of an app of unchanged shape. Each invocation still creates its own click context, parses
    its own arguments and runs the command's function; nothing in geardyn or typer changes a
    command tree while running a command (``geardyn.cli.main``'s ``_tidy_help`` runs on the tree
    it builds itself, never on this one)."""
    import typer.testing

    build = typer.testing._get_command
    if getattr(build, "_geardyn_memo", False):
        return
    built: dict[int, tuple] = {}

    def get_command(app):
        shape = _typer_shape(app)
        hit = built.get(id(app))
        if hit is not None and hit[0] is app and hit[1] == shape:
            return hit[2]
        command = build(app)
        built[id(app)] = (app, shape, command)
        return command

    get_command._geardyn_memo = True
    typer.testing._get_command = get_command


_memoise_typer_get_command()


def pytest_configure(config):
    """pytest-xdist controller: one cache folder for the whole session, shared by the workers
    (the cache's entry locks make concurrent builders safe, so a body or map that tests on both
    workers need is built once, not once per worker); files with the longest tests first."""
    if hasattr(config, "workerinput"):  # a worker: the controller did this
        return
    if getattr(config.option, "numprocesses", None):
        config._geardyn_shared_cache = tempfile.mkdtemp(prefix="geardyn-test-cache-")
        # the work queue in the order of the collection (longest files first, below), not
        # xdist's default order by the number of tests in a file (pytest-xdist >= 3.8)
        if hasattr(config.option, "loadscopereorder"):
            config.option.loadscopereorder = False


def pytest_unconfigure(config):
    shared = getattr(config, "_geardyn_shared_cache", None)
    if shared:
        shutil.rmtree(shared, ignore_errors=True)


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """pytest-xdist controller: hand each worker the session's shared cache folder."""
    shared = getattr(node.config, "_geardyn_shared_cache", None)
    if shared:
        node.workerinput["geardyn_cache_dir"] = shared


def pytest_collection_modifyitems(config, items):
    """The files with the longest tests first (longest-processing-time-first scheduling: the
    two workers then finish together instead of one running the last long file alone); other
    files keep their order. The weights are the files' test time in seconds, measured with
    ``python3 -m pytest --durations=0`` on the 2-core machine (see :data:`LONGEST_FILES`; a
    file's place in the queue is all they decide: a stale weight costs time, never a result)."""
    order = {path: -weight for path, weight in LONGEST_FILES.items()}
    items.sort(key=lambda it: order.get(it.nodeid.split("::", 1)[0], 0.0))


#: Test files over 5 s, by their measured test time [s] (setup + call + teardown, summed from
#: ``python3 -m pytest -p no:cacheprovider --durations=0`` on 2026-11-26, after the in-process
#: CLI runs stopped rebuilding typer's click tree, see :func:`_memoise_typer_get_command`;
#: measured while another job loaded the machine, so about 1.3x the quiet figures: only their
#: order matters). The files not listed take under 5 s each and fill the end of the queue.
LONGEST_FILES = {
    "tests/faults/test_examples.py": 63.6,
    "tests/hardening/test_fuzz_commands.py": 51.6,
    "tests/studies/test_paper_run.py": 45.5,
    "tests/fe/test_background_bodies.py": 40.4,
    "tests/reliability/test_kill.py": 34.6,
    "tests/sweep/test_kill_resume.py": 26.8,
    "tests/cli/test_reruns.py": 24.6,
    "tests/faults/test_sif.py": 24.0,
    "tests/hardening/test_interrupts.py": 21.9,
    "tests/faults/test_fault_sweeps.py": 20.6,
    "tests/faults/test_crack_growth_cli.py": 19.6,
    "tests/config/test_validate_completeness.py": 19.4,
    "tests/sweep/test_dask_cluster.py": 16.6,
    "tests/cli/test_diagnose_pulses.py": 15.0,
    "tests/sweep/test_example.py": 14.2,
    "tests/cli/test_cli_foundation.py": 13.8,
    "tests/fe/test_fe_faults.py": 13.3,
    "tests/test_readme.py": 13.2,
    "tests/fe/test_load_consistent.py": 13.2,
    "tests/studies/test_warm_run_cache.py": 11.9,
    "tests/cli/test_cli_polish.py": 11.2,
    "tests/sweep/test_failed_runs_exit.py": 11.1,
    "tests/dynamics/test_kernel_mutants.py": 10.7,
    "tests/fe/test_contact.py": 10.0,
    "tests/studies/test_model_regimes.py": 9.4,
    "tests/dynamics/test_transverse_examples.py": 8.4,
    "tests/fe/test_crack_path_map.py": 7.6,
    "tests/cli/test_diagnose_inputs.py": 7.6,
    "tests/cli/test_file_reruns.py": 6.4,
    "tests/fe/test_stiffness_fe.py": 5.2,
}


@pytest.fixture(autouse=True, scope="session")
def _private_cache(request, tmp_path_factory):
    """Keep the tests' stiffness maps and FE matrices out of the user's cache: one folder for
    the session (shared by pytest-xdist's workers, see :func:`pytest_configure`)."""
    old = os.environ.get("GEARDYN_CACHE_DIR")
    shared = getattr(request.config, "workerinput", {}).get("geardyn_cache_dir")
    os.environ["GEARDYN_CACHE_DIR"] = shared or str(tmp_path_factory.mktemp("geardyn-cache"))
    yield
    if old is None:
        os.environ.pop("GEARDYN_CACHE_DIR", None)
    else:
        os.environ["GEARDYN_CACHE_DIR"] = old


#: Fuzz counts reported by pytest-xdist workers (merged in the controller).
_WORKER_FUZZ_COUNTS: dict[str, int] = {}


def _fuzz_counts() -> dict[str, int]:
    try:
        from tests.hardening.conftest import FUZZ_COUNTS
    except ImportError:  # pragma: no cover
        return {}
    return dict(FUZZ_COUNTS)


def pytest_sessionfinish(session):
    """In a pytest-xdist worker: hand the fuzz counts to the controller."""
    out = getattr(session.config, "workeroutput", None)
    if out is not None:
        out["fuzz_counts"] = _fuzz_counts()


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """pytest-xdist controller: collect a finished worker's fuzz counts."""
    for family, n in getattr(node, "workeroutput", {}).get("fuzz_counts", {}).items():
        _WORKER_FUZZ_COUNTS[family] = _WORKER_FUZZ_COUNTS.get(family, 0) + n


def pytest_terminal_summary(terminalreporter):
    """Report how many fuzzed inputs each command family was given (hardening tests)."""
    counts = _fuzz_counts()
    for family, n in _WORKER_FUZZ_COUNTS.items():
        counts[family] = counts.get(family, 0) + n
    if counts:
        terminalreporter.section("fuzzed inputs per command family")
        for family, n in sorted(counts.items()):
            terminalreporter.write_line(f"{family}: {n} generated inputs, each a valid run or a "
                                        "clean error (exit 2, field named, no traceback)")


@pytest.fixture(scope="module")
def client():
    """An in-process Dask cluster (two worker threads) for the sweep and reliability tests: the
    same scheduler and task code paths as a process cluster, without the start-up time."""
    import logging

    import dask
    from distributed import Client, LocalCluster

    # as geardyn's own local cluster (geardyn.studies.sweep.execute, local_workers): no
    # stack sampling every 10 ms for a dashboard nobody sees, and the scheduler's HTTP server
    # on a free port (dashboard_address=None asks for 8787, and Dask warns "Port 8787 is
    # already in use" when the other test worker's cluster has it)
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                               dashboard_address="127.0.0.1:0",
                               scheduler_kwargs={"dashboard": False}, silence_logs=logging.ERROR)
    cl = Client(cluster)
    yield cl
    cl.close()
    cluster.close()
