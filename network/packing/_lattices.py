r"""Regular sphere arrays (simple cubic, BCC, FCC) of a given solid fraction.

These are the packings whose exact Stokes permeability is published (see
:mod:`network.validation`), so they are the validation cases of the network
model. A box of ``n x n x n`` cubic cells of lattice constant :math:`a` holds
:math:`m n^3` spheres (:math:`m` = 1, 2, 4 spheres per cell for SC, BCC, FCC),
all of one radius fixed by the solid fraction

.. math:: \phi = m \, \tfrac{4}{3} \pi r^3 / a^3
          \quad\Longrightarrow\quad
          r = a \left( \frac{3 \phi}{4 \pi m} \right)^{1/3}.

Neighbouring spheres touch when :math:`2r` equals the nearest-neighbour distance
(:math:`a`, :math:`\sqrt{3}a/2`, :math:`a/\sqrt{2}`), i.e. at the close-packing
fractions

========  ==========================  ===========
lattice   touching fraction            value
========  ==========================  ===========
``sc``    :math:`\pi/6`                0.5235988
``bcc``   :math:`\sqrt{3}\pi/8`        0.6801747
``fcc``   :math:`\sqrt{2}\pi/6`        0.7404805
========  ==========================  ===========

Exact lattices are the worst case for a Delaunay tessellation (8, 8+6 or 12+6
co-spherical centres per empty sphere); a seeded ``jitter`` moves each centre
by a small Gaussian displacement to break those ties reproducibly.

Functions
---------
lattice_radius(kind, solid_fraction, *, lattice_constant_m=1.0)
lattice_packing(kind, solid_fraction, *, n_cells=4, lattice_constant_m=1e-3, ...)
"""

from __future__ import annotations

import logging
import math

import numpy as np

__all__ = [
    "LATTICES",
    "TOUCHING_FRACTION",
    "SPHERES_PER_CELL",
    "lattice_basis",
    "lattice_radius",
    "lattice_packing",
]

logger = logging.getLogger(__name__)

#: Supported lattice names.
LATTICES = ("sc", "bcc", "fcc")

#: Solid fraction at which nearest neighbours touch (close packing of the lattice).
TOUCHING_FRACTION = {
    "sc": math.pi / 6.0,
    "bcc": math.sqrt(3.0) * math.pi / 8.0,
    "fcc": math.sqrt(2.0) * math.pi / 6.0,
}

_BASIS = {
    "sc": ((0.0, 0.0, 0.0),),
    "bcc": ((0.0, 0.0, 0.0), (0.5, 0.5, 0.5)),
    "fcc": ((0.0, 0.0, 0.0), (0.5, 0.5, 0.0), (0.5, 0.0, 0.5), (0.0, 0.5, 0.5)),
}

#: Number of spheres per cubic cell.
SPHERES_PER_CELL = {k: len(v) for k, v in _BASIS.items()}

#: Nearest-neighbour distance in units of the lattice constant.
_NEAREST = {"sc": 1.0, "bcc": math.sqrt(3.0) / 2.0, "fcc": 1.0 / math.sqrt(2.0)}


def _check_kind(kind: str) -> str:
    if not isinstance(kind, str):
        raise TypeError(f"lattice kind must be a str, got {type(kind).__name__}")
    k = kind.lower()
    if k not in LATTICES:
        raise ValueError(f"unknown lattice {kind!r}; expected one of {LATTICES}")
    return k


def lattice_basis(kind: str) -> np.ndarray:
    """Fractional coordinates of the spheres in one cubic cell, shape (m, 3).

    Parameters
    ----------
    kind : {'sc', 'bcc', 'fcc'}

    Examples
    --------
    >>> lattice_basis('bcc')
    array([[0. , 0. , 0. ],
           [0.5, 0.5, 0.5]])
    """
    return np.array(_BASIS[_check_kind(kind)], dtype=float)


def lattice_radius(kind: str, solid_fraction: float, *, lattice_constant_m: float = 1.0) -> float:
    r"""Sphere radius (m) giving ``solid_fraction`` in a lattice of constant ``a``.

    .. math:: r = a \left( 3 \phi / (4 \pi m) \right)^{1/3}

    Parameters
    ----------
    kind : {'sc', 'bcc', 'fcc'}
    solid_fraction : float
        :math:`\phi`, in (0, touching fraction of the lattice].
    lattice_constant_m : float, m
        Edge of the cubic cell (default 1.0).

    Raises
    ------
    ValueError
        Fraction out of (0, touching] (a 1e-4 relative excess, as in a published 0.5236 for
        pi/6, is tolerated and
        clipped), or a non-positive lattice constant.

    Examples
    --------
    Touching simple-cubic spheres have diameter ``a``:

    >>> round(lattice_radius('sc', TOUCHING_FRACTION['sc']), 12)
    0.5
    """
    k = _check_kind(kind)
    phi = float(solid_fraction)
    a = float(lattice_constant_m)
    if not (math.isfinite(a) and a > 0):
        raise ValueError("lattice_constant_m must be positive and finite, "
                         f"got {lattice_constant_m!r}")
    phi_max = TOUCHING_FRACTION[k]
    if not (math.isfinite(phi) and 0.0 < phi <= phi_max * (1.0 + 1e-4)):
        raise ValueError(
            f"solid_fraction must be in (0, {phi_max:.7f}] for {k} (touching), "
            f"got {solid_fraction!r}"
        )
    phi = min(phi, phi_max)
    r = a * (3.0 * phi / (4.0 * math.pi * SPHERES_PER_CELL[k])) ** (1.0 / 3.0)
    # at exactly touching, snap to half the nearest-neighbour distance (round-off)
    return min(r, 0.5 * _NEAREST[k] * a)


def lattice_packing(
    kind: str,
    solid_fraction: float,
    *,
    n_cells: int | tuple[int, int, int] = 4,
    lattice_constant_m: float = 1e-3,
    origin_m=(0.0, 0.0, 0.0),
    include_far_faces: bool = False,
    jitter: float = 0.0,
    rng: np.random.Generator | int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Sphere centres and radii of an SC/BCC/FCC array filling ``n_cells`` cubic cells.

    Sphere centres are :math:`\mathbf{x} = \mathbf{o} + a(\mathbf{i} + \mathbf{b})`
    for integer cell indices :math:`0 \le i_\alpha < n_\alpha` and basis vectors
    :math:`\mathbf{b}` (:func:`lattice_basis`), so the box
    :math:`[o, o + n a)` holds exactly :math:`m n_x n_y n_z` spheres and tiles
    space periodically. With ``include_far_faces`` the lattice points on the far
    faces (fractional coordinate equal to :math:`n_\alpha`) are added too, making
    the array mirror-symmetric about the box centre (a BCC box of 2 cells then
    has 27 + 8 = 35 spheres).

    Parameters
    ----------
    kind : {'sc', 'bcc', 'fcc'}
    solid_fraction : float
        :math:`\phi` in (0, touching]; see :data:`TOUCHING_FRACTION`.
    n_cells : int or (3,) ints, keyword-only
        Cells along x, y, z (default 4).
    lattice_constant_m : float, m, keyword-only
        Cubic cell edge :math:`a` (default 1e-3 m).
    origin_m : (3,) array_like, m, keyword-only
        Position of the first lattice point (default the origin).
    include_far_faces : bool, keyword-only
        Also place spheres on the far faces of the box (default False).
    jitter : float, keyword-only
        Standard deviation of an independent Gaussian displacement of every
        centre coordinate, in units of :math:`a` (default 0: exact lattice).
        Radii are not changed, so near touching a jitter lets spheres overlap
        slightly (by about ``jitter * a``).
    rng : numpy.random.Generator, int or None, keyword-only
        Source of the jitter (an int is a seed). Ignored when ``jitter == 0``.

    Returns
    -------
    centers : (N, 3) ndarray, m
    radii : (N,) ndarray, m

    Raises
    ------
    ValueError
        Bad kind, fraction, cell counts, lattice constant, origin or jitter.

    Examples
    --------
    >>> c, r = lattice_packing('fcc', 0.5, n_cells=3)
    >>> c.shape, r.shape
    ((108, 3), (108,))
    >>> round(float(4 * (4 / 3) * np.pi * r[0] ** 3 / 1e-3 ** 3), 12)
    0.5
    """
    k = _check_kind(kind)
    r = lattice_radius(k, solid_fraction, lattice_constant_m=lattice_constant_m)
    a = float(lattice_constant_m)
    n = np.broadcast_to(np.asarray(n_cells), (3,))
    if not np.issubdtype(n.dtype, np.integer) or np.any(n < 1):
        raise ValueError(f"n_cells must be a positive int or three positive ints, got {n_cells!r}")
    origin = np.asarray(origin_m, dtype=float)
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise ValueError(f"origin_m must be 3 finite numbers, got {origin_m!r}")
    jitter = float(jitter)
    if not (math.isfinite(jitter) and jitter >= 0.0):
        raise ValueError(f"jitter must be >= 0 (units of the lattice constant), got {jitter!r}")

    extra = 1 if include_far_faces else 0
    axes = [np.arange(int(ni) + extra, dtype=float) for ni in n]
    cells = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    basis = lattice_basis(k)
    frac = (cells[:, None, :] + basis[None, :, :]).reshape(-1, 3)
    keep = np.all(frac <= n[None, :] + 1e-9, axis=1)
    if not include_far_faces:
        keep &= np.all(frac < n[None, :] - 1e-9, axis=1)
    frac = frac[keep]
    centers = origin[None, :] + a * frac
    if jitter > 0.0:
        gen = np.random.default_rng(rng)
        centers = centers + gen.normal(0.0, jitter * a, size=centers.shape)
    radii = np.full(centers.shape[0], r)
    logger.debug("%s lattice: %d spheres, phi=%.4f, r=%.4g m", k, centers.shape[0],
                 solid_fraction, r)
    return centers, radii
