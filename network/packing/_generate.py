r"""Fast geometric sphere packings for tests, the bundled scene and the benchmark.

Not a DEM (that is ``dem/``): spheres are placed at random in a box and their overlaps are
relaxed away while their radii grow to the target size ("grow and push"). Each sweep finds the
overlapping pairs with ``cKDTree.query_pairs`` (periodic ``boxsize`` when asked) and moves both
spheres of a pair apart along their line of centres, in proportion to the other's volume:

.. math:: \delta_{ij} = s (r_i + r_j) - |x_i - x_j|, \qquad
          \Delta x_i = -\tfrac{\omega}{2}\, \delta_{ij}\, \hat n_{ij}
          \frac{2 r_j^3}{r_i^3 + r_j^3}

, with :math:`s` rising from ``s0`` to 1. Walls (when
not periodic) push centres back to one radius from the faces. It stops when the largest overlap
is below ``tol`` times the pair's contact distance. The result is a random, loose-to-dense,
non-overlapping (to ``tol``) packing: isotropic, but without gravity, so it has no settling
anisotropy, and denser than about 0.62 it becomes slow (it is not a jamming algorithm).
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .._deferred import spatial
from ..core import Packing

__all__ = ["random_packing", "periodic_copies", "soybean_default_scene", "SOYBEAN_DEFAULT"]

log = logging.getLogger(__name__)


def _forces(x, rs, box, pairs, periodic):
    """Harmonic overlap forces F_i = sum_j delta_ij n_ji and the worst relative overlap."""
    i, j = pairs[:, 0], pairs[:, 1]
    d = x[j] - x[i]
    if periodic:
        d -= box * np.round(d / box)
    dist = np.sqrt(np.einsum("ij,ij->i", d, d))
    contact = rs[i] + rs[j]
    over = np.maximum(contact - dist, 0.0)
    f = (over / np.maximum(dist, 1e-300))[:, None] * d
    n = x.shape[0]
    force = np.column_stack([np.bincount(j, f[:, k], n) - np.bincount(i, f[:, k], n)
                             for k in range(3)])
    worst = float(np.max(over / contact)) if over.size else 0.0
    if not periodic:
        lo_pen = np.maximum(rs[:, None] - x, 0.0)
        hi_pen = np.maximum(x + rs[:, None] - box, 0.0)
        force += lo_pen - hi_pen
        worst = max(worst, float(np.max((lo_pen + hi_pen) / (2 * rs[:, None]))))
    return force, worst


def _relax(x, r, box, *, periodic, tol, max_sweeps, s0, grow_sweeps):
    """FIRE minimisation of the harmonic overlap energy with growing radii and a Verlet list."""
    rmax = r.max()
    skin = 0.3 * rmax
    dt_max, dt = 0.2, 0.05
    alpha0, alpha, n_pos = 0.1, 0.1, 0
    v = np.zeros_like(x)
    x_ref = x.copy()
    pairs = None
    worst = np.inf
    for sweep in range(max_sweeps):
        s = min(1.0, s0 + (1.0 - s0) * sweep / max(grow_sweeps, 1))
        rs = s * r
        disp = x - x_ref
        if periodic:
            disp -= box * np.round(disp / box)
        if pairs is None or np.max(np.einsum("ij,ij->i", disp, disp)) > (0.5 * skin) ** 2:
            tree = spatial.cKDTree(x, boxsize=box if periodic else None)
            pairs = tree.query_pairs(2.0 * rs.max() + skin, output_type="ndarray")
            x_ref = x.copy()
        f, worst = _forces(x, rs, box, pairs, periodic)
        if s >= 1.0 and worst < tol:
            break
        # FIRE (Bitzek et al. 2006), unit masses, lengths in units of rmax
        fs = f / rmax
        power = float(np.einsum("ij,ij->", fs, v))
        if power > 0:
            fn = math.sqrt(float(np.einsum("ij,ij->", fs, fs)))
            vn = math.sqrt(float(np.einsum("ij,ij->", v, v)))
            if fn > 0:
                v = (1 - alpha) * v + alpha * vn * fs / fn
            n_pos += 1
            if n_pos > 5:
                dt = min(dt * 1.1, dt_max)
                alpha *= 0.99
        else:
            v[:] = 0.0
            dt *= 0.5
            alpha = alpha0
            n_pos = 0
        v += dt * fs
        x = x + dt * v * rmax
        if periodic:
            x %= box
        else:
            x = np.clip(x, 0.5 * rs[:, None], box - 0.5 * rs[:, None])
    else:
        log.warning("random_packing: %d sweeps reached, largest overlap %.2e of contact "
                    "distance", max_sweeps, worst)
    return x, sweep, worst


def random_packing(n_spheres: int, *, diameter_range_m=(5.5e-3, 7.5e-3),
                   solid_fraction: float = 0.60, aspect=(1.0, 1.0, 1.0), periodic: bool = False,
                   rng=None, tol: float = 2e-3, max_sweeps: int = 3000, s0: float = 0.75,
                   grow_sweeps: int = 150) -> Packing:
    """Random non-overlapping packing of spheres with uniformly distributed diameters.

    Parameters
    ----------
    n_spheres : int
        Number of spheres (>= 5).
    diameter_range_m : (2,) floats, m
        Diameters are uniform on this range (default 5.5–7.5 mm, soybeans, thesis Table 3.1).
    solid_fraction : float
        Sphere volume / box volume, 0 < φ <= 0.64 (default 0.60, porosity 0.40). With walls the
        bulk away from them is denser than this global value.
    aspect : (3,) floats
        Box side ratios (scaled to give the volume).
    periodic : bool
        Periodic box (no walls); centres are wrapped into [0, L).
    rng : numpy.random.Generator or int or None
        Random source: the same seed gives the same packing.
    tol : float
        Stop when every overlap < ``tol`` × (r_i + r_j).
    max_sweeps : int
        Sweep limit; reaching it is logged with the remaining overlap.
    s0, grow_sweeps : float, int
        Initial radius scale and the sweeps over which it grows linearly to 1.

    Returns
    -------
    Packing
        Centres in [0, L_k] per axis (m), radii (m); ``source`` records the parameters.
    """
    if n_spheres < 5:
        raise ValueError(f"n_spheres must be >= 5, got {n_spheres}")
    if not 0 < solid_fraction <= 0.64:
        raise ValueError(f"solid_fraction must be in (0, 0.64], got {solid_fraction}")
    dmin, dmax = map(float, diameter_range_m)
    if not 0 < dmin <= dmax:
        raise ValueError(f"diameter range must satisfy 0 < min <= max, got {diameter_range_m}")
    gen = np.random.default_rng(rng)
    r = 0.5 * gen.uniform(dmin, dmax, n_spheres)
    vol = (4.0 / 3.0) * math.pi * np.sum(r**3) / solid_fraction
    asp = np.asarray(aspect, dtype=float)
    box = asp * (vol / np.prod(asp)) ** (1.0 / 3.0)
    x = gen.random((n_spheres, 3)) * box
    if not periodic:
        x = np.clip(x, r[:, None], box - r[:, None])
    x, sweep, worst = _relax(x, r, box, periodic=periodic, tol=tol, max_sweeps=max_sweeps,
                             s0=s0, grow_sweeps=grow_sweeps)
    log.info("random_packing: %d spheres, solid fraction %.3f, box %s m, %d sweeps, "
             "max overlap %.1e", n_spheres, solid_fraction, np.round(box, 5), sweep + 1, worst)
    src = (f"random_packing(n={n_spheres}, d={dmin:g}-{dmax:g} m, phi={solid_fraction:g}, "
           f"periodic={periodic})")
    return Packing(x, r, source=src)


def periodic_copies(packing: Packing, side: float, copies: int) -> Packing:
    """``copies``³ copies of a periodic packing in a cube of side ``side`` (same unit).

    Centres are wrapped into [0, side) first, so the copies tile space without overlaps;
    copy (i, j, k) is shifted by (i, j, k) * side. Sphere order: copy by copy, each in the
    order of ``packing``.

    Examples
    --------
    >>> p = periodic_copies(Packing([[0.5, 0.5, 1.5]], [0.5]), 1.0, 2)
    >>> p.centers.shape, float(p.centers[:, 2].max())
    ((8, 3), 1.5)
    """
    n = int(copies)
    if n < 1:
        raise ValueError(f"copies must be >= 1, got {copies!r}")
    shifts = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), -1).reshape(-1, 3)
    c = (np.mod(packing.centers, side)[None] + side * shifts[:, None]).reshape(-1, 3)
    grain = None
    if packing.grain_id is not None:            # each copy's grains numbered apart
        span = int(packing.grain_id.max()) - int(packing.grain_id.min()) + 1
        grain = (packing.grain_id[None] + span * np.arange(len(shifts))[:, None]).ravel()
    return Packing(c, np.tile(packing.radii, len(shifts)), grain_id=grain,
                   source=f"{n}^3 periodic copies of {packing.source}")


#: Parameters of the bundled scene ``network/data/soybean_default.csv``.
SOYBEAN_DEFAULT = {"n_spheres": 3000, "diameter_range_m": (5.5e-3, 7.5e-3),
                   "solid_fraction": 0.57, "aspect": (1.0, 1.0, 2.0), "periodic": False,
                   "rng": 20261122}


def soybean_default_scene() -> Packing:
    """Regenerate the bundled soybean-like scene (3000 spheres, d = 5.5–7.5 mm, closed box).

    A closed 1 : 1 : 2 box (70 × 70 × 143 mm) with global solid fraction 0.57; the walls loosen
    the outer layer, so the interior box 1.5 mean diameters inside the outer sphere surfaces
    has porosity 0.399 ± 0.001 (Monte Carlo), the thesis bed's 0.40. Written with 6
    significant digits (0.1 µm) by :func:`network.write_packing_csv`.
    """
    return random_packing(**SOYBEAN_DEFAULT)
