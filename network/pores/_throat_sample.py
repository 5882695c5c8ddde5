"""Realistic throat shapes: interior Delaunay faces of random sphere packings."""

from __future__ import annotations

import numpy as np

from ..packing import random_packing
from ._tessellation import tessellate

__all__ = ["sample_throats"]


def sample_throats(n_throats: int, *, n_spheres: int = 1500, diameter_range_m=(5.5e-3, 7.5e-3),
                   solid_fraction: float = 0.57, margin_diameters: float = 1.0, rng=None):
    """Throat shapes (Delaunay faces) of random packings: ``n_throats`` of them, shuffled.

    Packings of ``n_spheres`` spheres (:func:`network.random_packing`, closed box, diameters uniform
    on ``diameter_range_m``) are made, each seeded from ``rng``, until ``n_throats`` interior
    faces are collected: faces shared by two tetrahedra whose three sphere centres lie at least
    ``margin_diameters`` mean diameters inside every wall (the wall layer is looser than the
    bulk). The faces are shuffled, so any prefix is a fair sample. This is the sampler of
    realistic throats for the throats/cache tests and benchmarks.

    Returns
    -------
    radii_m, sides_m : (n_throats, 3) ndarray, m
        [r1, r2, r3] and [l12, l13, l23] of each face.

    Examples
    --------
    >>> r, s = sample_throats(50, n_spheres=200, rng=1)
    >>> r.shape, s.shape, bool((s > 0).all())
    ((50, 3), (50, 3), True)
    """
    n = int(n_throats)
    if n < 0:
        raise ValueError(f"n_throats must be >= 0, got {n_throats!r}")
    gen = np.random.default_rng(rng)
    rs, ss, got = [], [], 0
    while got < n or not rs:
        pk = random_packing(int(n_spheres), diameter_range_m=diameter_range_m,
                            solid_fraction=solid_fraction, rng=gen)
        t = tessellate(pk)
        m = float(margin_diameters) * pk.mean_diameter
        lo, hi = pk.centers.min(axis=0) + m, pk.centers.max(axis=0) - m
        xyz = pk.centers[t.throat_vertices]                         # (Nt, 3, 3)
        keep = (t.throat_pores[:, 1] >= 0) & np.all((xyz >= lo) & (xyz <= hi), axis=(1, 2))
        if not keep.any():
            raise ValueError(f"no interior throats in a packing of {n_spheres} spheres with "
                             f"margin {margin_diameters} diameters: use more spheres")
        rs.append(t.throat_radii[keep])
        ss.append(t.throat_sides[keep])
        got += int(keep.sum())
    radii, sides = np.concatenate(rs), np.concatenate(ss)
    order = gen.permutation(radii.shape[0])[:n]
    return radii[order], sides[order]
