"""Which porosities a bed of grains can have: the physical bounds and the recorded ranges.

Two checks, both before any packing. :func:`check_physical_porosity` refuses a porosity no
static bed of grains has: at or below the densest packing of equal spheres (Kepler, 0.2595) or
at or above :data:`LOOSEST_POROSITY`. :func:`recorded_reach` gives the one range a grain reaches
in a container: ``dem.pack --porosity`` measures it once (the porosities of the beds its search
made, ``porosity_search.reachable`` of the bed's companion JSON) and the bundled beds
(``network/data/<grain>_grains.json``) store it, so every command quotes the same numbers
(:func:`reach_text`) and refuses a request outside them at once.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

__all__ = ["KEPLER_POROSITY", "LOOSEST_POROSITY", "check_physical_porosity", "recorded_reach",
           "reach_text", "reach_refusal"]

#: densest packing of equal spheres (face-centred cubic), 1 - pi / sqrt(18)
KEPLER_POROSITY = 1.0 - math.pi / math.sqrt(18.0)
#: no static bed of grains under gravity is this loose: random loose packing of frictional
#: spheres is 0.45 (solid fraction 0.555, Onoda & Liniger 1990, Phys. Rev. Lett. 64:2727) and
#: the loosest measured bulk porosity in the grain library is 0.4834 (barley)
LOOSEST_POROSITY = 0.6
_DATA = Path(__file__).resolve().parents[1] / "data"


def check_physical_porosity(porosity, what: str = "--porosity") -> None:
    """ValueError unless KEPLER_POROSITY < ``porosity`` < LOOSEST_POROSITY, naming ``what``.

    >>> check_physical_porosity(0.9)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: --porosity 0.9: no static bed of grains is that loose (loosest taken: 0.6; ...
    """
    if not (isinstance(porosity, (int, float)) and math.isfinite(porosity)):
        raise ValueError(f"{what} must be a number in (0, 1), got {porosity!r}")
    if porosity <= KEPLER_POROSITY:
        raise ValueError(f"{what} {porosity:g}: no packing of grains is that dense (the densest "
                         f"packing of equal spheres has {KEPLER_POROSITY:.4f})")
    if porosity >= LOOSEST_POROSITY:
        raise ValueError(f"{what} {porosity:g}: no static bed of grains is that loose (loosest "
                         f"taken: {LOOSEST_POROSITY:g}; random loose packing of frictional "
                         "spheres is 0.45)")


def _same_container(a, b) -> bool:
    if not (isinstance(a, dict) and isinstance(b, dict)) or a.get("kind") != b.get("kind"):
        return False
    keys = ("size_m", "fill_height_m", "radius_m", "height_m")
    try:
        for k in keys:
            va, vb = a.get(k), b.get(k)
            if (va is None) != (vb is None):
                return False
            if va is not None and not all(abs(float(x) - float(y)) <= 1e-9 for x, y in
                                          zip(_list(va), _list(vb), strict=True)):
                return False
    except (TypeError, ValueError):
        return False
    return True


def _list(v):
    return list(v) if isinstance(v, (list, tuple)) else [v]


def recorded_reach(grain: str, container: dict | None = None, seed=None) -> dict | None:
    """The recorded reachable range of ``grain`` (a template name) in ``container`` (a
    ``Container.to_dict()``; None: any) with ``seed`` (None: any), or None.

    Returns a dict: ``range`` (low, high porosity of the beds the search made), ``tol`` (its
    tolerance), ``container``, ``seed``, ``source`` (the file that records it), ``beds`` (the
    search's beds: lever, porosity, ...) and ``n_grains`` (their grain count).

    >>> r = recorded_reach("soybean"); [round(v, 4) for v in r["range"]], r["tol"]
    ([0.349, 0.4114], 0.005)
    """
    for path in sorted(_DATA.glob("*_grains.json")):
        try:
            meta = json.loads(path.read_text())
            search = meta["porosity_search"]
            lo, hi = (float(v) for v in search["reachable"])
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if meta.get("template") != grain:
            continue
        if container is not None and not _same_container(meta.get("container"), container):
            continue
        if seed is not None and meta.get("seed") != seed:
            continue
        beds = [{"converged": True, **b} for b in search.get("range_beds", search.get("tried", []))]
        return {"range": (min(lo, hi), max(lo, hi)), "tol": float(search.get("tol", 0.0)),
                "container": meta.get("container"), "seed": meta.get("seed"),
                "source": f"network/data/{path.name}", "beds": beds,
                "n_grains": meta.get("n_grains")}
    return None


def reach_text(record: dict) -> str:
    """The range as every command quotes it: ``0.3490-0.4114 (...)``, naming the container, the
    seed, how the beds were made (``how``, where given) and the file that keeps them.

    >>> reach_text(recorded_reach("soybean"))  # doctest: +ELLIPSIS
    '0.3490-0.4114 (the beds dem.pack --porosity made in the 0.05 x 0.05 x 0.05 m box, seed 1, ...'
    """
    lo, hi = record["range"]
    c = record.get("container") or {}
    where = ""
    try:
        if c.get("kind") == "box":
            where = " in the " + " x ".join(f"{v:g}" for v in [*c["size_m"], c["fill_height_m"]]) \
                + " m box"
        elif c.get("kind") == "cylinder":
            where = (f" in the {_list(c['size_m'])[0]:g} m wide, {c['fill_height_m']:g} m high "
                     "cylinder")
    except (KeyError, TypeError, ValueError):
        where = ""
    seed = "" if record.get("seed") is None else f", seed {record['seed']}"
    how = f", {record['how']}" if record.get("how") else ""
    return (f"{lo:.4f}-{hi:.4f} (the beds dem.pack --porosity made{where}{seed}{how}, "
            f"{record['source']}; a request within its {record['tol']:g} tolerance is taken)")


def reach_refusal(porosity: float, grain: str, record: dict, what: str = "--porosity") -> str:
    """The one message of a porosity outside ``record``'s range (widened by its tolerance).

    >>> reach_refusal(0.45, "soybean", recorded_reach("soybean"))  # doctest: +ELLIPSIS
    '--porosity 0.45 is outside what dem.pack reaches for soybean in this container: 0.3490-...'
    """
    return (f"{what} {porosity:g} is outside what dem.pack reaches for {grain} in this container: "
            f"{reach_text(record)}")
