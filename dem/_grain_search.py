r"""The porosity search of the grown fill: a bed of grains at a requested porosity.

``dem.pack --grain G --fill grow --porosity P`` moves the packing procedure's lever λ
(:func:`dem._clump_pack.procedure_lever`) until a bed lands within the tolerance of P in
network's sample region. The range comes first (:func:`grain_reach`: the beds at λ = -1, 0, +1
with the grain's own count, measured once per template, container and seed and kept,
:mod:`dem._reach`), so a request outside it is refused at once with that one range, and the
search inside starts from those beds (:func:`pack_grains_to_porosity`). Beds are made by
:func:`dem._clump_pack.pack_grains`, looked up on that module at each call.
"""

from __future__ import annotations

import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from network.core import KEPLER_POROSITY, LOOSEST_POROSITY, reach_refusal, reach_text

from . import _clump_pack
from ._clump_pack import grain_number, procedure_lever
from ._reach import (COUNT_POROSITY_DEFAULT, RANGE_LEVERS, count_porosity, load_reach, reach_dir,
                     reach_key, store_reach)

#: settle step limit of the range's beds, at least (``max_steps`` when larger): the range is the
#: same whatever step limit a request gives (shelled corn's 0.08 m cube settled after 119 400
#: steps; wheat's closed box in its 0.032 x 0.032 x 0.04 m box is not settled after 60 000)
RANGE_MAX_STEPS = 240_000

__all__ = ["grain_count", "grain_reach", "pack_grains_to_porosity"]


def grain_count(container, template, *, size_cv=0.0, n_grains=None):
    r"""(N, φ_c, where φ_c comes from) of the porosity search: ``n_grains`` when given, else
    :math:`N = \lfloor (1 - φ_c) V / (V_t \overline{f^3}) \rfloor` with φ_c the grain's
    (:func:`dem._reach.count_porosity`), whatever porosity is requested."""
    phi_c, why = count_porosity(template.name)
    if n_grains is not None:
        return int(n_grains), phi_c, "--n-grains"
    return grain_number(container, template, phi_c, size_cv), phi_c, why


def _bed_point(lam, s, stage):
    head, mu = procedure_lever(lam)
    settle = s.get("stages", {}).get("settle", {})
    return {"stage": stage, "lever": float(lam), "lid_headroom": head, "deposition_friction": mu,
            "porosity": float(s["porosity_network_region"]),
            "porosity_error": float(s["porosity_network_region_error"]),
            "converged": bool(settle.get("converged", True)), "settle_steps": int(settle.get("steps", 0)),
            "wall_time_s": float(s["wall_time_s"])}


def _levers_text(levers):
    return ", ".join(f"{v:+g}" if v else "0" for v in levers)


def grain_reach(container, template, *, on_packing=None, workers=1, **kwargs):
    r"""The porosities the grown fill reaches for ``template`` in ``container``: the beds at
    :data:`dem._reach.RANGE_LEVERS`, packed with the grain's own count (:func:`grain_count`),
    read from the cache (:func:`dem._reach.load_reach`) when an integer seed (``rng``) made them
    before, else packed now (``workers=2``: two processes; settle steps up to
    :data:`RANGE_MAX_STEPS` or ``max_steps``, the larger) and kept there.

    ``kwargs`` are :func:`pack_grains`'s (not ``porosity``, ``deposition_friction``,
    ``lid_headroom``). Returns a record for :func:`network.core.reach_text`: ``range`` (low,
    high porosity in network's sample region), ``beds`` (one dict per lever), ``n_grains``,
    ``count_porosity``, ``container``, ``seed``, ``how``, ``source`` (the cache file),
    ``cached``, ``packed`` (the beds packed now, by lever: the search takes one of them as it
    is) and ``measure_seconds`` (the packings' wall time now, 0 when read).
    """
    kwargs = dict(kwargs)
    n, phi_c, why = grain_count(container, template, size_cv=kwargs.get("size_cv", 0.0),
                                n_grains=kwargs.pop("n_grains", None))
    seed = kwargs.get("rng")
    max_steps = max(int(kwargs.get("max_steps", _clump_pack.PACK_MAX_STEPS)), RANGE_MAX_STEPS)
    path, what, entry = None, None, None
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        settings = {k: v for k, v in kwargs.items() if k not in ("rng", "max_steps", "progress")}
        if "material" in settings:
            m = settings["material"]
            settings["material"] = {k: getattr(m, k) for k in m.__dataclass_fields__}
        name, what = reach_key(container, template, seed=int(seed), n_grains=n, settings=settings)
        path = reach_dir() / name
        entry = load_reach(path, max_steps)
    cached = entry is not None
    t0 = time.perf_counter()
    outs = {}
    if entry is None:
        kw = {**kwargs, "porosity": phi_c, "n_grains": n, "max_steps": max_steps}
        if workers > 1:
            with ProcessPoolExecutor(2) as ex:
                jobs = {lam: ex.submit(_pack_at, lam, container, template, {**kw, "progress": None})
                        for lam in RANGE_LEVERS}
                outs = {lam: job.result() for lam, job in jobs.items()}
        else:
            outs = {lam: _pack_at(lam, container, template, kw) for lam in RANGE_LEVERS}
        beds = [_bed_point(lam, outs[lam][4], "range") for lam in RANGE_LEVERS]
        made = [b["porosity"] for b in beds]
        entry = {"key": what, "range": [min(made), max(made)], "beds": beds, "n_grains": n,
                 "count_porosity": phi_c, "count_porosity_source": why, "max_steps": max_steps,
                 "wall_time_s": time.perf_counter() - t0}
        note = "not cached: no integer seed" if path is None else store_reach(path, entry)
    else:
        beds, note = entry["beds"], None
    for b in beds:
        if on_packing is not None:
            on_packing({**b, "cached": cached})
    unsettled = [b["lever"] for b in beds if not b["converged"]]
    how = f"{n} grains at levers {_levers_text(RANGE_LEVERS)}" + (
        f" (lever {_levers_text(unsettled)} not at equilibrium after {entry['max_steps']} settle "
        "steps)" if unsettled else "")
    return {"range": tuple(float(v) for v in entry["range"]), "beds": beds, "n_grains": n,
            "count_porosity": phi_c, "container": container.to_dict(),
            "seed": None if path is None else int(seed), "how": how, "max_steps": entry["max_steps"],
            "source": note or str(path), "cached": cached, "packed": outs,
            "measure_seconds": 0.0 if cached else time.perf_counter() - t0}


def _pack_at(lam, container, template, kw):
    """:func:`dem._clump_pack.pack_grains` at lever ``lam`` (its headroom and friction)."""
    head, mu = procedure_lever(lam)
    return _clump_pack.pack_grains(container, template, lid_headroom=head, deposition_friction=mu, **kw)


def _next_lever(points, target, tol, packed, history):
    """The next lever of the search: a known bed within ``tol`` not packed by this search yet
    (the same seed makes the same bed), else inside the tightest bracket of the known beds
    (sorted by lever, porosities on both sides of ``target``), by regula falsi kept 20 % of the
    bracket inside its ends, by bisection after two beds on the same side; None: no bracket."""
    close = [p for p in points if abs(p["porosity"] - target) <= tol and p["converged"]
             and not any(abs(p["lever"] - q) < 1e-9 for q in packed)]
    if close:
        return min(close, key=lambda p: abs(p["porosity"] - target))["lever"]
    pts = sorted(points, key=lambda p: p["lever"])
    pairs = [(a, b) for a, b in zip(pts, pts[1:])
             if (a["porosity"] - target) * (b["porosity"] - target) < 0 and b["lever"] > a["lever"]]
    if not pairs:
        return None
    a, b = min(pairs, key=lambda ab: ab[1]["lever"] - ab[0]["lever"])
    (la, ea), (lb, eb) = (a["lever"], a["porosity"]), (b["lever"], b["porosity"])
    w = lb - la
    if len(history) >= 2 and (history[-1] - target) * (history[-2] - target) > 0:
        lam = 0.5 * (la + lb)
    else:
        lam = float(np.clip(la + (target - ea) * w / (eb - ea), la + 0.2 * w, lb - 0.2 * w))
    while any(abs(lam - q) < 1e-9 for q in packed):    # the same bed again: step aside
        lam += 0.05 * w
    return float(lam)


def pack_grains_to_porosity(container, template, *, porosity, porosity_tol=0.005, max_packings=6,
                            on_packing=None, workers=1, reach=None, **kwargs):
    r"""A packing whose porosity in network's region (``porosity_network_region``) is within
    ``porosity_tol`` of ``porosity``, reached by the packing procedure's lever λ (:func:`procedure_lever`).

    The range comes first: ``reach`` (a recorded range with its ``beds`` and ``n_grains``, the
    bundled beds') or :func:`grain_reach` (the beds at λ = -1, 0, +1, cached); a request more
    than ``porosity_tol`` outside it is a ValueError quoting it (:func:`network.core.reach_text`;
    also when a range bed leaves network's region empty: a bed too thin), before any other
    packing. Inside, the search packs (at most ``max_packings`` beds, the range's not counted)
    until a bed at equilibrium lands within ``porosity_tol``: a range bed within it again, else
    regula falsi on φ(λ) in the tightest bracket of the beds known (:func:`_next_lever`); then
    RuntimeError naming the closest. Every bed has the range's grain count. ``on_packing(dict)``
    is called for each bed (range beds with ``stage`` 'range' and ``cached``). Returns what
    :func:`pack_grains` returns; the summary gains ``porosity_search``: target, tol,
    ``reachable`` (the range), ``reachable_text`` (as quoted), ``reachable_how``,
    ``reachable_source`` (the file that keeps it), ``range_beds``, ``n_grains``,
    ``grain_count_porosity``, ``tried`` (the search's own beds).
    """
    if not (np.isfinite(porosity) and 0 < porosity < 1):
        raise ValueError(f"porosity must be in (0, 1), got {porosity!r}")
    tol = porosity_tol
    if not (np.isfinite(tol) and tol > 0):
        raise ValueError(f"porosity tolerance must be > 0, got {tol!r}")
    if int(max_packings) < 1:
        raise ValueError(f"the search packs at least one bed: max packings >= 1, got {max_packings!r}")
    if reach is None:
        reach = grain_reach(container, template, on_packing=on_packing, workers=workers, **kwargs)
    reach = {**reach, "tol": float(tol)}
    made = [b["porosity"] for b in reach["beds"]]
    if not all(np.isfinite(made)):
        levers = ", ".join(f"{e:.4f} at lever {_levers_text([b['lever']])}"
                           for e, b in zip(made, reach["beds"]))
        raise ValueError(f"network's sample region (1.5 grain diameters inside the bed on every "
                         f"side) is empty in the {template.name} beds this container holds "
                         f"(porosity {levers}): give a larger container or more grains")
    wild = [(e, b["lever"]) for e, b in zip(made, reach["beds"])
            if not KEPLER_POROSITY < e < LOOSEST_POROSITY]
    if wild:
        raise ValueError(f"the {template.name} bed at lever {_levers_text([wild[0][1]])} has porosity "
                         f"{wild[0][0]:.4f} in network's sample region, which no static bed has: "
                         f"its {reach['n_grains']} grains do not fit this container (a grain count "
                         "this container holds: --n-grains, or a larger container)")
    lo, hi = reach["range"]
    if not (lo - tol <= porosity <= hi + tol):
        raise ValueError(reach_refusal(porosity, template.name, reach, what="porosity"))
    kw = {k: v for k, v in kwargs.items() if k != "n_grains"}
    kw.update(porosity=float(reach.get("count_porosity") or COUNT_POROSITY_DEFAULT),
              n_grains=int(reach["n_grains"]))
    tried, outs, history = [], [], []

    def rank(o):  # a bed at equilibrium within tol first, then the closest
        s = o[4]
        settled = s.get("stages", {}).get("settle", {}).get("converged", True)
        miss = abs(s["porosity_network_region"] - porosity)
        return (miss > tol or not settled, miss)

    while len(tried) < int(max_packings) and not (outs and not rank(min(outs, key=rank))[0]):
        mine = {t["lever"] for t in tried}
        known = tried + [b for b in reach["beds"] if b["lever"] not in mine]
        lam = _next_lever(known, porosity, tol, [t["lever"] for t in tried], history)
        if lam is None:
            break
        again = reach.get("max_steps") if any(lam == b["lever"] for b in reach["beds"]) else None
        out = reach.get("packed", {}).get(lam) or _pack_at(     # a range bed: as the range made it
            lam, container, template, kw if again is None else {**kw, "max_steps": again})
        out[4]["procedure_lever"] = float(lam)
        tried.append(_bed_point(lam, out[4], "search"))
        history.append(tried[-1]["porosity"])
        outs.append(out)
        if on_packing is not None:
            on_packing(tried[-1])
    steps = [(round(t["lever"], 3), round(t["porosity"], 4)) for t in tried]
    if not outs:
        raise RuntimeError(f"no bed at equilibrium within {tol:g} of porosity {porosity:g} to "
                           f"pack in the range {reach_text(reach)}")
    best = min(outs, key=rank)
    best[4]["porosity_search"] = {
        "target": float(porosity), "tol": float(tol), "reachable": [float(lo), float(hi)],
        "reachable_text": reach_text(reach), "reachable_how": reach.get("how"),
        "reachable_source": reach["source"], "range_beds": reach["beds"],
        "n_grains": int(reach["n_grains"]),
        "grain_count_porosity": reach.get("count_porosity"), "tried": tried,
        "lever": "lambda in [-1, 0]: lid headroom 0.3 (1 + lambda), frictionless growth; "
                 "[0, 1]: deposition friction lambda (porosity in network's sample region)"}
    if rank(best)[0]:
        got = best[4]["porosity_network_region"]
        raise RuntimeError(f"no packing at equilibrium within {tol:g} of porosity {porosity:g} "
                           f"after {len(tried)} packings (closest {got:.4f}; lever, porosity: "
                           f"{steps}; the range {lo:.4f}-{hi:.4f} from levers "
                           f"{_levers_text(b['lever'] for b in reach['beds'])})")
    return best
