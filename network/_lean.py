"""Leaner imports for command processes (``python -m network.<command>``), issue 18 item 2.

Importing ``scipy.sparse`` and ``scipy.spatial`` (measured with SciPy 1.17.1) costs this
project's commands about 0.15 s of work they never use, a sixth of a 5 000-sphere
``network.solve``:

- SciPy's array-API layer clones the ``numpy`` namespace (``dir(numpy)`` and ``getattr`` of every
  name), which executes NumPy's lazily loaded ``numpy.f2py`` (and through it
  ``charset_normalizer``), ``numpy.testing`` and ``numpy.ma``: 0.08 s;
- SciPy's ``xp_capabilities`` decorator parses the numpydoc docstring of each of some 230
  functions of ``scipy.special`` and ``scipy.spatial`` at import to append its array-API
  support table to ``__doc__``: 0.07 s;
- pyamg's ``__init__`` imports every solver family, its gallery (and ``scipy.io``), its plots and
  ``importlib.metadata``: 0.05 s, where the smoothed-aggregation modules the commands use take
  0.01 s;
- OpenBLAS starts a thread per core whose waits spin on the cores the pipeline's own threads
  use; the commands have no dense algebra large enough to gain from them (the AMG solves ran
  under a one-thread limit already): started with one thread, 5 000 spheres 1.010 -> 0.900 s,
  20 000 2.400 -> 2.180 s (16 interleaved pairs each). ``OPENBLAS_NUM_THREADS`` set by the
  user is left as it is;
- glibc's malloc returns every large freed block to the kernel, so that each NumPy temporary
  of the pipeline is page-faulted afresh: :func:`keep_heap` (called once the packing is read)
  keeps it for the next one.

:func:`lean_imports` registers ``numpy.f2py`` and ``numpy.testing`` with the standard
library's :class:`importlib.util.LazyLoader` (the module object exists, its code runs on the
first attribute access: ``from numpy.testing import ...`` works as before; ``numpy.ma`` is
left to load, :data:`LAZY_NUMPY`), replaces SciPy's ``xp_capabilities`` (where its array-API
layer has one) by one that leaves functions and their docstrings as they are (the support
tables feed SciPy's own test suite and documentation only), and registers pyamg and
``scipy.spatial`` with their ``__init__`` deferred to the first package-level name asked for
that their submodules do not answer (:func:`_package_first`, :data:`LAZY_INIT`), and
sets ``OPENBLAS_NUM_THREADS=1`` before NumPy loads where it is unset (:func:`user_environment`
hands other programs the environment without it). Computations are untouched but for the last
bits of long BLAS reductions. The package applies it only when Python was started as
``python -m network.<command>`` (``sys.argv[0]`` is ``'-m'`` while the package is imported),
never when the library is imported into someone's session.
"""

from __future__ import annotations

import ctypes
import gc
import importlib.util
import os
import sys
import threading

#: NumPy submodules that SciPy's namespace clone executes and no command uses. Not
#: ``numpy.ma`` (0.015 s): NumPy >= 2.3's ``np.unique`` asks ``np.ma.is_masked`` on every call,
#: so each command loads it anyway, and Python 3.11's LazyLoader is not thread-safe: a first
#: use from two threads at once met a half-executed module ("module 'numpy.ma' has no attribute
#: 'isMaskedArray'", 1 run in 12 once SciPy's modules were imported beside gmsh).
LAZY_NUMPY = ("numpy.f2py", "numpy.testing")
#: Packages whose ``__init__`` imports far more than the commands use (module docstring), with
#: the package-level names the commands ask for served from the submodule that defines them
#: (``scipy.spatial.Delaunay`` is ``scipy.spatial._qhull.Delaunay``): SciPy's spatial
#: ``__init__`` brings ``distance`` (and ``scipy.special``), ``transform`` (and
#: ``scipy.constants``), Voronoi and Procrustes: 53 modules, 0.055 s of a solve (20 paired runs).
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


#: glibc's malloc kept from handing memory back between the pipeline's stages
#: (:func:`keep_heap`): ``mallopt`` parameter number -> bytes. M_MMAP_THRESHOLD (-3): blocks
#: below it come from the heap instead of a fresh ``mmap``; M_TRIM_THRESHOLD (-1): free memory
#: at the heap's top kept up to this; M_TOP_PAD (-2): extra taken per heap extension.
HEAP_KEPT = {-3: 256 << 20, -1: 512 << 20, -2: 64 << 20}
#: Largest packing (spheres) :func:`keep_heap` acts on: measured faster up to 300 000 spheres
#: (peak memory +3-7 %); at 1e6 no faster and 0.77 GB more (docs/network-bench.md, session 16).
HEAP_KEPT_MAX_SPHERES = 300_000
#: The environment variables through which a user sets the same parameters (left alone then).
MALLOC_ENV = ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_", "MALLOC_TOP_PAD_",
              "GLIBC_TUNABLES")
#: True in a command process (:func:`lean_imports` has run).
COMMAND = False
#: True once :func:`keep_heap` has set :data:`HEAP_KEPT` in this process.
HEAP_SET = False

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
    global BLAS_SINGLE, COMMAND
    COMMAND = True
    gc.disable()                                 # until imports_done
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


def imports_done() -> None:
    """End of the package's import in a command process: the cyclic garbage collector, off
    since :func:`lean_imports` (64 young and 5 middle collections over the import's objects,
    0.014 s of a 5 000-sphere command), is switched on again with everything imported so far
    frozen out of its passes (:func:`gc.freeze`: modules, functions and classes live to the
    end anyway). No-op outside a command process."""
    if COMMAND and not gc.isenabled():
        gc.freeze()
        gc.enable()


def keep_heap(n_spheres: int) -> bool:
    """In a command process on glibc, keep freed memory in the heap for the next stage.

    glibc's malloc serves blocks above its ``mmap`` threshold (128 kB, raised on the fly to at
    most 32 MB) with fresh mappings and returns them at ``free``: every large NumPy temporary of
    the pipeline is then paid again in page faults, zeroed by the kernel, 4 kB at a time (1e5
    faults, 0.3-0.7 s of kernel time in a 20 000-sphere ``network.solve``). With
    :data:`HEAP_KEPT` (blocks up to 256 MB from the heap, up to 512 MB of free heap kept) a
    freed block is re-used by the next one. Acts on packings of at most
    :data:`HEAP_KEPT_MAX_SPHERES` spheres, only where the user set none of :data:`MALLOC_ENV`
    and Python was started as a command (:data:`COMMAND`); True where the setting is in
    effect (set by this call or an earlier one, :data:`HEAP_SET`). Results are untouched (where
    memory comes from, not what is computed).
    """
    global HEAP_SET
    if HEAP_SET:
        return True
    if not COMMAND or n_spheres > HEAP_KEPT_MAX_SPHERES or any(v in os.environ
                                                                for v in MALLOC_ENV):
        return False
    try:
        os.confstr("CS_GNU_LIBC_VERSION")        # ValueError / OSError where not glibc
        mallopt = ctypes.CDLL(None).mallopt
    except (ValueError, OSError, AttributeError):
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    HEAP_SET = all([mallopt(param, value) == 1 for param, value in HEAP_KEPT.items()])
    return HEAP_SET
