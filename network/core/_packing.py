"""The packing: sphere centres and radii (m), optionally the grain each sphere belongs to.

:class:`Packing` is the table every stage reads; :func:`validate_spheres` and
:func:`check_grains` are the checks every reader runs; :func:`scale_warning` flags a packing
that is probably not in metres.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from .._deferred import csgraph, sparse, spatial

__all__ = ["MIN_SPHERES", "PLAUSIBLE_DIAMETER_M", "DegeneratePackingError", "Packing",
           "check_grains", "check_three_dimensional", "grain_volumes", "scale_warning",
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
        # read-only copies: the caller's arrays stay as they were (writable: the DEM moves them)
        c = c.copy() if c.flags.writeable else c
        r = r.copy() if r.flags.writeable else r
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

    def scaled(self, factor: float, source: str | None = None) -> "Packing":
        """This packing with every length times ``factor`` (a unit change), every other column
        (``grain_id``) kept; ``source`` replaces the description when given.

        >>> p = Packing(np.eye(3), [1, 1, 1], grain_id=[4, 5, 6]).scaled(0.01)
        >>> p.radii.tolist(), p.grain_id.tolist()
        ([0.01, 0.01, 0.01], [4, 5, 6])
        """
        return dataclasses.replace(self, centers=self.centers * factor,
                                   radii=self.radii * factor,
                                   source=self.source if source is None else source)

    def shifted(self, offset) -> "Packing":
        """This packing moved by ``offset`` (3,) (its unit), every other column kept."""
        return dataclasses.replace(self, centers=self.centers + np.asarray(offset, float))

    def subset(self, members, source: str | None = None) -> "Packing":
        """The spheres ``members`` (a bool mask or indices) of this packing, every column kept
        (a grain keeps its id; a grain cut by the subset keeps the spheres selected)."""
        return dataclasses.replace(
            self, centers=self.centers[members], radii=self.radii[members],
            grain_id=None if self.grain_id is None else self.grain_id[members],
            source=self.source if source is None else source)

    @functools.cached_property
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

    def extent(self, members=None) -> np.ndarray:
        """(2, 3) array: the bed's bounding box, lowest and highest sphere surface (m); of the
        spheres ``members`` (a bool mask or indices) only, when given."""
        c, r = ((self.centers, self.radii) if members is None
                else (self.centers[members], self.radii[members]))
        return np.stack([(c - r[:, None]).min(axis=0), (c + r[:, None]).max(axis=0)])

    @functools.cached_property
    def grain_diameters(self) -> np.ndarray:
        r"""(n_grains,) volume-equivalent diameter of each grain, :math:`(6V/\pi)^{1/3}`, m.

        A sphere's is its diameter; a multi-sphere grain's volume is that of the union of its
        spheres, by quasi-Monte Carlo (1024 scrambled Sobol points in the grain's bounding box,
        randomly shifted per grain, seed 0): about 1 % of V per grain (0.3 % of d) measured on
        dimers and 7-sphere rods, independent between grains, so a mean over n grains is good to
        about 0.3/sqrt(n) %. Grains in ``np.unique(grain_id)`` order.
        """
        if self.grain_id is None:
            return 2.0 * self.radii
        return (6.0 / np.pi * grain_volumes(self.centers, self.radii, self.grain_id)) ** (1 / 3)

    @property
    def grain_diameter(self) -> float:
        """Mean volume-equivalent grain diameter, m (the mean sphere diameter for spheres)."""
        if self.grain_id is None or self.n_grains == self.n:
            return self.mean_diameter
        return float(self.grain_diameters.mean())

    def orientation_order(self, axis: int = 2) -> float | None:
        r"""Orientation order of the grains' long axes against ``axis`` (z: vertical).

        .. math:: S = \langle \tfrac32 \cos^2\theta - \tfrac12 \rangle

        over the grains of two or more spheres, :math:`\theta` the angle between ``axis`` and
        the grain's long axis: the principal axis of largest extent of its sphere centres,
        weighted by :math:`r^3`. S = 1: all along the axis, -1/2: all normal to it, 0: random.
        None without multi-sphere grains.

        >>> rod = Packing([[0, 0, 0], [0, 0, 1], [5, 0, 0], [6, 0, 0]], [1, 1, 1, 1],
        ...               grain_id=[0, 0, 1, 1])
        >>> rod.orientation_order(axis=2)    # one vertical, one horizontal: (1 - 0.5)/2
        0.25
        """
        if self.grain_id is None:
            return None
        ids, g = np.unique(self.grain_id, return_inverse=True)
        count = np.bincount(g)
        w = self.radii**3
        wsum = np.bincount(g, w)
        mean = np.column_stack([np.bincount(g, w * self.centers[:, k]) for k in range(3)])
        mean /= wsum[:, None]
        d = self.centers - mean[g]
        gyr = np.zeros((ids.size, 3, 3))
        np.add.at(gyr, g, w[:, None, None] * d[:, :, None] * d[:, None, :])
        multi = count > 1
        if not multi.any():
            return None
        _, vec = np.linalg.eigh(gyr[multi])                     # ascending eigenvalues
        cos = vec[:, int(axis), -1]                             # long axis, component on axis
        return float(np.mean(1.5 * cos**2 - 0.5))

    @property
    def sauter_diameter(self) -> float:
        r"""Sauter mean diameter :math:`d_{32} = \sum d^3 / \sum d^2` of the grains, m."""
        if self.grain_id is None or self.n_grains == self.n:
            r = self.radii
            return float(2 * np.sum(r**3) / np.sum(r**2))
        d = self.grain_diameters
        return float(np.sum(d**3) / np.sum(d**2))


def validate_spheres(centers, radii, lines, source, *, check_duplicates=True,
                     min_spheres: int = MIN_SPHERES):
    """Check finite values, positive radii, distinct centres and at least ``min_spheres``.

    ``lines[i]`` is the row sphere i came from, counted as a spreadsheet does: the file line
    (header = row 1) of a text file, the 1-based array index of a .npz.
    """
    n = len(radii)
    if n < min_spheres:
        raise ValueError(f"{source}: too few spheres ({n}); a packing needs at least {min_spheres}")
    bad = ~np.isfinite(centers).all(axis=1) | ~np.isfinite(radii)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{source}: row {lines[i]}: non-finite value (NaN or inf) "
                         f"in x,y,z,r = {centers[i].tolist() + [float(radii[i])]}")
    bad = radii <= 0
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{source}: row {lines[i]}: radius must be > 0, got {float(radii[i])!r}")
    if check_duplicates:
        order = np.lexsort(centers.T[::-1])
        s = centers[order]
        dup = np.all(s[1:] == s[:-1], axis=1)
        if dup.any():
            k = int(np.flatnonzero(dup)[0])
            a, b = sorted((int(order[k]), int(order[k + 1])))
            raise ValueError(f"{source}: row {lines[b]}: duplicate centre {centers[b].tolist()} "
                             f"(same as row {lines[a]})")


class DegeneratePackingError(ValueError):
    """The sphere centres span less than three dimensions (coplanar or collinear): there is no
    3-D tessellation of them, an input fault (``bad_input``: exit 2 in a CLI)."""

    bad_input = True


#: Relative size (to the largest) below which a singular value of the centred coordinates
#: counts as zero in :func:`check_three_dimensional`.
FLAT_RTOL = 1e-10


def check_three_dimensional(centers, source: str = "") -> None:
    """:class:`DegeneratePackingError` when the centres (N, 3) lie in one plane or on one line.

    The rank of the centred coordinates, from their singular values (a value below
    :data:`FLAT_RTOL` times the largest counts as zero); ``source`` prefixes the message.

    >>> try:
    ...     check_three_dimensional([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    ... except DegeneratePackingError as e:
    ...     print(e)
    the sphere centres are coplanar: no 3-D tessellation
    """
    c = np.asarray(centers, dtype=float)
    s = np.linalg.svd(c - c.mean(axis=0), compute_uv=False) if c.shape[0] > 1 else np.zeros(1)
    rank = int(np.sum(s > FLAT_RTOL * s.max())) if s.max() > 0 else 0
    if rank < 3:
        shape = {2: "coplanar", 1: "collinear"}.get(rank, "all at one point")
        raise DegeneratePackingError(f"{source + ': ' if source else ''}the sphere centres are "
                                     f"{shape}: no 3-D tessellation")


def check_grains(centers, radii, grain_id, lines, source) -> None:
    """ValueError naming the grain when the spheres of one ``grain_id`` are not one body.

    A rigid multi-sphere grain is a set of overlapping spheres: the graph of overlapping pairs
    (distance < r_i + r_j) of one grain must be connected. One id on spheres far apart is an
    id mix-up (two grains numbered alike), which would merge two grains into one solid.
    """
    c = np.asarray(centers, float)
    r = np.asarray(radii, float)
    g = np.asarray(grain_id).astype(np.int64)
    pairs = spatial.cKDTree(c).query_pairs(2.0 * float(r.max()), output_type="ndarray")
    if pairs.size:
        i, j = pairs[:, 0], pairs[:, 1]
        keep = (g[i] == g[j]) & (np.linalg.norm(c[i] - c[j], axis=1) < r[i] + r[j])
        i, j = i[keep], j[keep]
    else:
        i = j = np.zeros(0, dtype=np.int64)
    n = r.size
    adj = sparse.coo_array((np.ones(i.size), (i, j)), shape=(n, n))
    _, comp = csgraph.connected_components(adj, directed=False)
    pairs_gc = np.unique(np.column_stack([g, comp]), axis=0)
    ids, counts = np.unique(pairs_gc[:, 0], return_counts=True)
    split = ids[counts > 1]
    if split.size:
        gid = int(split[0])
        rows = np.flatnonzero(g == gid)
        far = rows[comp[rows] != comp[rows[0]]][0]
        raise ValueError(f"{source}: grain_id {gid} is on spheres that do not overlap into one "
                         f"body (row {lines[rows[0]]} and row {lines[far]} are apart): two "
                         f"grains with one id?")


#: Mean grain diameters (m) outside which a packing is probably not in metres.
PLAUSIBLE_DIAMETER_M = (0.5e-3, 50e-3)


def scale_warning(packing: Packing) -> str | None:
    """A one-line warning when the mean diameter is outside 0.5-50 mm (not metres?), else None.

    >>> scale_warning(Packing(np.eye(3) * 10, np.full(3, 3.3)))[:40]
    'mean grain diameter 6.6 m is outside 0.5'
    """
    d = packing.grain_diameter
    lo, hi = PLAUSIBLE_DIAMETER_M
    if lo <= d <= hi:
        return None
    return (f"mean grain diameter {d:.3g} m is outside 0.5-50 mm, the range of grains: if the "
            f"file is not in metres, give --units mm or --units cm (a dimensionless packing "
            f"is fine with --viscosity 1)")


def grain_volumes(centers, radii, grain_id, *, points: int = 1024, rng=0) -> np.ndarray:
    """(n_grains,) volume of the union of each grain's spheres, m³ (Monte Carlo, see
    :attr:`Packing.grain_diameters`); grains in ``np.unique(grain_id)`` order.

    >>> v = grain_volumes([[0, 0, 0], [1, 0, 0]], [1.0, 1.0], [7, 7])   # two unit spheres
    >>> bool(abs(v[0] / (8 * np.pi / 3 - 5 * np.pi / 12) - 1) < 0.03)   # 2 V - lens
    True
    """
    c = np.asarray(centers, float)
    r = np.asarray(radii, float)
    ids, g = np.unique(np.asarray(grain_id), return_inverse=True)
    order = np.argsort(g, kind="stable")
    start = np.searchsorted(g[order], np.arange(ids.size))
    count = np.bincount(g, minlength=ids.size)
    lo = np.full((ids.size, 3), np.inf)
    hi = np.full((ids.size, 3), -np.inf)
    np.minimum.at(lo, g, c - r[:, None])
    np.maximum.at(hi, g, c + r[:, None])
    from scipy.stats import qmc                          # scrambled Sobol: error ~ 1/points

    u = qmc.Sobol(3, scramble=True, seed=rng).random(int(points))
    # a random shift of the point set per grain (Cranley-Patterson rotation): the grains' errors
    # are independent, so a mean over n grains is good to 1/sqrt(n) of one grain's error. The
    # shifts go to the grains in the order of their lowest corners, not of their ids: relabelled
    # grains or shuffled rows give the same volumes (by id order, k moved by 5e-4)
    rank = np.empty(ids.size, dtype=np.intp)
    rank[np.lexsort((lo[:, 2], lo[:, 1], lo[:, 0]))] = np.arange(ids.size)
    shift = np.random.default_rng(rng).random((ids.size, 3))[rank]
    vol = np.empty(ids.size)
    kmax = int(count.max())
    step = max(1, 2_000_000 // (int(points) * kmax))
    for a in range(0, ids.size, step):                 # chunks of grains, vectorised inside
        b = min(a + step, ids.size)
        frac = np.mod(u[None] + shift[a:b, None], 1.0)
        pts = lo[a:b, None] + (hi[a:b] - lo[a:b])[:, None] * frac       # (m, P, 3)
        inside = np.zeros(pts.shape[:2], dtype=bool)
        for k in range(kmax):                          # k-th sphere of each grain
            has = count[a:b] > k
            sph = order[np.minimum(start[a:b] + k, c.shape[0] - 1)]
            d2 = np.sum((pts - c[sph][:, None]) ** 2, axis=2)
            inside |= has[:, None] & (d2 < r[sph][:, None] ** 2)
        vol[a:b] = inside.mean(axis=1) * np.prod(hi[a:b] - lo[a:b], axis=1)
    one = count == 1                                   # one-sphere grains: exact
    vol[one] = 4.0 / 3.0 * np.pi * r[order[start[one]]] ** 3
    return vol
