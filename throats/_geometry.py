r"""Geometry of triangular throat cross-sections, vectorised over N throats.

A throat is the face shared by two Delaunay tetrahedra: three sphere centres with radii
``radii = [r1, r2, r3]`` and side lengths ``sides = [l12, l13, l23]`` (any consistent length
unit; column i of ``sides`` is the side between the vertices its name gives).  The face plane
cuts each sphere in a great circle, so the open (fluid) cross-section is

.. math:: \Omega = T \setminus (D_1 \cup D_2 \cup D_3),

the triangle :math:`T` minus three disks centred on its vertices.  This module holds the
input checks and the closed-form geometry of the triangle (vertices, area, canonical vertex
order, contact type); the open area and its boundary are in :mod:`throats._area` and
:mod:`throats._boundary`.
"""

from __future__ import annotations

import logging

import numpy as np

__all__ = ["as_throats", "canonical_form", "check_rows", "contact_count", "contact_type",
           "mean_radius", "triangle_area", "triangle_vertices", "validate_throats"]

logger = logging.getLogger(__name__)

#: column of ``sides`` holding the side between vertices (i, j)
PAIR_COL = {(0, 1): 0, (1, 0): 0, (0, 2): 1, (2, 0): 1, (1, 2): 2, (2, 1): 2}
#: vertex pairs in the column order of ``sides``
PAIRS = ((0, 1), (0, 2), (1, 2))
_PERMS = ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0))


def as_throats(radii, sides):
    """Convert to two float (N, 3) arrays (a single (3,) row is accepted as N = 1).

    Raises ``TypeError`` for non-numeric input and ``ValueError`` for other shapes.
    """
    try:
        r = np.atleast_2d(np.asarray(radii, dtype=float))
        s = np.atleast_2d(np.asarray(sides, dtype=float))
    except (TypeError, ValueError) as exc:
        raise TypeError(f"radii and sides must be numeric arrays: {exc}") from exc
    if r.ndim != 2 or r.shape[1] != 3 or s.shape != r.shape:
        raise ValueError(f"expected radii and sides of shape (N, 3), got {r.shape} and {s.shape}")
    return r, s


def mean_radius(radii):
    """Mean radius r̄ = (r1 + r2 + r3)/3 of each row, (N,), permutation-exact (sorted sum)."""
    r = np.atleast_2d(np.asarray(radii, dtype=float))
    if r.ndim != 2 or r.shape[1] != 3:
        r = np.sort(r, axis=1)
        return (r[:, 0] + r[:, 1] + r[:, 2]) / 3.0
    # ascending by a sorting network: np.sort's values (NaN aside), without its per-row cost
    lo1, hi1 = np.minimum(r[:, 0], r[:, 1]), np.maximum(r[:, 0], r[:, 1])
    x = np.maximum(lo1, r[:, 2])
    return (np.minimum(lo1, r[:, 2]) + np.minimum(hi1, x) + np.maximum(hi1, x)) / 3.0


def triangle_vertices(sides):
    r"""Planar vertex coordinates of N triangles, (N, 3, 2), counter-clockwise.

    Vertex 1 at the origin, vertex 2 on the +x axis, vertex 3 above it:

    .. math:: x_3 = \frac{l_{12}^2 + l_{13}^2 - l_{23}^2}{2 l_{12}},\quad
              y_3 = \sqrt{l_{13}^2 - x_3^2}.

    Parameters
    ----------
    sides : (N, 3) array_like
        ``[l12, l13, l23]`` in any length unit.

    Returns
    -------
    (N, 3, 2) ndarray, same unit as ``sides``.
    """
    s = np.atleast_2d(np.asarray(sides, dtype=float))
    l12, l13, l23 = s[:, 0], s[:, 1], s[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        x3 = (l12**2 + l13**2 - l23**2) / (2.0 * l12)
        y3 = np.sqrt(np.maximum(l13**2 - x3**2, 0.0))
    v = np.zeros((s.shape[0], 3, 2))
    v[:, 1, 0] = l12
    v[:, 2, 0] = x3
    v[:, 2, 1] = y3
    return v


def triangle_area(sides):
    """Area of N triangles from their sides, Heron's formula in Kahan's stable form.

    Parameters
    ----------
    sides : (N, 3) array_like
        Side lengths, any unit (rows that are no triangle give 0).

    Returns
    -------
    (N,) ndarray, the unit squared.

    Examples
    --------
    >>> triangle_area([[3.0, 4.0, 5.0]]).tolist()
    [6.0]
    """
    a = np.sort(np.asarray(sides, dtype=float), axis=1)[:, ::-1]  # a >= b >= c
    a, b, c = a[:, 0], a[:, 1], a[:, 2]
    prod = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c))
    return 0.25 * np.sqrt(np.maximum(prod, 0.0))


def canonical_form(radii, sides):
    r"""Scale-, permutation- and mirror-invariant form of N throats.

    Lengths are divided by the mean radius :math:`\bar r = (r_1+r_2+r_3)/3`, then the vertex
    order is chosen among the six permutations as the one whose row
    ``[r1, r2, r3, l12, l13, l23]`` is lexicographically smallest.  A throat is fixed by its
    radii and side lengths alone, so rotations, translations and mirror images of the face
    are already the same input; permutations of the vertices and uniform scaling give the
    same canonical row.

    Parameters
    ----------
    radii, sides : (N, 3) array_like, any consistent length unit
        ``[r1, r2, r3]`` and ``[l12, l13, l23]``.

    Returns
    -------
    radii_star, sides_star : (N, 3) ndarray, dimensionless (units of r̄)

    Examples
    --------
    >>> r, s = canonical_form([[2.0, 1.0, 3.0]], [[3.5, 5.0, 4.5]])
    >>> r.round(3).tolist(), s.round(3).tolist()
    ([[0.5, 1.0, 1.5]], [[1.75, 2.25, 2.5]])
    """
    r, s = as_throats(radii, sides)
    rbar = mean_radius(r)[:, None]
    r = r / rbar
    s = s / rbar
    cand = np.empty((r.shape[0], 6, 6))
    for k, (a, b, c) in enumerate(_PERMS):
        cand[:, k, 0:3] = r[:, [a, b, c]]
        cand[:, k, 3] = s[:, PAIR_COL[a, b]]
        cand[:, k, 4] = s[:, PAIR_COL[a, c]]
        cand[:, k, 5] = s[:, PAIR_COL[b, c]]
    alive = np.ones((r.shape[0], 6), dtype=bool)
    for col in range(6):
        v = np.where(alive, cand[:, :, col], np.inf)
        alive &= v == v.min(axis=1, keepdims=True)
    best = np.argmax(alive, axis=1)
    out = cand[np.arange(r.shape[0]), best]
    return out[:, :3].copy(), out[:, 3:].copy()


def contact_type(radii, sides, *, gap_tol=1e-9):
    r"""Contact type of N throats (thesis Fig. 3.17): ``'a'``, ``'b'``, ``'c'`` or ``'d'``.

    Disks i and j are in contact when their gap
    :math:`g_{ij} = l_{ij} - r_i - r_j \le` ``gap_tol`` :math:`\cdot\bar r` (touching or
    overlapping).  Zero, one, two or three pairs in contact give type a, b, c, d.

    Parameters
    ----------
    radii, sides : (N, 3) array_like
        ``[r1, r2, r3]`` and ``[l12, l13, l23]``, any consistent length unit.
    gap_tol : float, optional
        Gap (in units of r̄) still counted as touching, default 1e-9 (round-off of
        coordinates of touching spheres).

    Returns
    -------
    (N,) ndarray of str

    Examples
    --------
    >>> contact_type([[1, 1, 1], [1, 1, 1]], [[2, 2, 2], [2, 2.5, 2.5]]).tolist()
    ['d', 'b']
    """
    r, s = as_throats(radii, sides)
    return np.array(["a", "b", "c", "d"])[contact_count(r, s, mean_radius(r), gap_tol=gap_tol)]


def contact_count(r, s, rbar, *, gap_tol=1e-9):
    r"""Number of touching or overlapping disk pairs (0-3) of float (N, 3) arrays, (N,) int8.

    The rule of :func:`contact_type`: gap :math:`l_{ij} - r_i - r_j \le` ``gap_tol * rbar``.
    """
    tol = gap_tol * np.asarray(rbar, dtype=float)
    return ((s[:, 0] - r[:, 0] - r[:, 1] <= tol).astype(np.int8)
            + (s[:, 1] - r[:, 0] - r[:, 2] <= tol) + (s[:, 2] - r[:, 1] - r[:, 2] <= tol))


def validate_throats(radii, sides):
    """Row-wise checks of N throats; never raises for a bad row.

    A row is invalid when it holds NaN/inf, a radius or side <= 0, or sides that violate the
    triangle inequality or form a (nearly) collinear triangle (area <= 1e-9 * longest side²).
    Every other row is a triangle of disks and has an answer, deep overlaps included (a disk
    containing another vertex, r_i >= l_ij: open, or closed with Q* = 0).

    Parameters
    ----------
    radii, sides : (N, 3) array_like

    Returns
    -------
    ok : (N,) bool ndarray
    messages : (N,) object ndarray of str, '' where ok

    Raises
    ------
    ValueError
        If the arrays are not both of shape (N, 3) (a programming error, not a bad row).
    """
    return check_rows(*as_throats(radii, sides), deep_overlap=False)


def check_rows(r, s, *, deep_overlap):
    """``(ok, messages)`` of float (N, 3) arrays; ``deep_overlap`` also refuses r_i >= l_ij.

    Column by column (numpy's reductions over a length-3 axis are slow); the first failed
    check of a row names it.
    """
    n = r.shape[0]
    msg = np.full(n, "", dtype=object)
    bad = np.zeros(n, dtype=bool)

    def flag(mask, text):
        new = mask & ~bad
        for k in np.flatnonzero(new):  # only on bad rows, to build their messages
            msg[k] = text(k)
        np.logical_or(bad, new, out=bad)

    def cols(a, test):
        return test(a[:, 0]) | test(a[:, 1]) | test(a[:, 2])

    flag(cols(r, lambda c: ~np.isfinite(c)) | cols(s, lambda c: ~np.isfinite(c)),
         lambda k: f"non-finite value in radii {r[k].tolist()} or sides {s[k].tolist()}")
    flag(cols(r, lambda c: c <= 0), lambda k: f"radius <= 0 in radii {r[k].tolist()}")
    flag(cols(s, lambda c: c <= 0), lambda k: f"side length <= 0 in sides {s[k].tolist()}")
    with np.errstate(invalid="ignore"):
        # scaled by a power of two (exact: every comparison as in the given unit) so that the
        # longest side lies in [0.5, 1): no square or sum overflows or underflows, whatever
        # the (finite, positive) length unit; then the sorted sides by a sorting network (the
        # same values as np.sort(s, axis=1))
        top = np.max(np.where(np.isfinite(s) & (s > 0), s, 0.0), axis=1)
        q = np.ldexp(s, -np.frexp(np.where(top > 0, top, 1.0))[1][:, None])
        lo1, hi1 = np.minimum(q[:, 0], q[:, 1]), np.maximum(q[:, 0], q[:, 1])
        x = np.maximum(lo1, q[:, 2])
        lo, mid, hi = np.minimum(lo1, q[:, 2]), np.minimum(hi1, x), np.maximum(hi1, x)
        area = triangle_area(np.where(np.isfinite(q), q, 1.0))
        bad_tri = (hi >= lo + mid) | (area <= 1e-9 * hi ** 2)
    flag(bad_tri, lambda k: f"sides {s[k].tolist()} do not form a triangle "
                            "(triangle inequality violated or collinear vertices)")
    if not deep_overlap:
        return ~bad, msg
    with np.errstate(invalid="ignore"):
        deep = np.zeros(n, dtype=bool)
        for i, j in PAIRS:
            l = s[:, PAIR_COL[i, j]]
            deep |= (r[:, i] >= l) | (r[:, j] >= l)
    flag(deep, lambda k: f"a disk contains another vertex (r_i >= l_ij) in radii "
                         f"{r[k].tolist()}, sides {s[k].tolist()}: overlap too deep for a throat")
    return ~bad, msg
