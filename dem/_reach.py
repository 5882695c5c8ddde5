r"""The porosities the grown fill reaches for a grain in a container: one range, cached.

The porosity search of ``dem.pack --grain G --porosity P`` (:mod:`dem._grain_search`) moves
one lever λ in [-1, 1] (:func:`dem._clump_pack.procedure_lever`). Its grain count is the
grain's own, never the request's: :math:`N = \lfloor (1 - φ_c) V / (V_t \overline{f^3}) \rfloor` with φ_c the middle
of the grain's measured loose-fill porosity (:func:`count_porosity`), so a bed made at a given
λ, and with it the range, depends on the template, the container and the seed only. The range
is that of the beds at :data:`RANGE_LEVERS`: -1 (closed-box growth, the densest), 0 (free fall,
frictionless: where the lever's two halves meet; wheat's loosest bed lies near it, its
porosity is not monotone in λ) and +1 (deposition friction 1).

Those beds are packed once and their porosities kept in a JSON file per key
(:func:`reach_key`: template spheres, container, seed, grain count, material and run settings,
the ``dem`` sources, numpy's and numba's versions, the machine) in :func:`reach_dir`
(``$GRAINFLOW_REACH_CACHE``, else ``~/.cache/grainflow/reach``). A later request reads them:
refused at once when out of range, searched from them when inside.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
from pathlib import Path

import numpy as np

from .grains import grain

__all__ = ["RANGE_LEVERS", "COUNT_POROSITY_DEFAULT", "count_porosity", "reach_dir", "reach_key",
           "load_reach", "store_reach"]

#: the levers whose beds bound the range: closed box, frictionless free fall, friction 1
RANGE_LEVERS = (-1.0, 0.0, 1.0)
#: grain count porosity of a template with no measured loose fill (thesis Table 3.1)
COUNT_POROSITY_DEFAULT = 0.408
FORMAT = "grainflow.dem.reach"
_DEM = Path(__file__).resolve().parent


def count_porosity(name: str) -> tuple[float, str]:
    """(φ_c, where it comes from): the porosity the grown fill counts its grains from, the
    middle of the grain's measured loose-fill bulk porosity, else 0.408 (thesis Table 3.1).

    >>> count_porosity("soybean")[0], count_porosity("my_kernel")[0]
    (0.40985, 0.408)
    """
    try:
        rng = grain(name).bulk_porosity
    except ValueError:
        return COUNT_POROSITY_DEFAULT, "no library grain: 0.408, thesis Table 3.1"
    if rng.value is None:
        return COUNT_POROSITY_DEFAULT, f"no measured loose fill of {name}: 0.408, thesis Table 3.1"
    lo, hi = rng.value
    return round(0.5 * (lo + hi), 12), f"middle of {name}'s loose fill {lo:g}-{hi:g} ({rng.source})"


def reach_dir() -> Path:
    """``$GRAINFLOW_REACH_CACHE``, else ``~/.cache/grainflow/reach``."""
    env = os.environ.get("GRAINFLOW_REACH_CACHE")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "grainflow" / "reach"


def _code_digest() -> str:
    h = hashlib.blake2b(digest_size=8)
    for p in sorted(_DEM.glob("*.py")):
        h.update(p.name.encode() + b"\0" + p.read_bytes())
    return h.hexdigest()


def reach_key(container, template, *, seed: int, n_grains: int, settings: dict) -> tuple[str, dict]:
    """(file name, what it keys): the range's cache entry of ``template`` in ``container``
    with ``seed`` and ``n_grains``; ``settings`` are the packing's other inputs (material,
    mass scale, equilibrium tolerance, size spread, ...; not the step limit, see
    :func:`load_reach`)."""
    try:
        import numba
        numba_version = numba.__version__
    except ImportError:                       # pragma: no cover - numba is a dependency
        numba_version = None
    what = {"template": template.name, "container": container.to_dict(), "seed": int(seed),
            "n_grains": int(n_grains), "levers": list(RANGE_LEVERS),
            "settings": json.loads(json.dumps(settings, sort_keys=True, default=str)),
            "code": _code_digest(), "numpy": np.__version__, "numba": numba_version,
            "machine": platform.machine()}
    h = hashlib.blake2b(json.dumps(what, sort_keys=True).encode(), digest_size=10)
    h.update(np.ascontiguousarray(template.positions, dtype=float).tobytes())
    h.update(np.ascontiguousarray(template.radii, dtype=float).tobytes())
    safe = "".join(c if c.isalnum() or c in "_-" else "_" for c in template.name)[:40]
    return f"{safe}-{h.hexdigest()}.json", what


def load_reach(path, max_steps: int) -> dict | None:
    """The cached range entry at ``path`` if it holds for a step limit ``max_steps`` (every range
    bed reached equilibrium within it, or was made with that very limit), else None."""
    try:
        entry = json.loads(Path(path).read_text())
        beds = entry["beds"]
        if entry.get("format") != FORMAT or len(beds) != len(RANGE_LEVERS):
            return None
        [float(v) for v in entry["range"]]
        same = entry.get("max_steps") == int(max_steps)
        settled = all(b["converged"] and int(b["settle_steps"]) <= int(max_steps) for b in beds)
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return entry if same or settled else None


def store_reach(path, entry: dict) -> str | None:
    """Write ``entry`` to ``path`` atomically; None, or why it could not be kept (a read-only
    or full disk only costs the next request the range's packings again)."""
    path = Path(path)
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(json.dumps({"format": FORMAT, **entry}, indent=1))
        os.replace(tmp, path)
    except OSError as e:
        try:
            tmp.unlink(missing_ok=True)
        except OSError:
            pass
        return f"not kept: {e.strerror or e}"
    return None
