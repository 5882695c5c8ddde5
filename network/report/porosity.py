r"""The porosity of ``network.report``: which one, why, and how the prediction gets there.

A report is for one porosity ε, chosen in this order and named in
``porosity_source``: the user's ``--porosity``; else the grain's measured loose-fill bulk
porosity (the middle of the range in :data:`network._grains.BED`, the condition D272's data were
taken in); else, for a grain without one, the packing's own. The network is solved on a packing
of porosity :math:`\varepsilon_p` (its interior Monte-Carlo porosity); the prediction is moved to ε
along the porosity band's computed slope S(U) (:mod:`network.report.band`), not by packing anew:

.. math:: g(U; \varepsilon) = g(U; \varepsilon_p)\,
   \exp\!\big(S(U)\,(\varepsilon - \varepsilon_p)\big), \qquad
   \sigma_{\ln g} = |\varepsilon - \varepsilon_p|\,\sigma_S

(g in Pa/m; σ_S the slope's standard error). The porosities a packing of the grain can reach
are those its companion JSON records (``porosity_search.reachable`` of ``dem.pack --porosity``,
the beds its search made, within its tolerance: one range per grain and container, quoted the
same everywhere, :func:`network.core.reach_text`); a packing without that record accepts ε
within ``MAX_SHIFT`` of its own (the band's span). A porosity no bed of grains has is refused
at once (:func:`network.core.check_physical_porosity`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .._grains import BED
from ..core import check_physical_porosity, reach_text

__all__ = ["DATA_DIR", "MAX_SHIFT", "UnreachablePorosity", "bundled_packing", "bundled_grains",
           "packing_meta", "requested_porosity", "reach_record", "check_reachable",
           "shift_factor"]

DATA_DIR = Path(__file__).resolve().parents[1] / "data"
#: largest move along the band without a recorded reachable range (the band's span), porosity
MAX_SHIFT = 0.02


def bundled_packing(grain: str) -> Path | None:
    """The shipped packing of a grain, else None: ``network/data/<grain>_grains.csv`` (rigid
    multi-sphere grains made by ``dem.pack --grain``, network/data/README.md), else
    ``<grain>_default.csv`` (spheres), else ``<grain>_rain_0kPa.csv`` (the poured surface bed of
    the grain's bin bed set, :mod:`network.report.binbeds`)."""
    for name in (f"{grain}_grains.csv", f"{grain}_default.csv", f"{grain}_rain_0kPa.csv"):
        p = DATA_DIR / name
        if p.is_file():
            return p
    return None


def bundled_grains() -> list[str]:
    """The grains with a bundled packing."""
    return [g for g in BED if bundled_packing(g) is not None]


def packing_meta(path) -> dict:
    """The companion JSON of a packing (same stem, ``.json``) as a dict; {} if none or not JSON."""
    p = Path(path).with_suffix(".json")
    try:
        meta = json.loads(p.read_text())
    except (OSError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}


def requested_porosity(grain: str, porosity: float | None) -> tuple[float | None, str]:
    """(ε or None, why): ``--porosity``, else the grain's measured loose-fill porosity, else None
    (the packing's own, known only after the solve).

    >>> requested_porosity("wheat", None)[0], requested_porosity("canola", None)[0]
    (0.402, None)
    """
    if porosity is not None:
        if not (np.isfinite(porosity) and 0 < porosity < 1):
            raise ValueError(f"--porosity must be in (0, 1), got {porosity!r}")
        check_physical_porosity(porosity)
        return float(porosity), "--porosity (the user's)"
    bed = BED[grain]
    if bed.loose_fill_porosity is not None:
        lo, hi = bed.bulk_porosity
        why = (f"the grain's measured loose-fill bulk porosity, middle of {lo:g}-{hi:g} "
               f"({bed.bulk_porosity_source})")
        return bed.loose_fill_porosity, why
    return None, f"the packing's own (no measured loose-fill porosity for {grain})"


def reach_record(meta: dict, source) -> dict | None:
    """The range a packing of the grain reaches, from its companion JSON (``porosity_search`` of
    ``dem.pack --porosity``: the range it searched in, where it is kept, and its tolerance), as
    :func:`network.core.recorded_reach` gives it, quoted as dem.pack quoted it; None without
    that record.

    >>> r = reach_record({"porosity_search": {"reachable": [0.35, 0.41], "tol": 0.005}}, "b.json")
    >>> r["range"], r["tol"]
    ((0.35, 0.41), 0.005)
    """
    s = meta.get("porosity_search", {}) if isinstance(meta, dict) else {}
    r = s.get("reachable") if isinstance(s, dict) else None
    if not isinstance(r, (list, tuple)) or len(r) != 2:
        return None
    try:
        lo, hi = sorted(float(v) for v in r)
        tol = float(s.get("tol", 0.0))
    except (TypeError, ValueError):
        return None
    src = Path(source)
    if src.resolve().parent == DATA_DIR:        # a bundled bed: named as every command names it
        src = Path("network/data") / src.name
    return {"range": (lo, hi), "tol": tol, "container": meta.get("container"),
            "seed": meta.get("seed"), "how": s.get("reachable_how"),
            "source": str(s.get("reachable_source") or src)}


class UnreachablePorosity(ValueError):
    """A porosity outside the range a packing of the grain reaches: bad input (exit 2)."""

    bad_input = True


def check_reachable(porosity: float, own: float | None, reach, grain: str) -> None:
    """:class:`UnreachablePorosity` unless ``porosity`` lies in the recorded range ``reach`` (a
    :func:`reach_record`) widened by its tolerance, or, without one, within MAX_SHIFT of the
    packing's ``own`` porosity; the message quotes the range as every command does
    (:func:`network.core.reach_text`).

    >>> rec = {"range": (0.37, 0.43), "tol": 0.005, "source": "bed.json"}
    >>> check_reachable(0.45, None, rec, "wheat")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    network.report.porosity.UnreachablePorosity: porosity 0.45 is outside the range ...
    """
    if reach is not None:
        lo, hi = reach["range"]
        lo, hi = lo - reach["tol"], hi + reach["tol"]
        how = reach_text(reach)
    elif own is not None:
        lo, hi = own - MAX_SHIFT, own + MAX_SHIFT
        how = (f"{lo:.4f}-{hi:.4f}: the packing's own {own:.4f} +- {MAX_SHIFT} along the band; "
               "no recorded range")
    else:
        return
    if not lo - 1e-12 <= porosity <= hi + 1e-12:
        raise UnreachablePorosity(f"porosity {porosity:g} is outside the range a packing of "
                                  f"{grain} reaches: {how}")


def shift_factor(slope: float, slope_stderr: float, d_porosity: float) -> tuple[float, float]:
    r"""(exp(S Δε), σ of its logarithm |Δε| σ_S): the factor that moves g to ε_p + Δε.

    >>> f, s = shift_factor(-12.0, 1.0, 0.01); round(f, 6), round(s, 6)
    (0.88692, 0.01)
    """
    return float(np.exp(slope * d_porosity)), float(abs(d_porosity) * slope_stderr)
