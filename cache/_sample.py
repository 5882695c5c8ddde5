r"""Small private sampler of realistic throat shapes (for grid design, tests and the benchmark).

The network package owns the real tessellation of real packings; the cache only needs *samples*
of the throat shapes such packings produce, to learn the range of the signature space and to
hold out throats for accuracy measurements.  Data flows network → cache through CSV files, so
this module deliberately re-implements only the two small steps it needs:

1. a random dense packing by **overlap relaxation** in a periodic cube: spheres with diameters
   uniform in ``diameter_range`` are dropped at random positions at packing fraction
   :math:`\phi`, then overlapping pairs (found with ``cKDTree.query_pairs``) are pushed apart
   along their centre line by half their overlap each, until the largest overlap is below
   ``overlap_tol`` (relative to the mean radius) or ``max_iter`` sweeps have run.  Near
   :math:`\phi \approx 0.60` this leaves a dense packing with residual overlaps below
   ``overlap_tol``,
   like a DEM packing.
2. Delaunay tetrahedra of the centres (``scipy.spatial.Delaunay``) away from the cube faces;
   each shared triangular face is a throat with vertex radii and side lengths
   ``[l12, l13, l23]``.
"""

from __future__ import annotations

import logging

import numpy as np

logger = logging.getLogger(__name__)

__all__: list[str] = []


def _random_packing(n_spheres=2000, *, diameter_range=(5.5e-3, 7.5e-3), fraction=0.60,
                    overlap_tol=2e-3, max_iter=3000, rng=None):
    """Random dense packing of ``n_spheres`` spheres in a periodic cube by overlap relaxation.

    Returns ``(centers (N, 3) m, radii (N,) m, box_m)``; centres lie in ``[0, box_m)^3``.
    """
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(rng)
    d_lo, d_hi = (float(v) for v in diameter_range)
    if not 0 < d_lo <= d_hi:
        raise ValueError(f"diameter_range must satisfy 0 < lo <= hi, got {diameter_range}")
    radii = rng.uniform(d_lo, d_hi, n_spheres) / 2
    box = float((np.sum(4 / 3 * np.pi * radii**3) / fraction) ** (1 / 3))
    x = rng.uniform(0, box, (n_spheres, 3))
    rbar = radii.mean()
    for it in range(max_iter):
        tree = cKDTree(x, boxsize=box)
        pairs = tree.query_pairs(2 * radii.max(), output_type="ndarray")
        i, j = pairs[:, 0], pairs[:, 1]
        d = x[j] - x[i]
        d -= box * np.round(d / box)
        dist = np.linalg.norm(d, axis=1)
        overlap = radii[i] + radii[j] - dist
        hit = overlap > 0
        worst = overlap[hit].max() / rbar if hit.any() else 0.0
        if worst < overlap_tol:
            break
        i, j, d, dist, overlap = i[hit], j[hit], d[hit], dist[hit], overlap[hit]
        push = (0.5 * overlap / np.maximum(dist, 1e-12 * rbar))[:, None] * d
        dx = np.zeros_like(x)
        np.add.at(dx, i, -push)
        np.add.at(dx, j, push)
        x = np.mod(x + dx, box)
    logger.debug("overlap relaxation: %d sweeps, worst overlap %.2e r_mean", it + 1, worst)
    return x, radii, box


def _packing_throats(centers, radii, *, box=None, margin=None):
    """Throat shapes (Delaunay faces) of a packing: ``(radii (Nt, 3), sides (Nt, 3))``.

    With ``box`` (periodic cube edge) the packing is extended by periodic images so that
    every face near the centre is a true interior face; tetrahedra whose centroid lies
    within ``margin`` (default two mean diameters) of the hull of the original points are
    discarded.  Sides are ``[l12, l13, l23]`` for vertex radii ``[r1, r2, r3]``.
    """
    from scipy.spatial import Delaunay

    c = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    if margin is None:
        margin = 4 * r.mean()
    if box is not None:
        shifts = np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1])).reshape(3, -1).T
        allc = (c[None] + box * shifts[:, None]).reshape(-1, 3)
        allr = np.tile(r, len(shifts))
        keep = np.all((allc > -margin) & (allc < box + margin), axis=1)
        c, r = allc[keep], allr[keep]
        lo, hi = np.zeros(3), np.full(3, box)
    else:
        lo, hi = c.min(axis=0) + margin, c.max(axis=0) - margin
    tri = Delaunay(c)
    tet = tri.simplices
    cen = c[tet].mean(axis=1)
    inside = np.all((cen > lo) & (cen < hi), axis=1)
    tet = np.sort(tet[inside], axis=1)
    faces = np.concatenate([tet[:, [0, 1, 2]], tet[:, [0, 1, 3]], tet[:, [0, 2, 3]],
                            tet[:, [1, 2, 3]]])
    faces = np.unique(faces, axis=0)
    p = c[faces]
    sides = np.stack([np.linalg.norm(p[:, 0] - p[:, 1], axis=1),
                      np.linalg.norm(p[:, 0] - p[:, 2], axis=1),
                      np.linalg.norm(p[:, 1] - p[:, 2], axis=1)], axis=1)
    return r[faces], sides


def _sample_throats(n_throats=None, *, n_spheres=1500, diameter_range=(5.5e-3, 7.5e-3),
                    fraction=0.60, rng=None):
    """Throats of one random packing (see module notes); optionally a random subset of them."""
    rng = np.random.default_rng(rng)
    centers, radii, box = _random_packing(n_spheres, diameter_range=diameter_range,
                                          fraction=fraction, rng=rng)
    tr, ts = _packing_throats(centers, radii, box=box)
    if n_throats is not None and n_throats < len(tr):
        pick = rng.choice(len(tr), n_throats, replace=False)
        tr, ts = tr[pick], ts[pick]
    return tr, ts
