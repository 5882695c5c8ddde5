r"""The bin side of ``network.report``: system curve, airflow units, fan file, operating point.

A bed of depth H on a floor of area A at superficial velocity U passes the airflow Q = U A
(m³/s) against the static pressure P = H ΔP/L(U) (Pa, the grain only: no floor, duct or
spreader losses). Engineers give airflow per tonne of grain,

.. math:: q_t = \frac{60\,Q}{\rho_b A H / 1000}\ \mathrm{m^3/(min\,t)}, \qquad
          \rho_b = \rho_p (1 - \varepsilon),

with ρ_p the kernel (particle) density and ε the porosity, so U = q_t ρ_b H / 60 000 does not
depend on the floor area. The fan's operating point is where the fan curve (CSV
``airflow_m3_s,static_pressure_pa``) crosses the system curve: :func:`operating_point` brackets
the sign change of fan - system over their common airflow range and interpolates linearly
(exact for two piecewise-linear curves; the CLI hands it the system curve at 400 points,
log-log interpolated between the solved velocities).
"""

from __future__ import annotations

import logging
import math

import numpy as np

from ..core import read_table

__all__ = ["AIRFLOW_UNITS", "FAN_COLUMNS", "M3_MIN_M3_PER_CFM_BU", "airflow_unit", "bulk_density",
           "parse_airflow",
           "check_fan_shape", "floor_area", "velocity_from_airflow", "system_rows",
           "dense_system", "read_fan", "operating_point", "curve_range"]

#: units accepted by ``--airflow VALUE UNIT`` (any case): superficial velocity, airflow per
#: tonne of grain, per cubic metre of grain, and the US cubic feet per minute per bushel
AIRFLOW_UNITS = ("m/s", "m3/min/t", "m3/min/m3", "cfm/bu")
log = logging.getLogger(__name__)
#: 1 ft^3 (0.3048^3 m^3) per US bushel (2150.42 in^3 = 0.03523907 m^3): 1 cfm/bu is
#: 0.8035640 m^3/(min m^3) of grain
M3_MIN_M3_PER_CFM_BU = 0.3048**3 / 0.03523907
_UNIT_SPELLINGS = {"m3/(mint)": "m3/min/t", "m3/(minm3)": "m3/min/m3", "cfm/bushel": "cfm/bu",
                   "ft3/min/bu": "cfm/bu"}


def airflow_unit(text: str) -> str:
    """The unit of ``--airflow`` as :data:`AIRFLOW_UNITS` spells it: any case, spaces and
    ``^`` ignored (``M/S``, ``m^3/(min t)``); ValueError naming the accepted ones.

    >>> airflow_unit("M/S"), airflow_unit("m^3/(min t)"), airflow_unit("CFM/bu")
    ('m/s', 'm3/min/t', 'cfm/bu')
    """
    key = "".join(str(text).lower().split()).replace("^", "")
    key = _UNIT_SPELLINGS.get(key, key)
    if key not in AIRFLOW_UNITS:
        raise ValueError(f"--airflow unit {text!r}: use one of {', '.join(AIRFLOW_UNITS)} "
                         "(any case)")
    return key


def parse_airflow(value: str, unit: str) -> tuple[float, str]:
    """``--airflow VALUE UNIT`` as (a finite airflow > 0, the unit as :func:`airflow_unit` spells
    it); ValueError naming the option and what is wrong.

    >>> parse_airflow("0.1", "M3/MIN/T")
    (0.1, 'm3/min/t')
    """
    unit = airflow_unit(unit)
    try:
        airflow = float(value)
    except ValueError:
        raise ValueError(f"--airflow value {value!r} is not a number") from None
    if not (np.isfinite(airflow) and airflow > 0):
        raise ValueError(f"--airflow must be finite and > 0, got {value}")
    return airflow, unit


FAN_COLUMNS = ("airflow_m3_s", "static_pressure_pa")


def bulk_density(particle_density_kg_m3: float, porosity: float) -> float:
    """ρ_b = ρ_p (1 - ε), kg/m³.

    >>> round(bulk_density(1285.0, 0.4), 6)
    771.0
    """
    return float(particle_density_kg_m3) * (1.0 - float(porosity))


def floor_area(diameter_m=None, area_m2=None) -> float:
    """Floor area, m²: π D²/4 of a round bin, or the area given (1 m² when neither is)."""
    if diameter_m is not None and area_m2 is not None:
        raise ValueError("give --diameter (round bin) or --floor-area, not both")
    if diameter_m is not None:
        return math.pi * float(diameter_m) ** 2 / 4.0
    return 1.0 if area_m2 is None else float(area_m2)


def velocity_from_airflow(value: float, unit: str, *, depth_m: float,
                          bulk_density_kg_m3: float) -> float:
    r"""Superficial velocity U, m/s, of an airflow in one of :data:`AIRFLOW_UNITS`.

    Per tonne, :math:`U = q_t \rho_b H / 60\,000`; per cubic metre of grain,
    :math:`U = q_v H / 60`; ``cfm/bu`` is :math:`q_v` / 0.8035640 (1 ft³/min per US bushel of
    0.03523907 m³). H is the depth (m), ρ_b the bulk density (kg/m³).

    >>> round(velocity_from_airflow(0.1, "m3/min/t", depth_m=3.0, bulk_density_kg_m3=771.0), 8)
    0.003855
    >>> round(velocity_from_airflow(1.0, "cfm/bu", depth_m=3.0, bulk_density_kg_m3=771.0), 8)
    0.0401782
    """
    unit = airflow_unit(unit)
    if unit == "m/s":
        return float(value)
    if unit == "m3/min/t":
        return float(value) * bulk_density_kg_m3 * depth_m / 60_000.0
    per_m3 = float(value) * (M3_MIN_M3_PER_CFM_BU if unit == "cfm/bu" else 1.0)
    return per_m3 * depth_m / 60.0


def system_rows(velocity_m_s, gradient_pa_per_m, *, depth_m, area_m2,
                bulk_density_kg_m3) -> list[dict]:
    """One row per velocity: U, Q, Q per tonne and per m³ of grain, static pressure."""
    mass_t = bulk_density_kg_m3 * area_m2 * depth_m / 1000.0
    rows = []
    for u, g in zip(velocity_m_s, gradient_pa_per_m):
        q = float(u) * area_m2
        rows.append({"velocity_m_s": float(u), "airflow_m3_s": q,
                     "airflow_m3_min_t": 60.0 * q / mass_t,
                     "airflow_m3_min_m3": 60.0 * q / (area_m2 * depth_m),
                     "static_pressure_pa": float(g) * depth_m})
    return rows


def dense_system(velocity_m_s, gradient_pa_per_m, *, depth_m, area_m2, n=400):
    """(Q (n,), P (n,)) of the system curve between the solved velocities, log-log
    interpolated (a power law between neighbouring points)."""
    lu = np.log(np.asarray(velocity_m_s, dtype=float))
    lg = np.log(np.asarray(gradient_pa_per_m, dtype=float))
    uu = np.geomspace(np.exp(lu.min()), np.exp(lu.max()), n)
    return uu * area_m2, np.exp(np.interp(np.log(uu), lu, lg)) * depth_m


def read_fan(path) -> tuple[np.ndarray, np.ndarray]:
    """Fan curve (airflow m³/s, static pressure Pa), sorted by airflow, from a CSV with the
    header ``airflow_m3_s,static_pressure_pa`` (any column order, extra columns ignored; read as
    spreadsheets write it: :func:`network.core.read_table`). ValueError naming ``--fan``, the
    file and the row of a missing, non-numeric, negative or repeated value; at least two
    rows."""
    header, table = read_table(path, "--fan", what="a fan curve")
    names = [h.lower() for h in header]
    missing = [c for c in FAN_COLUMNS if c not in names]
    if missing:
        raise ValueError(f"--fan {path}: missing column(s) {', '.join(missing)} (header "
                         f"{','.join(FAN_COLUMNS)}: airflow m^3/s, static pressure Pa; got "
                         f"{','.join(header)})")
    cols = [names.index(c) for c in FAN_COLUMNS]
    rows = []
    for i, fields in table:
        if len(fields) != len(names):
            raise ValueError(f"--fan {path} row {i}: {len(fields)} values, the header has "
                             f"{len(names)}")
        vals = []
        for c, k in zip(FAN_COLUMNS, cols):
            text = fields[k]
            try:
                v = float(text)
            except ValueError:
                raise ValueError(f"--fan {path} row {i}: {c} {text!r} is not a number") from None
            if not math.isfinite(v) or v < 0:
                raise ValueError(f"--fan {path} row {i}: {c} must be finite and >= 0, "
                                 f"got {text}")
            vals.append(v)
        rows.append(vals)
    if len(rows) < 2:
        raise ValueError(f"--fan {path}: needs at least two rows, got {len(rows)}")
    a = np.array(sorted(rows))
    twice = np.flatnonzero(np.diff(a[:, 0]) == 0)
    if twice.size:
        raise ValueError(f"--fan {path}: airflow {a[twice[0], 0]:g} m^3/s appears twice")
    check_fan_shape(a[:, 0], a[:, 1], f"--fan {path}")
    return a[:, 0], a[:, 1]


def check_fan_shape(airflow_m3_s, pressure_pa, where: str = "the fan curve") -> None:
    """A fan's static pressure falls as its airflow rises. ValueError where it never falls
    (a system curve, or a curve whose columns are swapped); one logged warning where it rises
    over part of the range (a stall hump: the operating point is sought where it falls) or
    where the airflows exceed the pressures (m^3/s above Pa: swapped columns?).

    >>> check_fan_shape([0.0, 1.0, 2.0], [0.0, 100.0, 400.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: the fan curve: static pressure rises with airflow (0 Pa at 0 m^3/s to 400 ...
    """
    q, p = np.asarray(airflow_m3_s, float), np.asarray(pressure_pa, float)
    dp = np.diff(p)
    if not np.any(dp < 0):
        raise ValueError(f"{where}: static pressure rises with airflow ({p[0]:g} Pa at "
                         f"{q[0]:g} m^3/s to {p[-1]:g} Pa at {q[-1]:g} m^3/s) and never falls: "
                         "that is a system curve, not a fan's (columns "
                         f"{','.join(FAN_COLUMNS)}; a fan delivers less air against more "
                         "pressure)")
    up = np.flatnonzero(dp > 0)
    if up.size:
        log.warning("%s: static pressure rises with airflow between %g and %g m^3/s (a stall "
                    "region?); the operating point is sought where it falls", where,
                    q[up[0]], q[up[-1] + 1])
    if q.max() > p.max():
        log.warning("%s: airflows up to %g m^3/s exceed the pressures (at most %g Pa): are "
                    "the columns swapped? (%s)", where, q.max(), p.max(),
                    ",".join(FAN_COLUMNS))


def operating_point(system_q, system_p, fan_q, fan_p):
    """Lowest airflow where the fan curve crosses the system curve: (Q m³/s, P Pa), or None
    when they do not cross over their common airflow range. Both curves are piecewise linear
    through their points (Q ascending).

    >>> operating_point([0, 1, 2], [0, 100, 400], [0, 2], [300, 100])
    (1.25, 175.0)
    >>> operating_point([0, 1], [0, 100], [0, 1], [300, 200]) is None
    True
    """
    sq, sp = np.asarray(system_q, float), np.asarray(system_p, float)
    fq, fp = np.asarray(fan_q, float), np.asarray(fan_p, float)
    lo, hi = max(sq[0], fq[0]), min(sq[-1], fq[-1])
    if lo > hi:
        return None
    q = np.unique(np.concatenate([[lo, hi], sq[(sq > lo) & (sq < hi)], fq[(fq > lo) & (fq < hi)]]))
    d = np.interp(q, fq, fp) - np.interp(q, sq, sp)
    hit = np.flatnonzero(d == 0)
    cross = np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)
    cands = sorted(set(hit.tolist()) | set(cross.tolist()))
    if not cands:
        return None
    i = cands[0]
    if d[i] == 0:
        qx = q[i]
    else:
        qx = q[i] - d[i] * (q[i + 1] - q[i]) / (d[i + 1] - d[i])
    return float(qx), float(np.interp(qx, sq, sp))


def curve_range(name: str, q, p) -> str:
    """``name: airflow a-b m^3/s, static pressure c-d Pa`` for the no-crossing message."""
    q, p = np.asarray(q, float), np.asarray(p, float)
    return (f"{name}: airflow {q.min():.4g}-{q.max():.4g} m^3/s, static pressure "
            f"{p.min():.4g}-{p.max():.4g} Pa")
