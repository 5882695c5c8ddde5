r"""Realistic throats for tests, fits and benchmarks: Delaunay faces of a random packing.

A small random packing of spheres with diameters uniform in 5.5–7.5 mm (the thesis soybean
bed, Table 3.1) is made by overlap relaxation: random centres in a box sized for solid
fraction ``phi``, then repeated pairwise pushes (``scipy.spatial.cKDTree.query_pairs``) until
the largest overlap is a small fraction of the radius (DEM-like residual overlaps).  Its
Delaunay tetrahedra (``scipy.spatial.Delaunay``) give the throats: every face once, kept when
its three centres are at least ``margin`` diameters from the walls.  The ``network`` package
has the real tessellation; this module only feeds ``throats`` tests and benchmarks.
"""

from __future__ import annotations

import numpy as np

__all__ = ["random_packing", "packing_throats", "sample_throats"]


def random_packing(n=400, *, d_min=5.5e-3, d_max=7.5e-3, phi=0.57, iterations=1500,
                   rng=None):
    """Random sphere packing in a cubic box by overlap relaxation.

    Parameters
    ----------
    n : int
        Number of spheres.
    d_min, d_max : float, m
        Diameter range (uniform).
    phi : float
        Solid fraction of the box (the thesis bed has 0.592 = 1 - 0.408).
    iterations : int
        Maximum relaxation sweeps.
    rng : numpy.random.Generator | int | None

    Returns
    -------
    centers : (n, 3) ndarray, m
    radii : (n,) ndarray, m
    """
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(rng)
    r = 0.5 * rng.uniform(d_min, d_max, n)
    box = (np.sum(4.0 / 3.0 * np.pi * r**3) / phi) ** (1.0 / 3.0)
    x = rng.uniform(0, box, (n, 3))
    x = np.clip(x, r[:, None], box - r[:, None])
    for _ in range(iterations):
        pairs = cKDTree(x).query_pairs(2 * r.max(), output_type="ndarray")
        i, j = pairs[:, 0], pairs[:, 1]
        d = x[j] - x[i]
        dist = np.linalg.norm(d, axis=1)
        ov = r[i] + r[j] - dist
        m = ov > 0
        if not m.any() or ov[m].max() < 1e-3 * r.min():
            break
        i, j, d, dist, ov = i[m], j[m], d[m], dist[m], ov[m]
        push = (0.5 * 1.05 * ov / np.maximum(dist, 1e-12))[:, None] * d
        dx = np.zeros_like(x)
        np.add.at(dx, i, -push)
        np.add.at(dx, j, push)
        x = np.clip(x + dx, r[:, None], box - r[:, None])
    return x, r


def packing_throats(centers, radii, *, margin=1.0):
    """Delaunay faces of a packing as throats.

    Parameters
    ----------
    centers : (n, 3) array_like, m
    radii : (n,) array_like, m
    margin : float
        Keep faces whose vertices are at least ``margin`` mean diameters from the bounding box.

    Returns
    -------
    radii : (Nt, 3) ndarray, m
    sides : (Nt, 3) ndarray, m, ``[l12, l13, l23]``
    """
    from scipy.spatial import Delaunay

    x = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    tet = Delaunay(x).simplices
    faces = np.concatenate([tet[:, [0, 1, 2]], tet[:, [0, 1, 3]], tet[:, [0, 2, 3]],
                            tet[:, [1, 2, 3]]])
    faces = np.unique(np.sort(faces, axis=1), axis=0)
    lo, hi = x.min(axis=0), x.max(axis=0)
    cut = margin * 2 * r.mean()
    inner = np.all((x > lo + cut) & (x < hi - cut), axis=1)
    faces = faces[inner[faces].all(axis=1)]
    p = x[faces]
    sides = np.stack([np.linalg.norm(p[:, 0] - p[:, 1], axis=1),
                      np.linalg.norm(p[:, 0] - p[:, 2], axis=1),
                      np.linalg.norm(p[:, 1] - p[:, 2], axis=1)], axis=1)
    return r[faces], sides


def sample_throats(n, *, rng=None):
    """``n`` throats (radii, sides in m) drawn from a random 5.5–7.5 mm packing.

    Packings of 400 spheres are generated (each seeded from ``rng``) until ``n`` interior
    faces are collected; the faces are shuffled so that a prefix is a fair sample.
    """
    rng = np.random.default_rng(rng)
    rs, ss, got = [], [], 0
    while got < n:
        c, r = random_packing(400, rng=rng)
        tr, ts = packing_throats(c, r)
        rs.append(tr)
        ss.append(ts)
        got += tr.shape[0]
    tr, ts = np.concatenate(rs), np.concatenate(ss)
    order = rng.permutation(tr.shape[0])[:n]
    return tr[order], ts[order]
