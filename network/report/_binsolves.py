"""The solve cache of ``network.report``'s bin beds (:mod:`network.report.binbeds`).

Each bed of a bin's bed set is solved once: the solve is kept in ``--bed-dir``
(``bin_solves/<key>.json``), keyed by the bed file's SHA-256, the code version (package version
and a hash of the network, throats and cache sources) and the solve's inputs, so a second report
on the same beds reads it.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import json
import os
from pathlib import Path

#: the cache folder's subfolder of solves
BIN_SOLVES = "bin_solves"
_ROOT = Path(__file__).resolve().parents[2]


def solve_cache_key(path, inputs: dict) -> str:
    """SHA-256 of the bed file's bytes, the code version and the solve's inputs (a JSON dict)."""
    h = hashlib.sha256()
    h.update(Path(path).read_bytes())
    h.update(code_version().encode())
    h.update(json.dumps(inputs, sort_keys=True).encode())
    return h.hexdigest()


_CODE_VERSION = None


def code_version() -> str:
    """The package version and a SHA-256 of the network, throats and cache sources (.py)."""
    global _CODE_VERSION
    if _CODE_VERSION is None:
        h = hashlib.sha256()
        for pkg in ("network", "throats", "cache"):
            for p in sorted((_ROOT / pkg).rglob("*.py")):
                h.update(str(p.relative_to(_ROOT)).encode())
                h.update(p.read_bytes())
        try:
            v = importlib.metadata.version("grainflow")
        except importlib.metadata.PackageNotFoundError:
            v = "?"
        _CODE_VERSION = f"{v}+{h.hexdigest()[:16]}"
    return _CODE_VERSION


def _read_cached(p: Path):
    try:
        d = json.loads(p.read_text())
    except (OSError, ValueError):
        return None
    return d if isinstance(d, dict) and d.get("code_version") == code_version() else None


def _write_cached(p: Path, d: dict) -> None:
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.with_name(p.name + ".tmp")
    tmp.write_text(json.dumps(d))
    os.replace(tmp, p)


def solve_set(plan: dict, solve_bed, inputs: dict) -> list[dict]:
    """Each bed of the set solved (``solve_bed(path) -> dict`` with ``porosity``,
    ``gradient_z_pa_per_m``, ``gradient_x_pa_per_m``, ``converged``), read from the cache where
    a solve of the same file, code and inputs is there."""
    out = []
    cache = Path(plan["bed_dir"]) / BIN_SOLVES
    for stress, path in plan["beds"]:
        key = solve_cache_key(path, inputs)
        cp = cache / f"{key}.json"
        got = _read_cached(cp)
        cached = got is not None
        if got is None:
            got = solve_bed(path)
            got = dict(got, code_version=code_version(), inputs=inputs, bed=str(path))
            try:
                _write_cached(cp, got)
            except OSError:
                pass                    # an unwritable cache: solved, not cached
        out.append(dict(got, stress_pa=float(stress), path=str(path), cached=cached))
    return out
