"""The code's architecture, read with ``ast``: layer order, no cycles, long modules flagged.

Rules:

* packages: ``throats`` <- ``cache`` <- ``network``; below them all ``network.core`` (the
  packing format, the text reader and the command-line base, NumPy only at import), the one
  module of ``network`` that ``dem``, ``throats`` and ``cache`` import (it imports none of
  them); no package imports ``dem``. A benchmark (``<package>/bench.py``) is a tool on top of
  the pipeline and may import the public API (the package itself, never a private module) of the
  packages below or beside it;
* inside a package, subpackages form layers (``LAYERS``): a module imports only its own layer
  and the layers before it (a subpackage's ``__main__`` is a command, in the top layer); the
  module import graph has no cycle;
* inside ``network`` only the ``conductance`` layer imports ``cache``;
* no import of a project module inside a function (matplotlib and other optional libraries may
  stay lazy); no import of another module's ``_private`` name;
* a library module over ``MAX_LINES`` lines or with a module docstring over ``MAX_DOC_LINES``
  lines is named in a warning: modules are cut by concept, and the line counts only flag a
  module to look at.
"""

from __future__ import annotations

import ast
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("throats", "cache", "network", "dem")
#: which project packages each package may import (bench modules: see ``BENCH_MAY_IMPORT``)
MAY_IMPORT = {"throats": {"network"}, "cache": {"throats", "network"},
              "network": {"throats", "cache"}, "dem": {"network"}}
#: of another package, a package may import only these modules where listed (the light core
#: of network, nothing else of it)
ONLY_MODULES = {p: {"network": "network.core"} for p in ("dem", "throats", "cache")}
#: what the shared core may import of its own package: itself and the deferred SciPy modules
CORE = "network.core"
CORE_MAY_IMPORT = ("network.core", "network._deferred")
BENCH_MAY_IMPORT = {"throats": {"network"}, "cache": {"throats", "network"},
                    "network": {"throats", "cache"}, "dem": set()}
#: inside network, only the conductance layer talks to the Q* table (cache)
ONLY_FROM = {"cache": "network.conductance"}
#: layers inside a package, lowest first; a module's layer is its first path component
#: below the package (a subpackage name, or the module name for top-level modules)
LAYERS = {
    "network": [
        {"_lean", "_deferred", "_air", "_json", "_grains", "core", "packing"},
        {"pores"},
        {"conductance"},
        {"flow"},
        {"paths"},
        {"validation"},
        {"__init__", "_cli", "solve", "throats", "throatlist", "curve", "report", "bin", "bench",
         "benchmarks", "__main__"},
    ],
}
MAX_LINES = 450
MAX_DOC_LINES = 40


def _modules(package):
    for path in sorted((ROOT / package).rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            name, is_pkg = ".".join(parts[:-1]), True
        else:
            name, is_pkg = ".".join(parts), False
        yield name, path, is_pkg


def _resolve(module, is_pkg, node):
    """Absolute dotted names a ``from``/``import`` statement refers to, with imported names."""
    if isinstance(node, ast.Import):
        return [(a.name, None) for a in node.names]
    base = module.split(".") if is_pkg else module.split(".")[:-1]
    if node.level:
        base = base[: len(base) - (node.level - 1)]
        target = ".".join(base + ([node.module] if node.module else []))
    else:
        target = node.module or ""
    return [(target, a.name) for a in node.names]


def _project_imports(package):
    """(module, path, lineno, target, name, in_function) for every project import."""
    out = []
    for module, path, is_pkg in _modules(package):
        tree = ast.parse(path.read_text(), filename=str(path))
        func_lines = set()
        for fn in ast.walk(tree):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for sub in ast.walk(fn):
                    if isinstance(sub, (ast.Import, ast.ImportFrom)):
                        func_lines.add(id(sub))
        for node in ast.walk(tree):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            for target, name in _resolve(module, is_pkg, node):
                top = target.split(".")[0]
                if top in PACKAGES:
                    out.append((module, path, node.lineno, target, name, id(node) in func_lines))
    return out


def _known_modules():
    return {m for p in PACKAGES for m, _, _ in _modules(p)}


@pytest.mark.slow
@pytest.mark.parametrize("package", PACKAGES)
def test_packages_import_only_what_they_may(package):
    bad = []
    for module, path, line, target, name, _ in _project_imports(package):
        top = target.split(".")[0]
        if top == package:
            continue
        is_bench = module == f"{package}.bench"
        allowed = BENCH_MAY_IMPORT[package] if is_bench else MAY_IMPORT[package]
        only = ONLY_MODULES.get(package, {}).get(top)
        if top not in allowed or (is_bench and target != top) or (
                only and not is_bench and target != only):
            bad.append(f"{path.relative_to(ROOT)}:{line} imports {target}")
        elif top in ONLY_FROM and package == ONLY_FROM[top].split(".")[0] \
                and not module.startswith(ONLY_FROM[top]):
            bad.append(f"{path.relative_to(ROOT)}:{line} imports {target}: only "
                       f"{ONLY_FROM[top]} may")
    assert not bad, "\n".join(bad)


@pytest.mark.slow
def test_the_shared_core_imports_only_itself():
    """network.core, which dem imports, imports nothing of network but itself and the deferred
    SciPy modules, so that importing it never loads the pipeline."""
    bad = [f"{p.relative_to(ROOT)}:{line} imports {t}"
           for m, p, line, t, _, _ in _project_imports("network")
           if m.startswith(CORE) and not t.startswith(CORE_MAY_IMPORT)]
    assert not bad, "\n".join(bad)


_LIGHT_PROBE = """
import json, sys
import {module}
print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in
                        ('network', 'numba', 'scipy', 'pyamg', 'matplotlib'))))
"""


@pytest.mark.slow
def test_the_shared_core_loads_numpy_alone():
    """``import network.core`` loads NumPy and the core, no SciPy, numba or pipeline layer;
    ``import dem`` loads no module of network beyond it."""
    import json
    import subprocess
    import sys

    def loaded(module):
        out = subprocess.run([sys.executable, "-c", _LIGHT_PROBE.format(module=module)],
                             capture_output=True, text=True, cwd=ROOT, check=True)
        return json.loads(out.stdout)

    core = loaded("network.core")
    own = {m for m, _, _ in _modules("network") if m.startswith(CORE)}
    assert set(core) == {"network", "network._deferred"} | own, core
    net = {m for m in loaded("dem") if m.split(".")[0] == "network"}
    assert net == set(core), net


@pytest.mark.slow
@pytest.mark.parametrize("package", PACKAGES)
def test_no_function_level_project_imports(package):
    bad = [f"{p.relative_to(ROOT)}:{line} imports {t} inside a function"
           for _, p, line, t, _, in_fn in _project_imports(package) if in_fn]
    assert not bad, "\n".join(bad)


@pytest.mark.slow
@pytest.mark.parametrize("package", PACKAGES)
def test_no_private_names_of_other_modules(package):
    known = _known_modules()
    bad = []
    for module, path, line, target, name, _ in _project_imports(package):
        if name is None or not name.startswith("_") or name.startswith("__"):
            continue
        if f"{target}.{name}" in known:       # a private module imported from its package
            continue
        bad.append(f"{path.relative_to(ROOT)}:{line} imports {target}.{name}")
    assert not bad, "\n".join(bad)


def _layer_of(package, module):
    parts = module.split(".")
    key = parts[1] if len(parts) > 1 else "__init__"
    if parts[-1] == "__main__":       # a subpackage's command (python -m network.paths)
        key = "__main__"
    for i, layer in enumerate(LAYERS[package]):
        if key in layer:
            return i
    raise AssertionError(f"{module}: not in any layer of {package} (add it to LAYERS)")


@pytest.mark.slow
@pytest.mark.parametrize("package", sorted(LAYERS))
def test_layer_order(package):
    bad = []
    for module, path, line, target, name, _ in _project_imports(package):
        if target.split(".")[0] != package:
            continue
        full = f"{target}.{name}" if name and f"{target}.{name}" in _known_modules() else target
        if full == package:
            continue      # the package's public API (only the CLIs on top should use it)
        if _layer_of(package, full) > _layer_of(package, module):
            bad.append(f"{path.relative_to(ROOT)}:{line} ({module}) imports the higher layer "
                       f"{full}")
    assert not bad, "\n".join(bad)


@pytest.mark.slow
@pytest.mark.parametrize("package", PACKAGES)
def test_no_import_cycles(package):
    known = _known_modules()
    graph: dict = {}
    for module, _, _, target, name, _ in _project_imports(package):
        full = f"{target}.{name}" if name and f"{target}.{name}" in known else target
        if full.split(".")[0] == package and full != module:
            graph.setdefault(module, set()).add(full)
    # a package's __init__ imports its modules; an import of the package is an import of it
    state: dict = {}
    stack: list = []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for n in graph.get(m, ()):
            if state.get(n) == 1:
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(n):] + [n]))
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = 2

    for m in list(graph):
        if m not in state:
            visit(m)


@pytest.mark.parametrize("package", PACKAGES)
def test_long_modules_are_flagged(package):
    """Modules are cut by concept, not to fit a line count: a module over ``MAX_LINES`` lines or
    with a module docstring over ``MAX_DOC_LINES`` lines is named in a ``UserWarning`` (a prompt
    to look for a second concept in it), never a failure."""
    long = []
    for module, path, _ in _modules(package):
        text = path.read_text()
        n = text.count("\n")
        if n > MAX_LINES:
            long.append(f"{path.relative_to(ROOT)}: {n} lines (> {MAX_LINES})")
        doc = ast.get_docstring(ast.parse(text), clean=False)
        if doc and doc.count("\n") + 1 > MAX_DOC_LINES:
            long.append(f"{path.relative_to(ROOT)}: module docstring {doc.count(chr(10)) + 1} "
                        f"lines (> {MAX_DOC_LINES})")
    if long:
        warnings.warn(f"long modules in {package}: " + "; ".join(long), UserWarning,
                      stacklevel=1)


def test_the_rules_see_a_violation(tmp_path):
    """The checker itself: an in-function import and a private name are found."""
    src = "def f():\n    from ._x import _y\n"
    tree = ast.parse(src)
    imports = [n for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    assert _resolve("network.pores._a", False, imports[0]) == [("network.pores._x", "_y")]
    assert _resolve("network.pores", True, imports[0]) == [("network.pores._x", "_y")]


def _public_home(target: str):
    """The public package above a private module path (``network.pores._sample`` ->
    ``network.pores``), or None when the path has no private part."""
    parts = target.split(".")
    for i, p in enumerate(parts):
        if p.startswith("_"):
            return ".".join(parts[:i]) if i else None
    return None


@pytest.mark.slow
def test_tests_use_the_public_api():
    """A test imports from a private module only what no public package above it exports."""
    import importlib

    bad = []
    for path in sorted((ROOT / "tests").rglob("test_*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom) or node.level or not node.module:
                continue
            home = _public_home(node.module)
            if home is None or home.split(".")[0] not in PACKAGES:
                continue
            public = set(getattr(importlib.import_module(home), "__all__", ()))
            for a in node.names:
                if a.name in public:
                    bad.append(f"{path.relative_to(ROOT)}:{node.lineno} imports {a.name} from "
                               f"{node.module}: use {home}")
    assert not bad, "\n".join(bad)
