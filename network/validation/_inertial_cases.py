r"""Inertial validation cases: the resistance curve of a known packing against the drag laws.

Each case builds a packing, runs the inertial pipeline (:func:`solve_sample_curve`: the steps
of :func:`network.solve_network` with ``inertia=True``, conduit model, stages timed) at
viscosity 1 and density 1 with the superficial velocities :math:`U = Re/d`, so that
:math:`Re_p = \rho U d/\mu` is the requested Reynolds number, and returns an
:class:`InertialCase`: the network's :math:`k/k_{app}` (pressure gradient over its Darcy value,
k the sample's Stokes permeability) beside the laws'
:math:`F(\phi, Re)/F(\phi, 0)` (:mod:`._drag_laws`).

The conduit law is the window law of :func:`network.conductance.conduit_law`; a case's
``table`` (default :data:`network.conductance.CHAIN_WINDOW_TABLE`) gives its constants per
window ratio, so a comparison may solve the same form with other measured constants (a one-row
table holds one pair for every conduit).

* :func:`random_inertial_case`: periodic random packing (:func:`network.random_packing`),
  copied 3 x 3 x 3, the middle two periods as the sample, as
  :func:`random_sample_permeability` does;
* :func:`finney_inertial_case`: a cube from the centre of Finney's (1970) measured random dense
  packing (``shared/data/finney`` beside the checkout, packing fraction about 0.636);
* :func:`bed_inertial_case`: the interior box of a settled bed of our own DEM packer
  (``dem.pack``: gravity, walls, friction), flow vertical or horizontal;
* :func:`lattice_inertial_case`: simple-cubic / BCC / FCC arrays (no reference ratio: Hill,
  Koch & Ladd's ordered-array numbers were not found in the stored references).

Measured tables: ``docs/inertial-flow.md``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from ..conductance import conduit_law, throat_conductance
from ..flow import AMGSolver, darcy_permeability, solve_fixed_pressure, solve_inertial
from ..packing import Packing, lattice_packing, periodic_copies, random_packing, read_packing
from ..pores import (Region, merge_pores, prune_disconnected, region_porosity, select_sample,
                     tessellate)
from ._drag_laws import DRAG_LAWS, drag_ratio

__all__ = ["FINNEY_PATH", "InertialCase",
           "bed_inertial_case", "finney_inertial_case", "lattice_inertial_case",
           "periodic_inertial_case", "random_inertial_case", "solve_sample_curve"]

#: Finney's packing, central subset (radius 1, lengths in sphere radii): in the ``shared/``
#: folder beside the checkout (``../shared`` of the repository root, as a fresh clone has it),
#: else at the development machine's ``/work/shared``.
_FINNEY = Path("data/finney/finney_subset_4021.csv")
FINNEY_PATH = next((p for p in (Path(__file__).resolve().parents[3] / "shared" / _FINNEY,
                                Path("/work/shared") / _FINNEY) if p.exists()),
                   Path(__file__).resolve().parents[3] / "shared" / _FINNEY)


@dataclasses.dataclass
class InertialCase:
    """A solved validation curve. ``reynolds`` (n,) and ``k_ratio`` (n,) = k/k_app of the
    network; ``law_ratio`` {law: (n,)}; ``error`` {law: (n,)} = k_ratio / law_ratio - 1 (the
    relative error of the pressure gradient); Newton ``iterations`` (n,), ``converged``;
    ``permeability_d2`` (Stokes k / d²), ``solid_fraction``, ``seconds``."""

    name: str
    solid_fraction: float
    reynolds: np.ndarray
    k_ratio: np.ndarray
    law_ratio: dict
    error: dict
    iterations: np.ndarray
    converged: bool
    permeability_d2: float
    seconds: float

    def rows(self) -> list[dict]:
        """One JSON-ready dict per Reynolds number."""
        out = []
        for n, re in enumerate(self.reynolds):
            row = {"case": self.name, "solid_fraction": self.solid_fraction,
                   "reynolds_particle": float(re), "k_over_k_app": float(self.k_ratio[n]),
                   "newton_iterations": int(self.iterations[n])}
            for law in self.law_ratio:
                row[f"{law}_ratio"] = float(self.law_ratio[law][n])
                row[f"{law}_error"] = float(self.error[law][n])
            out.append(row)
        return out


def solve_sample_curve(packing, region, velocities_m_s, *, axis=0, policy="table-only",
                       db=None, viscosity_pa_s=1.0, density_kg_m3=1.0, table=None,
                       workers: int = 1):
    """The inertial pipeline of :func:`network.solve_network` (conduit model, bodies merged;
    one AMG hierarchy, built for the Stokes solve and reused by every Newton step):
    ``(permeability_m2, length_m, points, seconds)``, ``seconds`` a dict by stage.

    The conduit law is :func:`network.conductance.conduit_law` with the window ``table``
    (default :data:`network.conductance.CHAIN_WINDOW_TABLE`); ``workers`` continuation chains
    (:func:`network.flow.solve_inertial`)."""
    t = {}
    t0 = time.perf_counter()
    tess = tessellate(packing)
    merge = merge_pores(tess)
    sample = select_sample(tess, region, axis=axis, groups=np.asarray(merge.labels))
    t["tessellate"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    cres = throat_conductance(tess, sample.throats, model="conduit", policy=policy, db=db,
                              viscosity_pa_s=viscosity_pa_s, merge=merge)
    before = sample.throats
    sample, g = prune_disconnected(sample, tess, cres.g)
    keep = np.searchsorted(before, sample.throats)
    t["conductance"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    held = {}

    def amg_solve(A, b):        # the Stokes hierarchy, kept for the Newton solves
        held["amg"] = AMGSolver(A, smoother="forward-backward")
        return held["amg"].solve(b, tol=1e-10)[0]

    p0, _, check = solve_fixed_pressure(sample.n_pores, sample.conns, g, sample.inlet,
                                        sample.outlet, p_in=1.0, p_out=0.0, solver=amg_solve)
    k = darcy_permeability(check["q_in"], 1.0, sample.length_m, sample.area_m2,
                           viscosity_pa_s=viscosity_pa_s)
    t["stokes"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    K, c_on = conduit_law(
        tess, sample.throats, cres.h_m[keep], internal=np.asarray(cres.internal)[keep],
        pore_xyz_m=sample.pore_xyz, conns=sample.conns, stokes_flow_m3_s=check["throat_flow"],
        axis=axis, density_kg_m3=density_kg_m3, viscosity_pa_s=viscosity_pa_s, table=table)
    pts = solve_inertial(sample.n_pores, sample.conns, g, K, sample.inlet, sample.outlet,
                         np.asarray(velocities_m_s, dtype=float) * sample.area_m2,
                         onset_scale=c_on, amg=held.get("amg"),
                         workers=workers, stokes=(p0, check["q_in"]))
    t["inertial"] = time.perf_counter() - t0
    return k, sample.length_m, pts, t


def _run(name, packing, region, diameter, solid_fraction, reynolds, *, axis, policy, db,
         laws, table):
    re = np.asarray(reynolds, dtype=float)
    if re.ndim != 1 or not re.size or np.any(~np.isfinite(re)) or np.any(re <= 0):
        raise ValueError(f"reynolds must be a non-empty list of values > 0, got {reynolds!r}")
    t0 = time.perf_counter()
    us = re / diameter                      # mu = rho = 1: Re = U d
    k, length, pts, _ = solve_sample_curve(packing, region, us, axis=axis, policy=policy,
                                           db=db, table=table)
    grad = np.array([p.dp_pa for p in pts]) / length
    k_ratio = grad * k / us                 # (dP/L) / (mu U / k)
    law_ratio = {}
    for name_ in laws:
        if name_ == "hill_koch_ladd" and solid_fraction < 0.4:
            continue
        law_ratio[name_] = np.asarray(drag_ratio(name_, solid_fraction, re), dtype=float)
    error = {name_: k_ratio / r - 1.0 for name_, r in law_ratio.items()}
    return InertialCase(name, float(solid_fraction), re, k_ratio, law_ratio, error,
                        np.array([p.iterations for p in pts]),
                        bool(all(p.converged for p in pts)), float(k / diameter**2),
                        time.perf_counter() - t0)


def random_inertial_case(solid_fraction: float, reynolds, *, n_spheres: int = 800, rng=1,
                         copies: int = 3, axis: int = 0, policy: str = "table-only",
                         db=None, laws=tuple(DRAG_LAWS), table=None) -> InertialCase:
    """Periodic random packing of unit spheres at ``solid_fraction`` (<= 0.64), copied
    ``copies``³ times; sample = all but half a period at every face (module notes)."""
    phi = float(solid_fraction)
    if not 0.0 < phi <= 0.64:
        raise ValueError(f"solid_fraction must lie in (0, 0.64], got {solid_fraction!r}")
    base = random_packing(int(n_spheres), diameter_range_m=(1.0, 1.0), solid_fraction=phi,
                          periodic=True, rng=rng)
    return periodic_inertial_case(base, phi, reynolds, name=f"random phi={phi:.3f} "
                                  f"n={n_spheres} seed={rng}", copies=copies, axis=axis,
                                  policy=policy, db=db, laws=laws, table=table)


def periodic_inertial_case(base: Packing, solid_fraction: float, reynolds, *, name: str = "",
                           copies: int = 3, axis: int = 0, policy: str = "table-only",
                           db=None, laws=tuple(DRAG_LAWS), table=None) -> InertialCase:
    """A periodic packing of unit spheres in the cube of side L = (pi n / (6 phi))^(1/3),
    copied ``copies``³ times; sample = all but half a period at every face (module notes)."""
    phi = float(solid_fraction)
    side = (math.pi / 6.0 * base.n / phi) ** (1.0 / 3.0)
    packing = periodic_copies(base, side, int(copies))
    region = Region(np.full(3, 0.5 * side), np.full(3, (copies - 0.5) * side))
    return _run(name or f"periodic phi={phi:.3f} n={base.n}", packing, region, 1.0, phi,
                reynolds, axis=axis, policy=policy, db=db, laws=laws, table=table)


def finney_inertial_case(reynolds, *, half_side: float = 8.0, axis: int = 0,
                         policy: str = "table-only", db=None, path=FINNEY_PATH,
                         laws=tuple(DRAG_LAWS), table=None) -> InertialCase:
    """A cube of half-side ``half_side`` (sphere radii) at the centroid of Finney's packing;
    the law is evaluated at the cube's solid fraction (exact sphere-region volumes,
    :func:`network.pores.region_porosity`)."""
    packing = read_packing(Path(path))
    c = packing.centers.mean(axis=0)
    h = float(half_side)
    region = Region(c - h, c + h)
    phi = _box_solid_fraction(packing, region)
    return _run(f"finney cube {2 * h:g} r, phi={phi:.3f}", packing, region,
                float(2 * packing.radii.mean()), phi, reynolds, axis=axis, policy=policy,
                db=db, laws=laws, table=table)


def bed_inertial_case(path, reynolds, *, axis: int = 2, margin: float = 2.5,
                      top_margin: float = 3.0, policy: str = "table-only", db=None,
                      laws=tuple(DRAG_LAWS), table=None) -> InertialCase:
    """A settled bed (a ``dem.pack`` CSV, walls and a free surface): the box ``margin``
    Sauter diameters d32 inside the spheres' extent at the walls and the floor and
    ``top_margin`` d32 below the surface (the lowest of the highest centres of 2 d32 wide
    columns, so that a sphere left on top does not lift it); flow along ``axis`` (2:
    vertical), the law at the box's solid fraction (exact, as Finney's) and d32."""
    packing = read_packing(Path(path))
    c = packing.centers
    d32 = packing.sauter_diameter
    lo, hi = packing.extent() + [[margin * d32], [-margin * d32]]
    n_col = np.maximum(np.floor((hi[:2] - lo[:2]) / (2.0 * d32)).astype(int), 1)
    col = np.floor((c[:, :2] - lo[:2]) / (2.0 * d32)).astype(int)
    inside = np.all((col >= 0) & (col < n_col), axis=1)
    tops = np.full(int(n_col.prod()), -np.inf)
    np.maximum.at(tops, col[inside, 0] * n_col[1] + col[inside, 1], c[inside, 2])
    hi[2] = tops.min() - top_margin * d32
    if np.any(hi - lo < 2.0 * d32):
        raise ValueError(f"{path}: the bed leaves no sample box of 2 d32 inside its margins "
                         f"(box {np.round((hi - lo) / d32, 2)} d32)")
    region = Region(lo, hi)
    phi = _box_solid_fraction(packing, region)
    size = "x".join(f"{v:.1f}" for v in (hi - lo) / d32)
    return _run(f"bed {Path(path).stem} {size} d, phi={phi:.3f}, axis {'xyz'[axis]}", packing,
                region, d32, phi, reynolds, axis=axis, policy=policy, db=db, laws=laws, table=table)


def _box_solid_fraction(packing: Packing, region: Region) -> float:
    """1 - porosity of the box: exact sphere-region volumes less the pairwise lenses of
    overlapping spheres (:func:`network.pores.region_porosity`, error below 1e-4)."""
    return 1.0 - region_porosity(packing, region, 0)[0]


def lattice_inertial_case(kind: str, solid_fraction: float, reynolds, *, n_cells: int = 7,
                          axis: int = 0, policy: str = "table-only", db=None,
                          offset: float = 0.137, table=None) -> InertialCase:
    """Simple-cubic / BCC / FCC array, lattice constant 1, sample box as
    :func:`lattice_sample_permeability`; ``law_ratio`` holds the random-packing laws for
    information only (an ordered array is not a random bed)."""
    c, r = lattice_packing(kind, solid_fraction, n_cells=n_cells, lattice_constant_m=1.0)
    region = Region(np.full(3, 1.0 + offset), np.full(3, n_cells - 2 + offset))
    return _run(f"{kind} phi={float(solid_fraction):.3f}", Packing(c, r), region,
                float(2 * r[0]), float(solid_fraction), reynolds, axis=axis, policy=policy,
                db=db, laws=("beetstra",), table=table)
