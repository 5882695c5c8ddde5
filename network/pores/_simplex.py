r"""Tetrahedron geometry in closed form, row by row: lengths, edge determinants, circumcentres.

numpy's batched ``linalg.det`` and ``linalg.solve`` factor every 3x3 matrix by LAPACK's LU one
call at a time; for the 124 000 tetrahedra of a 20 000-sphere packing that is 38 ms (det) and
65 ms (solve), where the cofactor forms below take a few vector operations (measured in
``docs/network-bench.md``). Their round-off is that of a 3x3 cofactor expansion,
a few units in the last place of :math:`|e_1||e_2||e_3|`, as LU's is; the results differ from
LAPACK's in the last bits only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CHUNK", "circumcentres", "column_norm", "cross_components", "edge_determinants",
           "pair_distances"]

#: rows per chunk of vectorised geometry (bounds the temporaries at a million centres)
CHUNK = 262_144


def column_norm(v) -> np.ndarray:
    """Lengths of vectors stored by component, ``v[0], v[1], v[2]`` (M,) each (a (3, M) array,
    or ``w.T`` of an (M, 3) one): :math:`\\sqrt{v_x^2 + v_y^2 + v_z^2}`, the bits of
    ``np.linalg.norm(w, axis=1)`` without its slow reduction over a length-3 axis."""
    return np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def pair_distances(a, ia, b, ib) -> np.ndarray:
    """Distances :math:`|a_{i_a} - b_{i_b}|` of M index pairs, ``a`` and ``b`` points stored by
    component ((3, N) rows), ``ia``, ``ib`` (M,): :func:`column_norm` of the gathered
    differences, in :data:`CHUNK` pieces, so that the (3, piece) temporaries stay in cache
    instead of being page-faulted afresh (the same values as in one piece)."""
    out = np.empty(len(ia))
    for lo in range(0, len(ia), CHUNK):
        hi = lo + CHUNK
        out[lo:hi] = column_norm(a[:, ia[lo:hi]] - b[:, ib[lo:hi]])
    return out


def cross_components(u, v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cross product :math:`u \\times v` of vectors stored by component (``u[0], u[1], u[2]``,
    (M,) each): its three components."""
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def _edges(pts: np.ndarray, simp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Edge vectors e_i = v_i - v_0 as (3 components, 3 edges, M) and v_0 as (3, M): the
    component-major layout in which each vector operation runs over contiguous memory."""
    x = pts.T[:, simp]                                          # (3, M, 4)
    e = np.ascontiguousarray((x[:, :, 1:] - x[:, :, :1]).transpose(0, 2, 1))
    return e, x[:, :, 0]


def edge_determinants(pts: np.ndarray, simp: np.ndarray) -> np.ndarray:
    r"""Determinants :math:`D = e_1 \cdot (e_2 \times e_3)` of the edge vectors
    :math:`e_i = v_i - v_0` of the tetrahedra ``simp`` (M, 4) of the points ``pts`` (N, 3):
    six times the signed volume (length³)."""
    e, _ = _edges(pts, simp)
    c23 = cross_components(e[:, 1], e[:, 2])
    return e[0, 0] * c23[0] + e[1, 0] * c23[1] + e[2, 0] * c23[2]


def circumcentres(pts: np.ndarray, simp: np.ndarray, *,
                  flat_tol: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    r"""Circumcentres (M, 3) and edge determinants (M,) of the tetrahedra ``simp`` (M, 4) of
    the points ``pts`` (N, 3).

    The centre :math:`c` solves :math:`2\,e_i \cdot (c - v_0) = |e_i|^2`, i = 1..3; by
    Cramer's rule

    .. math:: c = v_0 + \frac{|e_1|^2\, e_2 \times e_3 + |e_2|^2\, e_3 \times e_1
                             + |e_3|^2\, e_1 \times e_2}{2 D},
              \qquad D = e_1 \cdot (e_2 \times e_3).

    NaN where the tetrahedron is flat: :math:`|D| \le` ``flat_tol`` :math:`(\sum_i
    |e_i|^2 / 3)^{3/2}` (0: only where D is exactly 0).
    """
    e, v0 = _edges(pts, simp)
    a, b, c = e[:, 0], e[:, 1], e[:, 2]
    c23, c31, c12 = cross_components(b, c), cross_components(c, a), cross_components(a, b)
    det = a[0] * c23[0] + a[1] * c23[1] + a[2] * c23[2]
    n1, n2, n3 = (e * e).sum(axis=0)
    if flat_tol > 0:
        ok = np.abs(det) > flat_tol * np.maximum(((n1 + n2 + n3) / 3.0) ** 1.5, 1e-300)
    else:
        ok = det != 0
    with np.errstate(divide="ignore", invalid="ignore"):
        two_d = np.where(ok, 2.0 * det, np.nan)
        out = np.stack([(n1 * c23[k] + n2 * c31[k] + n3 * c12[k]) / two_d + v0[k]
                        for k in range(3)], axis=1)
    return out, det
