"""The packing: sphere centres and radii (m), optionally the grain each sphere belongs to.

:class:`Packing` is the table every stage reads; :func:`validate_spheres` and
:func:`check_grains` are the checks every reader runs; :func:`scale_warning` flags a packing
that is probably not in metres.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

__all__ = ["MIN_SPHERES", "PLAUSIBLE_DIAMETER_M", "Packing", "check_grains", "scale_warning",
           "validate_spheres"]

#: Fewest spheres that make a three-dimensional Delaunay tessellation with an interior.
MIN_SPHERES = 5


@dataclasses.dataclass(frozen=True)
class Packing:
    """A sphere packing.

    Attributes
    ----------
    centers : (N, 3) ndarray of float, m
        Sphere centres.
    radii : (N,) ndarray of float, m
        Sphere radii, all > 0.
    source : str
        Where the packing came from (a path, or a short description); informative only.
    """

    centers: np.ndarray
    radii: np.ndarray
    source: str = ""
    #: (N,) int: the rigid grain (multi-sphere clump) each sphere belongs to, or None when every
    #: sphere is a grain of its own.
    grain_id: np.ndarray | None = None

    def __post_init__(self):
        try:
            c = np.asarray(self.centers, dtype=float)
            r = np.asarray(self.radii, dtype=float)
        except (TypeError, ValueError) as e:
            raise TypeError(f"centers and radii must be numeric arrays: {e}") from e
        if c.ndim != 2 or c.shape[1] != 3:
            raise ValueError(f"centers must have shape (N, 3), got {c.shape}")
        if r.shape != (c.shape[0],):
            raise ValueError(f"radii must have shape ({c.shape[0]},), got {r.shape}")
        c.setflags(write=False)
        r.setflags(write=False)
        object.__setattr__(self, "centers", c)
        object.__setattr__(self, "radii", r)
        if self.grain_id is not None:
            g = np.asarray(self.grain_id)
            if g.shape != r.shape:
                raise ValueError(f"grain_id must have shape ({r.size},), got {g.shape}")
            if g.size and not np.all(np.equal(np.mod(g, 1), 0)):
                raise ValueError("grain_id must be whole numbers")
            g = g.astype(np.int64)
            g.setflags(write=False)
            object.__setattr__(self, "grain_id", g)

    @property
    def n_grains(self) -> int:
        """Number of grains (spheres when there is no ``grain_id``)."""
        return self.n if self.grain_id is None else int(np.unique(self.grain_id).size)

    @property
    def n(self) -> int:
        """Number of spheres."""
        return int(self.radii.shape[0])

    @property
    def mean_diameter(self) -> float:
        """Arithmetic mean sphere diameter, m."""
        return float(2.0 * self.radii.mean())

    def bounds(self) -> np.ndarray:
        """(2, 3) array: lowest and highest centre coordinate along x, y, z (m)."""
        return np.stack([self.centers.min(axis=0), self.centers.max(axis=0)])


def validate_spheres(centers, radii, lines, source, *, check_duplicates=True):
    """Check finite values, positive radii, distinct centres and enough spheres.

    ``lines[i]`` is the 1-based file line (or array row) that sphere i came from.
    """
    n = len(radii)
    if n < MIN_SPHERES:
        raise ValueError(f"{source}: too few spheres ({n}); a packing needs at least {MIN_SPHERES}")
    bad = ~np.isfinite(centers).all(axis=1) | ~np.isfinite(radii)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{source}: line {lines[i]}: non-finite value (NaN or inf) "
                         f"in x,y,z,r = {centers[i].tolist() + [float(radii[i])]}")
    bad = radii <= 0
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{source}: line {lines[i]}: radius must be > 0, got {radii[i]!r}")
    if check_duplicates:
        order = np.lexsort(centers.T[::-1])
        s = centers[order]
        dup = np.all(s[1:] == s[:-1], axis=1)
        if dup.any():
            k = int(np.flatnonzero(dup)[0])
            a, b = sorted((int(order[k]), int(order[k + 1])))
            raise ValueError(f"{source}: line {lines[b]}: duplicate centre {centers[b].tolist()} "
                             f"(same as line {lines[a]})")


def check_grains(centers, radii, grain_id, lines, source) -> None:
    """ValueError naming the grain when the spheres of one ``grain_id`` are not one body.

    A rigid multi-sphere grain is a set of overlapping spheres: the graph of overlapping pairs
    (distance < r_i + r_j) of one grain must be connected. One id on spheres far apart is an
    id mix-up (two grains numbered alike), which would merge two grains into one solid.
    """
    c = np.asarray(centers, float)
    r = np.asarray(radii, float)
    g = np.asarray(grain_id).astype(np.int64)
    pairs = cKDTree(c).query_pairs(2.0 * float(r.max()), output_type="ndarray")
    if pairs.size:
        i, j = pairs[:, 0], pairs[:, 1]
        keep = (g[i] == g[j]) & (np.linalg.norm(c[i] - c[j], axis=1) < r[i] + r[j])
        i, j = i[keep], j[keep]
    else:
        i = j = np.zeros(0, dtype=np.int64)
    n = r.size
    adj = sp.coo_array((np.ones(i.size), (i, j)), shape=(n, n))
    _, comp = connected_components(adj, directed=False)
    pairs_gc = np.unique(np.column_stack([g, comp]), axis=0)
    ids, counts = np.unique(pairs_gc[:, 0], return_counts=True)
    split = ids[counts > 1]
    if split.size:
        gid = int(split[0])
        rows = np.flatnonzero(g == gid)
        far = rows[comp[rows] != comp[rows[0]]][0]
        raise ValueError(f"{source}: grain_id {gid} is on spheres that do not overlap into one "
                         f"body (line {lines[rows[0]]} and line {lines[far]} are apart): two "
                         f"grains with one id?")


#: Mean grain diameters (m) outside which a packing is probably not in metres.
PLAUSIBLE_DIAMETER_M = (0.5e-3, 50e-3)


def scale_warning(packing: Packing) -> str | None:
    """A one-line warning when the mean diameter is outside 0.5-50 mm (not metres?), else None.

    >>> scale_warning(Packing(np.eye(3) * 10, np.full(3, 3.3)))[:40]
    'mean grain diameter 6.6 m is outside 0.5'
    """
    d = packing.mean_diameter
    lo, hi = PLAUSIBLE_DIAMETER_M
    if lo <= d <= hi:
        return None
    return (f"mean grain diameter {d:.3g} m is outside 0.5-50 mm, the range of grains: if the "
            f"file is not in metres, give --units mm or --units cm (a dimensionless packing "
            f"is fine with --viscosity 1)")
