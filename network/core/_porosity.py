r"""Porosity of a sample region: exact volumes of the spheres cut by it, or Monte Carlo.

``method='exact'`` (default): the solid volume in the region is

.. math:: V_s = \sum_i |S_i \cap R| - \sum_{i<j} |L_{ij} \cap R|,

with :math:`|S_i \cap R|` the full sphere volume for spheres inside the region, 0 outside, and
for the spheres the region's faces cut, the integral along the axis of the exact area of a
disk cut by the region's cross-section (a rectangle: inclusion-exclusion of disk-quadrant
areas; a circle: the circle-circle lens), in :math:`z = z_c + r\sin\theta`, by Gauss-Legendre
on the pieces between the kinks where a slice meets a face, edge or wall, each mapped so the
:math:`(\theta-\theta_k)^{3/2}` kink is smooth (16 nodes: 5e-9 of a sphere's volume).
Overlapping pairs (DEM packings) subtract their lens volume, counted when the lens centre lies
in the region (a sphere inside another: its exact share of the region); triple overlaps are not
computed. The returned error is the quadrature's (the difference to 12 nodes), the lens volume
of lenses within a lens radius of the region's faces, and, for every three spheres overlapping
pairwise, the smallest of their lenses (a bound of the triple intersection, subtracted once too
often: the porosity errs high). ``method='monte-carlo'``: :math:`M` uniform points,
:math:`\hat\varepsilon = 1 - S/M`, :math:`\sigma = \sqrt{\hat\varepsilon(1-\hat\varepsilon)/M}`.
On the bundled scene: exact 0.399039 (error bound 3e-7) in 0.03 s; Monte Carlo 0.3992 ± 0.0008
in 0.3-1.4 s (400 000 points). Inscribed cylinders along z and x: 0.39975 and 0.39664, Monte
Carlo with 2e6 points 0.39950 and 0.39694 ± 0.00035.
"""

from __future__ import annotations

import logging

import numpy as np

from .._deferred import spatial

__all__ = ["region_porosity", "POROSITY_METHODS", "MAX_EXACT_ERROR", "OverlapError",
           "disk_rectangle_area", "circle_lens_area", "sphere_region_volume"]

log = logging.getLogger(__name__)

#: Porosity methods of :func:`region_porosity`.
POROSITY_METHODS = ("exact", "monte-carlo")
#: Largest error bound of the exact porosity taken (its pairwise lens correction misses what
#: three or more spheres share): above it the spheres overlap too much to be separate grains
MAX_EXACT_ERROR = 0.1


class OverlapError(ValueError):
    """Spheres of different grains overlap so much that the bed is no packing of separate
    grains (typically multi-sphere grains written without their ``grain_id`` column): an input
    fault (``bad_input``: exit 2 in a CLI), with a sentence saying what to give."""

    bad_input = True

    def __init__(self, packing, porosity, error, tree):
        c, r = packing.centers, packing.radii
        g = np.arange(packing.n) if packing.grain_id is None else packing.grain_id
        pairs = tree.query_pairs(2.0 * float(r.max()), output_type="ndarray")
        i, j = pairs[:, 0], pairs[:, 1]
        deep = (g[i] != g[j]) & (np.linalg.norm(c[i] - c[j], axis=1)
                                 < r[i] + r[j] - 0.2 * np.minimum(r[i], r[j]))
        n = np.unique(np.concatenate([i[deep], j[deep]])).size
        super().__init__(
            f"{packing.source + ': ' if packing.source else ''}{n} of {packing.n} spheres "
            f"overlap a sphere of another grain by more than a fifth of its radius (the "
            f"porosity comes out {porosity:.3g} +- {error:.2g}): this is no packing of separate "
            f"grains. If its spheres make multi-sphere grains, give each grain's spheres one "
            f"id in a grain_id column")
#: Gauss-Legendre nodes per smooth piece of a cut sphere.
_NODES = 16


def _disk_quadrant(x, y, r):
    r"""Area of the disk of radius r at the origin with :math:`u < x` and :math:`v < y`.

    With :math:`S(t) = \int_{-r}^{t}\sqrt{r^2-u^2}\,du` (half-disk area left of t) and
    :math:`B(x, y)` the area left of x above :math:`|y|`, the result is :math:`2S(x) - B` for
    :math:`y \ge 0` and :math:`B(x, |y|)` for :math:`y < 0` (mirror symmetry).
    """
    x = np.clip(x, -r, r)
    ay = np.minimum(np.abs(y), r)
    safe = np.where(r > 0, r, 1.0)

    def half(t):
        return 0.5 * (t * np.sqrt(np.maximum(r * r - t * t, 0.0))
                      + r * r * np.arcsin(np.clip(t / safe, -1, 1))) + 0.25 * np.pi * r * r

    xs = np.sqrt(np.maximum(r * r - ay * ay, 0.0))       # chord half-width at |v| = |y|
    top = np.minimum(x, xs)
    above = np.where(top > -xs, half(top) - half(-xs) - ay * (top + xs), 0.0)
    return np.where(y >= 0, 2.0 * half(x) - above, above)


def disk_rectangle_area(cx, cy, r, x0, x1, y0, y1):
    """Area of disks (centre cx, cy, radius r) inside the rectangle [x0, x1] x [y0, y1].

    >>> round(float(disk_rectangle_area(0.0, 0.0, 1.0, 0.0, 5.0, 0.0, 5.0)), 12)   # quarter
    0.785398163397
    """
    f = _disk_quadrant
    return np.maximum(f(x1 - cx, y1 - cy, r) - f(x0 - cx, y1 - cy, r) - f(x1 - cx, y0 - cy, r)
                      + f(x0 - cx, y0 - cy, r), 0.0)


def circle_lens_area(d, r, big_r):
    """Area common to circles of radii r and big_r with centres d apart (elementwise).

    >>> round(float(circle_lens_area(0.0, 1.0, 2.0)), 12)     # small circle inside
    3.14159265359
    """
    d, r, big_r = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (d, r, big_r)))
    out = np.zeros(d.shape)
    inside = d <= np.abs(big_r - r)
    out[inside] = np.pi * np.minimum(r, big_r)[inside] ** 2
    part = ~inside & (d < r + big_r)
    dd, a, b = d[part], r[part], big_r[part]
    ca = np.clip((dd**2 + a**2 - b**2) / (2 * dd * a), -1, 1)
    cb = np.clip((dd**2 + b**2 - a**2) / (2 * dd * b), -1, 1)
    k = np.sqrt(np.maximum((-dd + a + b) * (dd + a - b) * (dd - a + b) * (dd + a + b), 0.0))
    out[part] = a**2 * np.arccos(ca) + b**2 * np.arccos(cb) - 0.5 * k
    return out


def sphere_region_volume(centers, radii, region, axis: int, *, nodes: int = _NODES):
    r"""Volume of each sphere inside ``region`` (box, or cylinder along ``axis``), shape (N,).

    Slices normal to ``axis`` are integrated in :math:`\theta`, :math:`z = z_c + r\sin\theta`,
    :math:`dz = r\cos\theta\, d\theta`, by Gauss-Legendre on the pieces between the angles
    where the slice's disk meets a face, an edge or the cylinder wall (there the slice area has
    a kink); within a piece it is smooth, so ``nodes`` per piece reach rounding error.

    >>> from network.pores import Region
    >>> v = sphere_region_volume([[0, 0, 0]], [1.0], Region([0, 0, 0], [3, 3, 3]), 2)
    >>> round(float(v[0] / (4 / 3 * np.pi)), 12)                   # a corner: one eighth
    0.125
    """
    c = np.asarray(centers, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float).ravel()
    lat = [k for k in range(3) if k != axis]
    t0 = np.arcsin(np.clip((region.lo[axis] - c[:, axis]) / r, -1, 1))
    t1 = np.arcsin(np.clip((region.hi[axis] - c[:, axis]) / r, -1, 1))
    if region.radius is None:
        dx = np.abs(c[:, lat[0], None] - [region.lo[lat[0]], region.hi[lat[0]]])   # (N, 2)
        dy = np.abs(c[:, lat[1], None] - [region.lo[lat[1]], region.hi[lat[1]]])
        dist = np.concatenate([dx, dy, np.hypot(dx[:, :, None], dy[:, None, :]).reshape(-1, 4)],
                              axis=1)
    else:
        d = np.linalg.norm(c[:, lat] - 0.5 * (region.lo[lat] + region.hi[lat]), axis=1)
        dist = np.stack([np.abs(region.radius - d), region.radius + d], axis=1)
    # slice radius rho = r cos(theta) meets distance D at theta = +-arccos(D / r) (D < r only)
    a = np.arccos(np.clip(dist / r[:, None], 0.0, 1.0))
    a = np.where(dist < r[:, None], a, t1[:, None])
    brk = np.concatenate([t0[:, None], -a, a, t1[:, None]], axis=1)
    brk = np.sort(np.clip(brk, t0[:, None], t1[:, None]), axis=1)           # (N, K)
    # the non-empty pieces, flattened, each with its sphere
    piece = np.flatnonzero((brk[:, 1:] > brk[:, :-1]).ravel())
    k = piece // (brk.shape[1] - 1)
    lo_ = brk[:, :-1].ravel()[piece, None]
    hi_ = brk[:, 1:].ravel()[piece, None]
    # Gauss-Legendre in t on [0, 1] with theta = lo + (hi - lo)(1 - cos(pi t))/2: the slice
    # area goes like (theta - theta_k)^(3/2) at a kink, t^3 after the map, so it stays smooth
    g, w = np.polynomial.legendre.leggauss(int(nodes))
    t = 0.5 * (g + 1)
    th = lo_ + (hi_ - lo_) * 0.5 * (1 - np.cos(np.pi * t))                    # (P, m)
    rho = r[k, None] * np.cos(th)
    jac = (hi_ - lo_) * 0.25 * np.pi * np.sin(np.pi * t) * w * rho
    if region.radius is None:
        area = disk_rectangle_area(c[k, lat[0], None], c[k, lat[1], None], rho,
                                   region.lo[lat[0]], region.hi[lat[0]],
                                   region.lo[lat[1]], region.hi[lat[1]])
    else:
        area = circle_lens_area(d[k, None], rho, region.radius)
    return np.bincount(k, weights=np.sum(area * jac, axis=1), minlength=r.size)


def _exact(packing, region, axis, tree):
    c, r = packing.centers, packing.radii
    lat = [k for k in range(3) if k != axis]
    lo, hi = region.lo, region.hi
    dlo, dhi = c - lo, hi - c
    if region.radius is None:
        inside = np.all((dlo >= r[:, None]) & (dhi >= r[:, None]), axis=1)
        outside = np.any((dlo <= -r[:, None]) | (dhi <= -r[:, None]), axis=1)
    else:
        d = np.linalg.norm(c[:, lat] - 0.5 * (lo[lat] + hi[lat]), axis=1)
        inside = ((d + r <= region.radius) & (dlo[:, axis] >= r) & (dhi[:, axis] >= r))
        outside = ((d - r >= region.radius) | (dlo[:, axis] <= -r) | (dhi[:, axis] <= -r))
    cut = ~inside & ~outside
    vol = 4.0 / 3.0 * np.pi * r**3
    v = np.sum(vol[inside])
    vc = sphere_region_volume(c[cut], r[cut], region, axis)
    vh = sphere_region_volume(c[cut], r[cut], region, axis, nodes=3 * _NODES // 4)
    v += np.sum(vc)
    err = float(np.sum(np.abs(vc - vh)))
    # overlapping pairs: subtract their lens (height h_i on sphere i's side), counted when the
    # lens centre (on the radical plane) lies in the region
    pairs = tree.query_pairs(2 * float(r.max()), output_type="ndarray")
    if pairs.size:
        i, j = pairs[:, 0], pairs[:, 1]
        dv = c[j] - c[i]
        dist = np.linalg.norm(dv, axis=1)
        hit = dist < r[i] + r[j]
        i, j, dv, dist = i[hit], j[hit], dv[hit], dist[hit]
        if i.size:
            ri, rj = r[i], r[j]
            # a sphere inside another (a grain's small sphere, a fine): the lens is all of it
            nested = dist <= np.abs(ri - rj)
            dd = np.where(nested, 1.0, dist)
            lens = np.where(nested, 4.0 / 3.0 * np.pi * np.minimum(ri, rj) ** 3,
                            np.pi * (ri + rj - dd) ** 2 * (dd**2 + 2 * dd * rj - 3 * rj**2
                            + 2 * dd * ri + 6 * ri * rj - 3 * ri**2) / (12 * dd))
            a = (dd**2 + ri**2 - rj**2) / (2 * dd)             # radical plane from centre i
            pc = np.where(nested[:, None], np.where((ri <= rj)[:, None], c[i], c[j]),
                          c[i] + (a / dd)[:, None] * dv)
            # a nested sphere's share of the region is exact, as any sphere's
            v -= np.sum(sphere_region_volume(pc[nested], np.minimum(ri, rj)[nested], region,
                                             axis)) if nested.any() else 0.0
            v -= np.sum(lens[~nested & region.contains(pc, axis)])
            # lenses near a face are split by it: their volume bounds that error
            rl = np.sqrt(np.maximum(ri**2 - a**2, 0.0))
            near = ~nested & (region.contains(pc, axis) != region.contains(
                np.clip(pc, lo + rl[:, None], hi - rl[:, None]), axis))
            err += float(np.sum(lens[near]))
            keep = ~outside[i] & ~outside[j]
            err += _triple_bound(i[keep], j[keep], lens[keep], r.size)
    total = region.cross_section(axis) * (hi[axis] - lo[axis])
    return 1.0 - v / total, err / total


def _triple_bound(i, j, lens, n):
    r"""Bound of the solid volume the pairwise lens correction subtracts once too often: every
    triangle of the overlap graph (three spheres overlapping pairwise, none outside the region)
    may have a triple intersection, inside each of its three lenses, so at most the smallest."""
    if i.size < 3:
        return 0.0
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    order = np.lexsort((hi, lo))
    lo, hi, lens = lo[order], hi[order], lens[order]
    key = lo.astype(np.int64) * n + hi                        # sorted: edges by (lo, hi)
    end = np.searchsorted(lo, lo, side="right")
    later = end - np.arange(lo.size) - 1                      # edges after e at the same apex
    e = np.repeat(np.arange(lo.size), later)                  # apex lo[e] = lo[f], hi[e] < hi[f]
    if not e.size:
        return 0.0
    f = e + 1 + np.arange(e.size) - np.repeat(np.cumsum(later) - later, later)
    third = hi[e].astype(np.int64) * n + hi[f]
    pos = np.minimum(np.searchsorted(key, third), key.size - 1)
    tri = key[pos] == third
    return float(np.sum(np.minimum(np.minimum(lens[e], lens[f]), lens[pos])[tri]))


def _monte_carlo(packing, region, axis, tree, n_points, rng):
    gen = np.random.default_rng(rng)
    lo, hi = region.lo, region.hi
    need, chunks = n_points, []
    while need > 0:  # rejection for the cylinder (acceptance pi/4), one or two rounds
        cand = lo + (hi - lo) * gen.random((int(need * 1.35) + 16, 3))
        cand = cand[region.contains(cand, axis)]
        chunks.append(cand[:need])
        need -= chunks[-1].shape[0]
    pts = np.vstack(chunks)
    k = min(8, packing.n)
    solid = np.zeros(pts.shape[0], dtype=bool)
    step = 100_000
    for s in range(0, pts.shape[0], step):
        d, i = tree.query(pts[s:s + step], k=k)
        solid[s:s + step] = np.any(d < packing.radii[i], axis=1)
    eps = 1.0 - solid.mean()
    return float(eps), float(np.sqrt(max(eps * (1 - eps), 1e-300) / pts.shape[0]))


def region_porosity(packing, region, axis: int, *, method: str = "exact",
                    n_points: int = 400_000, rng=0,
                    tree: spatial.cKDTree | None = None) -> tuple[float, float]:
    """Porosity of ``region`` (a box, or a cylinder along ``axis``) and its error.

    Parameters
    ----------
    packing : Packing
    region : Region
    axis : int
        Cylinder axis (and the slicing axis of the exact method).
    method : {'exact', 'monte-carlo'}
        Exact sphere-region volumes (default; Monte Carlo for multi-sphere grains, whose
        spheres overlap three at a time) or Monte Carlo.
    n_points : int, optional
        Monte-Carlo points (default 400 000; ignored by 'exact').
    rng : numpy.random.Generator or int or None, optional
        Monte-Carlo random source (default seed 0).
    tree : cKDTree, optional
        Tree of ``packing.centers`` if the caller already has one.

    Returns
    -------
    porosity : float
    error : float
        'exact': bound of the quadrature and lens-splitting error; 'monte-carlo': one
        standard error.
    """
    if method not in POROSITY_METHODS:
        raise ValueError(f"unknown porosity method {method!r}; choose one of "
                         f"{', '.join(POROSITY_METHODS)}")
    if method == "monte-carlo" and n_points < 100:
        raise ValueError(f"n_points must be >= 100, got {n_points}")
    tree = spatial.cKDTree(packing.centers) if tree is None else tree
    if method == "exact" and packing.grain_id is not None and packing.n_grains < packing.n:
        # the spheres of a multi-sphere grain overlap three and more at a time, which the
        # exact method's pairwise lens correction does not count: the union by Monte Carlo
        log.info("multi-sphere grains: porosity by Monte Carlo (union of the spheres)")
        method = "monte-carlo"
    if method == "exact":
        eps, err = _exact(packing, region, int(axis), tree)
        if not 0 < eps < 1 or err > MAX_EXACT_ERROR:
            raise OverlapError(packing, eps, err, tree)
        log.info("region porosity %.5f (error < %.1e, exact sphere-region volumes)", eps, err)
    else:
        eps, err = _monte_carlo(packing, region, int(axis), tree, n_points, rng)
        log.info("region porosity %.4f ± %.4f (%d Monte-Carlo points)", eps, err, n_points)
    return float(eps), float(err)
