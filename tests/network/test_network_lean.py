"""Lean command processes (network._lean): NumPy's f2py and testing deferred, pyamg's and
scipy.spatial's __init__ deferred, SciPy's docstring tables skipped, OpenBLAS on one thread, and
nothing a command computes changes."""

from __future__ import annotations

import pytest
import json
import os
import subprocess
import sys

PROBE = """
import json, sys
sys.argv = {argv!r}
import network, numpy, scipy.special
state = {{n: type(sys.modules[n]).__name__ for n in ("numpy.f2py", "numpy.testing", "numpy.ma")}}
from numpy.testing import assert_allclose
assert_allclose(scipy.special.gamma(5.0), 24.0, rtol=1e-15)
masked = numpy.ma.masked_invalid([float("nan"), 1.0, 2.0])
print(json.dumps({{"state": state, "count": int(masked.count()), "sum": float(masked.sum()),
                  "ma": type(sys.modules["numpy.ma"]).__name__}}))
"""


def _python(code, env=None, check=True):
    """``code`` run by a fresh interpreter (``-c``): the completed process, text output."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=check, env=env)


def _json(code, env=None):
    """What ``code`` prints as JSON in a fresh interpreter."""
    return json.loads(_python(code, env).stdout)


def _probe(argv):
    return _json(PROBE.format(argv=argv))


@pytest.mark.slow
def test_command_process_defers_numpy_submodules_until_used():
    got = _probe(["-m"])               # what python -m network.<command> sees on import
    # numpy.ma loads as ever: np.unique needs it, and a lazy module is not thread-safe in 3.11
    assert got["state"] == {"numpy.f2py": "_LazyModule", "numpy.testing": "_LazyModule",
                            "numpy.ma": "module"}
    # first use executes them: the masked mean of (nan, 1, 2) is over two values
    assert (got["count"], got["sum"], got["ma"]) == (2, 3.0, "module")


@pytest.mark.slow
def test_library_import_leaves_numpy_and_scipy_alone():
    got = _probe(["-c"])
    assert set(got["state"].values()) == {"module"}
    assert (got["count"], got["sum"]) == (2, 3.0)


@pytest.mark.slow
def test_command_answer_equals_the_library_answer(tmp_path):
    """python -m network.solve (lean) and the same main() in a plain process agree: the network
    to the bit, k and the drop to the CG tolerance (two runs of either differ by ~1e-13)."""
    cmd = ["--stokes", "--quiet", "--json"]
    a, b = tmp_path / "lean.json", tmp_path / "plain.json"
    subprocess.run([sys.executable, "-m", "network.solve", *cmd, str(a)], check=True,
                   capture_output=True)
    plain = f"import network.solve as s; raise SystemExit(s.main({cmd + [str(b)]!r}))"
    subprocess.run([sys.executable, "-c", plain], check=True, capture_output=True)
    ja, jb = json.loads(a.read_text()), json.loads(b.read_text())
    for key in ("porosity", "n_pores", "n_throats"):
        assert ja[key] == jb[key], key
    for key in ("permeability_m2", "pressure_drop_pa"):
        assert abs(ja[key] / jb[key] - 1) < 1e-10, key


FINISH = """
import atexit, sys
from network._cli import finish
atexit.register(lambda: print("handler ran"))
sys.stdout.write("unflushed, ")
sys.stderr.write("no newline")
finish({code})
print("never reached")
"""


CLOSED = """
import os, sys
from network._cli import finish
sys.stdout.write("lost")        # buffered for a stdout that is gone before the exit
os.close(1)
finish(2)
"""


@pytest.mark.slow
def test_finish_with_stdout_gone_keeps_the_status_and_prints_no_traceback():
    """A stdout that cannot be flushed at the end (the reader gone, the descriptor closed):
    finish still ends with the command's status, and stderr stays clean."""
    out = _python(CLOSED, check=False)
    assert out.returncode == 2 and out.stderr == ""


@pytest.mark.slow
def test_finish_runs_handlers_flushes_and_keeps_the_exit_status():
    """finish() ends the process by os._exit: the atexit handlers still run, buffered output
    (a pipe: block-buffered) still arrives, and the status is the command's."""
    for code in (0, 1, 2):
        out = _python(FINISH.format(code=code), check=False)
        assert (out.returncode, out.stdout, out.stderr) == (code, "unflushed, handler ran\n",
                                                            "no newline")


PYAMG = """
import json, sys
sys.argv = {argv!r}
import network
import pyamg.aggregation
from pyamg import amg_core
before = "pyamg.gallery" in sys.modules
version, solver = pyamg.__version__, pyamg.smoothed_aggregation_solver
print(json.dumps({{"gallery_before": before, "gallery_after": "pyamg.gallery" in sys.modules,
                  "version": version, "solver": solver.__name__,
                  "core": amg_core.__name__}}))
"""


@pytest.mark.slow
def test_command_process_runs_pyamg_init_only_when_a_package_name_is_asked_for():
    """A command imports pyamg's smoothed-aggregation modules without pyamg's __init__ (its
    gallery, plotting and version lookup); the first package-level name runs it, and then the
    package is the one a plain import gives."""
    from importlib.metadata import version
    runs = {}
    for argv in (["-m"], ["-c"]):
        runs[argv[0]] = _json(PYAMG.format(argv=argv))
    assert runs["-m"]["gallery_before"] is False and runs["-c"]["gallery_before"] is True
    for got in runs.values():
        assert got["gallery_after"] is True and got["version"] == version("pyamg")
        assert (got["solver"], got["core"]) == ("smoothed_aggregation_solver", "pyamg.amg_core")


#: Probe prelude: ``at_once(ask)`` calls ``ask()`` from eight threads released together
#: (a barrier) and returns their answers. No braces: probes ``str.format`` after it.
AT_ONCE = """
import threading

def at_once(ask, n=8):
    answers, barrier = [], threading.Barrier(n)

    def first_use():
        barrier.wait()
        answers.append(ask())

    threads = [threading.Thread(target=first_use) for _ in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return answers
"""

DEFERRED = AT_ONCE + """
import json, sys
import network
from network._deferred import csgraph, spatial
before = [m for m in ("scipy.spatial", "scipy.sparse.csgraph", "scipy.sparse.linalg")
          if m in sys.modules]
got = at_once(lambda: (spatial.cKDTree.__name__, csgraph.connected_components.__name__))
print(json.dumps({"before": before, "got": sorted(set(got)), "n": len(got)}))
"""


@pytest.mark.slow
def test_scipy_modules_are_imported_at_first_use_and_safely_from_threads():
    """Importing the package leaves scipy.spatial, csgraph and sparse.linalg unimported
    (network._deferred); eight threads using them first at once all get the real functions
    (the import system's lock, not a half-executed module)."""
    for _ in range(3):
        got = _json(DEFERRED)
        assert got == {"before": [], "got": [["cKDTree", "connected_components"]], "n": 8}


BLAS = """
import json, os, sys
sys.argv = {argv!r}
import network
from network._lean import BLAS_SINGLE, user_environment
import scipy.linalg  # noqa: F401 - SciPy's own OpenBLAS too
from threadpoolctl import threadpool_info
threads = sorted({{i["num_threads"] for i in threadpool_info() if i["internal_api"] == "openblas"}})
print(json.dumps({{"env": os.environ.get("OPENBLAS_NUM_THREADS"), "single": BLAS_SINGLE,
                  "threads": threads,
                  "user": user_environment().get("OPENBLAS_NUM_THREADS")}}))
"""


def _blas(argv, preset=None):
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if preset is not None:
        env["OPENBLAS_NUM_THREADS"] = preset
    return _json(BLAS.format(argv=argv), env)


@pytest.mark.slow
def test_command_process_starts_openblas_with_one_thread_unless_told_otherwise():
    """python -m network.<command>: OpenBLAS (NumPy's and SciPy's) starts with one thread, the
    environment handed to other programs does not carry it; a user's setting is kept; the
    library imported into a session leaves OpenBLAS alone."""
    got = _blas(["-m"])
    if got["threads"]:                                  # NumPy/SciPy built on OpenBLAS
        assert got == {"env": "1", "single": True, "threads": [1], "user": None}
    kept = _blas(["-m"], preset="2")
    assert (kept["env"], kept["single"], kept["user"]) == ("2", False, "2")
    if got["threads"] and (os.cpu_count() or 1) >= 2:
        assert kept["threads"] == [2]
    plain = _blas(["-c"])
    assert plain["env"] is None and plain["single"] is False and plain["user"] is None


SPATIAL = AT_ONCE + """
import json, sys
sys.argv = {argv!r}
import numpy as np
import network
import scipy.spatial as sps
names = at_once(lambda: (sps.Delaunay.__name__, sps.cKDTree.__name__, sps.QhullError.__name__))
from scipy.spatial._qhull import Delaunay
hull = sps.ConvexHull(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]))
pairs = sps.cKDTree(np.array([[0, 0, 0], [0.5, 0, 0], [3, 0, 0.0]])).query_pairs(1.0)
tri = sps.Delaunay(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]))
before = [m for m in ("scipy.spatial.distance", "scipy.special", "scipy.spatial.transform")
          if m in sys.modules]
d = float(sps.minkowski_distance([0, 0], [3, 4]))      # a name only the package's __init__ has
print(json.dumps({{"volume": hull.volume, "pairs": sorted(map(sorted, pairs)),
                  "tets": tri.simplices.shape[0], "same": sps.Delaunay is Delaunay,
                  "threads": sorted(set(names)), "n": len(names),
                  "before": before, "d": d,
                  "after": "scipy.spatial.distance" in sys.modules}}))
"""


@pytest.mark.slow
def test_command_process_serves_qhull_and_kdtree_without_scipy_spatial_init():
    """A command takes Delaunay, ConvexHull and cKDTree from their own modules without
    scipy.spatial's __init__ (distance, scipy.special, transform), eight threads asking at once
    included; any other package-level name runs it; the answers and objects are a plain
    import's."""
    lean = _json(SPATIAL.format(argv=["-m"]))
    plain = _json(SPATIAL.format(argv=["-c"]))
    assert lean["before"] == [] and "scipy.spatial.distance" in plain["before"]
    for got in (lean, plain):
        assert abs(got["volume"] - 1.0 / 6.0) < 1e-15 and got["pairs"] == [[0, 1]]
        assert got["tets"] == 1 and got["same"] is True
        assert got["n"] == 8 and got["threads"] == [["Delaunay", "cKDTree", "QhullError"]]
        assert got["d"] == 5.0 and got["after"] is True
