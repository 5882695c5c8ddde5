"""Leaner command processes (``python -m network.<command>``): two measured tricks, nothing else.

Importing ``scipy.sparse`` and ``scipy.spatial`` costs this project's commands work they never
use:

- SciPy's array-API layer clones the ``numpy`` namespace (``dir(numpy)`` and ``getattr`` of every
  name), which executes NumPy's lazily loaded ``numpy.f2py`` (and through it
  ``charset_normalizer``), ``numpy.testing`` and ``numpy.ma``;
- SciPy's ``xp_capabilities`` decorator parses the numpydoc docstring of each of some 230
  functions of ``scipy.special`` and ``scipy.spatial`` at import to append its array-API
  support table to ``__doc__``;
- pyamg's ``__init__`` imports every solver family, its gallery (and ``scipy.io``), its plots and
  ``importlib.metadata``, and ``scipy.spatial``'s brings ``distance`` (and ``scipy.special``),
  ``transform`` (and ``scipy.constants``), Voronoi and Procrustes, where the commands use the
  smoothed-aggregation modules, Qhull and the k-d tree alone;
- OpenBLAS starts a thread per core whose waits spin on the cores of the pipeline's threads.

What remains, each measured on ``python -m network.solve`` (bundled scene, default and
``--stokes``; a 5 000-sphere packing, ``--stokes``; medians of paired runs with and without it,
CPU seconds beside wall seconds on a shared two-core machine):

1. :func:`lean_imports` registers ``numpy.f2py`` and ``numpy.testing`` with the standard
   library's :class:`importlib.util.LazyLoader` (the module object exists, its code runs on the
   first attribute access: ``from numpy.testing import ...`` works as ever; ``numpy.ma`` is
   left to load, :data:`LAZY_NUMPY`), replaces SciPy's ``xp_capabilities`` (where its array-API
   layer has one) by one that leaves functions and their docstrings as they are (the support
   tables feed SciPy's own test suite and documentation only), and registers pyamg and
   ``scipy.spatial`` with their ``__init__`` deferred to the first package-level name asked for
   that their submodules do not answer (:func:`_package_first`, :data:`LAZY_INIT`). Without it
   the commands take 22-34 % more CPU time and 27-35 % more wall time.
2. It sets ``OPENBLAS_NUM_THREADS=1`` before NumPy loads where the user has not set it
   (:func:`user_environment` hands other programs the environment without it). Without it the
   commands take 7-14 % more CPU time and 10-11 % more wall time.

The garbage collector off during the imports (2-5 %) and glibc's freed heap kept (``mallopt``,
under 10 % of the default command) paid less and are not done. Computations are untouched but
for the last bits of long BLAS reductions. Both act only where Python was started as
``python -m network.<command>`` (``sys.argv[0]`` is ``'-m'`` while the package is imported),
never in a library caller's session, whose NumPy, SciPy and pyamg stay as they are.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import threading

#: NumPy submodules that SciPy's namespace clone executes and no command uses. Not
#: ``numpy.ma``: NumPy >= 2.3's ``np.unique`` asks ``np.ma.is_masked`` on every call,
#: so each command loads it anyway, and Python 3.11's LazyLoader is not thread-safe: a first
#: use from two threads at once can meet a half-executed module ("module 'numpy.ma' has no
#: attribute 'isMaskedArray'", about one run in 12 where SciPy's modules are imported beside
#: gmsh).
LAZY_NUMPY = ("numpy.f2py", "numpy.testing")
#: Packages whose ``__init__`` imports far more than the commands use (module docstring), with
#: the package-level names the commands ask for served from the submodule that defines them
#: (``scipy.spatial.Delaunay`` is ``scipy.spatial._qhull.Delaunay``): SciPy's spatial
#: ``__init__`` brings ``distance`` (and ``scipy.special``), ``transform`` (and
#: ``scipy.constants``), Voronoi and Procrustes: 53 modules.
LAZY_INIT = {
    "pyamg": {},
    "scipy.spatial": {"Delaunay": "_qhull", "ConvexHull": "_qhull", "QhullError": "_qhull",
                      "cKDTree": "_ckdtree"},
}


def _lazy(name: str) -> bool:
    """Register ``name`` as a lazily executed module (and as its parent's attribute, so that
    the parent's own ``__getattr__`` never imports it); False where it is already imported or
    cannot be found."""
    if name in sys.modules:
        return False
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None:
        return False
    loader = importlib.util.LazyLoader(spec.loader)
    spec.loader = loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    loader.exec_module(module)
    parent, _, child = name.rpartition(".")
    setattr(sys.modules[parent], child, module)
    return True


def _plain_capabilities(**_kw):
    """SciPy's ``xp_capabilities(...)`` without its docstring rewriting: the function as it is."""
    return lambda f: f


def _package_first(name: str, names: dict[str, str] | None = None) -> bool:
    """Register package ``name`` with its ``__init__`` not yet run: its submodules import as
    ever (``import pyamg.aggregation`` runs only what that module needs), a name of ``names``
    (name -> the submodule defining it) comes from that submodule, and the first other
    package-level name asked for (``pyamg.solve``, ``pyamg.__version__``) runs ``__init__``
    then (as does a mapped name its submodule lacks). False where it is already imported or
    cannot be found."""
    if name in sys.modules:
        return False
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None or spec.submodule_search_locations is None:
        return False
    module = importlib.util.module_from_spec(spec)
    lock = threading.Lock()
    names = dict(names or {})

    def __getattr__(attr: str):
        if attr in names:
            try:
                value = getattr(importlib.import_module(f"{name}.{names[attr]}"), attr)
            except (ImportError, AttributeError):    # another layout: run __init__ below
                pass
            else:
                setattr(module, attr, value)         # what __init__ binds it to as well
                return value
        elif not attr.startswith("__") and importlib.util.find_spec(f"{name}.{attr}"):
            return importlib.import_module(f"{name}.{attr}")
        with lock:                               # one thread runs __init__, the others wait
            if module.__dict__.get("__getattr__") is __getattr__:
                del module.__dict__["__getattr__"]   # the package as its own __init__ makes it
                spec.loader.exec_module(module)
        return getattr(module, attr)

    module.__getattr__ = __getattr__
    sys.modules[name] = module
    return True


#: True once :func:`lean_imports` has started OpenBLAS with one thread (``OPENBLAS_NUM_THREADS``
#: unset before NumPy's import, and NumPy built on OpenBLAS): then no call needs limiting.
BLAS_SINGLE = False
#: Environment variables :func:`lean_imports` set (name -> value), for :func:`user_environment`.
ADDED_ENV: dict[str, str] = {}


def user_environment() -> dict[str, str]:
    """``os.environ`` without what :func:`lean_imports` added: the environment to hand to
    another program (YADE) or to a command timed as a user would start it."""
    env = dict(os.environ)
    for name, value in ADDED_ENV.items():
        if env.get(name) == value:
            del env[name]
    return env


def lean_imports() -> list[str]:
    """Make :data:`LAZY_NUMPY` lazy, :data:`LAZY_INIT`'s ``__init__`` deferred and SciPy's
    ``xp_capabilities`` plain, and start OpenBLAS with one thread where the environment does
    not say otherwise (:data:`BLAS_SINGLE`); the names of what was changed (an empty list
    where everything was already imported)."""
    global BLAS_SINGLE
    changed = []
    if "numpy" not in sys.modules and "OPENBLAS_NUM_THREADS" not in os.environ:
        os.environ["OPENBLAS_NUM_THREADS"] = ADDED_ENV["OPENBLAS_NUM_THREADS"] = "1"
        changed.append("OPENBLAS_NUM_THREADS=1")
    import numpy  # noqa: F401  (the parent of the lazy submodules)

    if changed:
        blas = numpy.__config__.CONFIG.get("Build Dependencies", {}).get("blas", {})
        BLAS_SINGLE = "openblas" in str(blas.get("name", "")).lower()
    changed += [n for n in LAZY_NUMPY if _lazy(n)]
    changed += [n for n, names in LAZY_INIT.items() if _package_first(n, names)]
    if "scipy.special" not in sys.modules:
        try:
            import scipy._lib._array_api as api
        except ImportError:              # a SciPy without the array-API layer: nothing to do
            return changed
        if callable(getattr(api, "xp_capabilities", None)):
            api.xp_capabilities = _plain_capabilities
            changed.append("scipy xp_capabilities")
    return changed
