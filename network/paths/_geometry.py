r"""Geometry of a path: angles, lengths, smoothing, tortuosity (thesis Eqs. 3.25-3.27), the bed
depth, and the full and open areas of the triangles a path crosses (Eqs. 3.18, 3.23, 3.24).

A path is a polyline of face centroids (thesis Fig. 3.9); its tortuosity is its length over the
bed depth, raw or with sharp turns smoothed by the logistic factor of Eq. 3.26 (Sobieski et
al. 2012). Open areas are ``throats.open_area`` (exact with overlapping grains).
"""

from __future__ import annotations

import numpy as np
from throats import open_area  # the throats package owns the exact open area

from ..pores import axis_index

#: Coefficients of the smoothing factor, Eq. 3.26 (thesis: omega_a = 0.1, omega_b = 90 deg).
OMEGA_A = 0.1
OMEGA_B_DEG = 90.0


# --------------------------------------------------------------------------------------------
# geometry of a polyline: angles, smoothing, tortuosity (Eqs. 3.25-3.27)
# --------------------------------------------------------------------------------------------
def as_points(points):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("points must be finite")
    return p


def interior_angles(points, *, rule="eq3.25"):
    r"""Angle :math:`\omega_i` at each interior point of a polyline, degrees (Eq. 3.25).

    .. math:: \cos\omega_i = \frac{a_i^2 + b_i^2 - c_i^2}{2 a_i b_i}

    with :math:`a_i, b_i` the segments before and after point *i* and :math:`c_i` the chord
    from point *i-1* to *i+1*: 180° is a straight continuation, 0° a full reversal.

    Parameters
    ----------
    points : (n, 3) array_like, m
        Path points (face centroids), n >= 2.
    rule : {'eq3.25', 'appendix-d'}, optional
        ``'eq3.25'`` (default) is :math:`\arccos` of the expression. ``'appendix-d'``
        reproduces the script of thesis Appendix D, which omits the arccos: it takes
        :math:`\omega = (180/3.14)\cos\omega` and adds 180 when that is negative. Use it only
        to reproduce the thesis's smoothed tortuosities.

    Returns
    -------
    (n - 2,) ndarray, degrees
        Zero-length segments (repeated points) count as straight (180°).

    Examples
    --------
    >>> interior_angles([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0]]).round(6).tolist()
    [180.0, 90.0]
    """
    p = as_points(points)
    if p.shape[0] < 3:
        return np.zeros(0)
    a = p[1:-1] - p[:-2]
    b = p[2:] - p[1:-1]
    la, lb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        # (a^2 + b^2 - c^2) / (2ab) with c = a + b  is  -a.b / (|a||b|)
        cos_w = -np.einsum("ij,ij->i", a, b) / (la * lb)
    cos_w = np.clip(np.where(np.isfinite(cos_w), cos_w, -1.0), -1.0, 1.0)
    if rule == "eq3.25":
        return np.degrees(np.arccos(cos_w))
    if rule == "appendix-d":
        w = cos_w * (180.0 / 3.14)
        return np.where(w < 0, 180.0 + w, w)
    raise ValueError(f"unknown angle rule {rule!r}; expected 'eq3.25' or 'appendix-d'")


def turning_angles(points):
    r"""Local turning angle at each interior point, :math:`180° - \omega_i`, degrees.

    0° is straight on, 90° a right-angle turn (thesis Fig. 4.6 plots these).

    Examples
    --------
    >>> turning_angles([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0]]).round(6).tolist()
    [0.0, 90.0]
    """
    return 180.0 - interior_angles(points)


def smoothing_factor(omega_deg, *, omega_a=OMEGA_A, omega_b_deg=OMEGA_B_DEG):
    r"""Length correction factor of a sharp turn, Eq. 3.26 (Sobieski et al. 2012).

    .. math:: \omega^{cor} = \frac{\exp(\omega_a(\omega - \omega_b))}
                                  {1 + \exp(\omega_a(\omega - \omega_b))}

    A logistic function of the interior angle :math:`\omega` (degrees): about 1 for a straight
    continuation (180°), 1/2 at :math:`\omega_b`, about 0 for a reversal (0°).

    Parameters
    ----------
    omega_deg : array_like, degrees
    omega_a : float, optional
        Steepness, 1/degree (thesis: 0.1).
    omega_b_deg : float, optional
        Midpoint, degrees (thesis: 90).

    Returns
    -------
    ndarray, dimensionless in (0, 1)

    Examples
    --------
    >>> float(smoothing_factor(90.0))
    0.5
    """
    x = omega_a * (np.asarray(omega_deg, dtype=float) - omega_b_deg)
    return 0.5 * (1.0 + np.tanh(0.5 * x))  # = e^x / (1 + e^x), without overflow


def path_length(points):
    """Length of a polyline, sum of its segments, m.

    Examples
    --------
    >>> float(path_length([[0, 0, 0], [3, 4, 0], [3, 4, 1]]))
    6.0
    """
    p = as_points(points)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def smoothed_length(points, *, omega_a=OMEGA_A, omega_b_deg=OMEGA_B_DEG, rule="eq3.25"):
    r"""Length of a polyline with its sharp turns replaced by arcs, Eq. 3.27, m.

    .. math:: L^{cor} = \tfrac12 (a_1 + b_{n}) + \sum_{i=2}^{n-1} \tfrac12 (a_i + b_i)\,
              \omega_i^{cor}

    :math:`a_i, b_i` are the segments before and after interior point *i* (so
    :math:`a_1` is the first segment and :math:`b_n` the last), :math:`\omega_i^{cor}` the
    factor of :func:`smoothing_factor` at the angle of :func:`interior_angles`. A straight
    polyline keeps its length (factor 1 at 180°, up to :math:`e^{-9}`).

    Parameters
    ----------
    points : (n, 3) array_like, m
    omega_a, omega_b_deg : float, optional
        Eq. 3.26 coefficients (0.1, 90°).
    rule : {'eq3.25', 'appendix-d'}, optional
        Angle rule, see :func:`interior_angles`.

    Returns
    -------
    float, m
    """
    p = as_points(points)
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    if seg.size <= 1:
        return float(seg.sum())
    cor = smoothing_factor(interior_angles(p, rule=rule), omega_a=omega_a, omega_b_deg=omega_b_deg)
    return float(0.5 * (seg[0] + seg[-1]) + np.sum(0.5 * (seg[:-1] + seg[1:]) * cor))


def bed_depth(centers, radii, axis="z"):
    """Bed depth along ``axis``: centre span plus the mean diameter, m (Appendix D's L0).

    Appendix D divides the path length by ``max(z) - min(z) + 0.0065`` (centre span plus a
    6.5 mm mean diameter); this is the same with the packing's own mean diameter.
    """
    c = np.asarray(centers, dtype=float)
    ax = axis_index(axis)
    return float(np.ptp(c[:, ax]) + 2.0 * np.mean(radii))


def plane_axes(ax):
    return [i for i in range(3) if i != ax]



#: Exit faces of a path tetrahedron [b0, b1, b2, n] (inlet face b0 b1 b2), Appendix D's order.
EXIT_FACES = np.array([[0, 1, 3], [0, 2, 3], [1, 2, 3]])
#: The inlet vertex left behind by each exit face.
LEFT_BEHIND = np.array([2, 1, 0])


def face_areas(points, radii, triangles):
    """Full (Heron, Eq. 3.18) and open (Eq. 3.23, exact) areas of triangles of sphere centres.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    triangles : (..., 3) int array_like
        Sphere indices.

    Returns
    -------
    full_m2, open_m2 : (...) ndarrays, m²
        The open area comes from ``throats.open_area`` (0 when the disks cover the triangle;
        NaN for a degenerate triangle, which the path rules treat as closed).
    """
    tri = np.asarray(triangles, dtype=np.intp)
    shape = tri.shape[:-1]
    t = tri.reshape(-1, 3)
    x = np.asarray(points, dtype=float)[t]
    r = np.asarray(radii, dtype=float)[t]
    sides = np.column_stack([np.linalg.norm(x[:, 1] - x[:, 0], axis=1),
                             np.linalg.norm(x[:, 2] - x[:, 0], axis=1),
                             np.linalg.norm(x[:, 2] - x[:, 1], axis=1)])
    full = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    if t.shape[0] == 0:
        return full.reshape(shape), full.reshape(shape)
    with np.errstate(invalid="ignore"):
        opened = open_area(r, sides)
    return full.reshape(shape), opened.reshape(shape)

