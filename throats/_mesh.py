r"""Boundary construction of throat cross-sections, with the closing rules (meshing: ``_trimesh``).

All lengths here are in units of the mean radius r̄ (canonical throats).

Closing rule for narrow passages
--------------------------------
Tangent disks leave a zero-angle cusp that no mesh can fill, and gaps down to 1e-4 r̄ would
need elements that small.  The flow in a passage of width :math:`w` carries
:math:`\sim w^3` per unit length, so passages narrower than ``delta`` are closed by a short
no-slip cut where their width reaches ``delta``:

* **disk–disk passage** (pair i, j, gap :math:`g_{ij} = l_{ij} - r_i - r_j < \delta`, also
  touching or overlapping): at the height :math:`s^*` above edge ij where the distance between
  the two circles, measured parallel to the edge, equals ``delta``.  With
  :math:`D = l_{ij} - \delta`, :math:`x = (D^2 + r_i^2 - r_j^2)/(2D)`,
  :math:`s^* = \sqrt{r_i^2 - x^2}`; the region below the chord is removed.
* **disk–edge passage** (disk i and the opposite edge jk, :math:`h_i - r_i < \delta/2`, also
  when the disk crosses the edge): two cuts normal to the edge at
  :math:`\pm x^*,\ x^* = \sqrt{r_i^2 - (h_i - \delta/2)^2}` from the foot of the altitude,
  where the arc is ``delta``/2 from the symmetry line (a mirrored channel of width
  ``delta``); the region between is removed.

Both rules change the geometry continuously as a gap closes (type a → b → d), and the removed
regions lie in strips narrower than ``delta``.  The error this costs is measured in the tests
and the benchmark (``throats.bench``) against solves with a ten times smaller ``delta``.

Boundary curves are tagged by construction: pieces of the triangle edges are symmetry
(physical group ``SYMMETRY``), arcs and cuts are no-slip (group ``NOSLIP``).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ._boundary import region_boundary
from ._geometry import PAIRS, triangle_vertices

__all__ = ["DELTA_DEFAULT", "FLUID", "NOSLIP", "SYMMETRY", "ThroatGeometry", "build_geometries",
           "disk_geometry", "polygon_geometry"]

logger = logging.getLogger(__name__)

#: default width (units of r̄) below which a passage is closed by a no-slip cut
DELTA_DEFAULT = 0.01
#: second try (rows whose boundary failed): a cut lower (disk-disk) or shorter (disk-edge) than
#: this, in units of ``delta``, is not made (see :func:`build_geometries`)
CUT_MIN = 1e-2

NOSLIP, SYMMETRY, FLUID = 1, 2, 3


@dataclass(frozen=True)
class ThroatGeometry:
    """Boundary of one throat's open region, after the closing rules (units of r̄).

    Attributes
    ----------
    points : (P, 2) float
        Curve end points.
    lfs : (P,) float
        Local feature size at each point: distance to the nearest boundary piece not
        incident to it.
    curves : list of tuple
        ``(kind, i0, i1, center, radius, bc)`` with kind 'line' | 'arc', point indices,
        arc centre (2,) or None, radius, bc ``NOSLIP`` | ``SYMMETRY``; oriented with the
        fluid on the left.
    loops : list of list of int
        Closed loops of curve indices (one per connected piece of the open region).
    area : float
        Exact area of the region (after closing), from Green's theorem.
    error : str
        Why the boundary could not be assembled ('' when it could).
    """

    points: np.ndarray
    lfs: np.ndarray
    curves: list
    loops: list
    area: float
    error: str = ""


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _left(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _closing_rules(verts, radii, delta, feature_width, robust=False):
    """Cut segments and removed rectangles of the closing rules, vectorised (see module).

    ``robust`` (second try, :func:`build_geometries`): no sliver cuts (``CUT_MIN``), and a
    disk-disk cut only where the circles' radical line meets the edge inside the cut's strip.
    """
    N = verts.shape[0]
    segs_a, segs_b, owner, present = [], [], [], []
    rect = {k: [] for k in ("origin", "e", "n", "x0", "x1", "s1", "present")}
    extra_line = np.full((N, 3, 2), np.nan)   # extra breakpoints on triangle edges (feature)
    extra_circ = np.full((N, 3, 1), np.nan)   # extra breakpoints on circles (feature)
    edge_of_pair = {(0, 1): 0, (1, 2): 1, (0, 2): 2}    # CCW edge index: 1->2, 2->3, 3->1
    m = 0
    with np.errstate(invalid="ignore", divide="ignore"):
        for i, j in PAIRS:
            k = 3 - i - j
            ci, cj, ck = verts[:, i], verts[:, j], verts[:, k]
            ri, rj = radii[:, i], radii[:, j]
            length = np.linalg.norm(cj - ci, axis=1)
            e = _unit(cj - ci)
            n = _left(e)
            n = np.where((np.sum(n * (ck - ci), axis=1) < 0)[:, None], -n, n)
            dd = length - delta
            x = (dd**2 + ri**2 - rj**2) / (2 * dd)
            s1 = np.sqrt(ri**2 - x**2)
            on = (length - ri - rj < delta) & (x**2 < ri**2) & (s1 < np.minimum(ri, rj))
            if robust:
                xc = (length**2 + ri**2 - rj**2) / (2 * length)
                on &= (s1 > CUT_MIN * delta) & (xc > x + 0.05 * delta) & (xc < x + 0.95 * delta)
            a = ci + e * (x - 0.5 * delta)[:, None] + n * s1[:, None]
            b = ci + e * (x + 1.5 * delta)[:, None] + n * s1[:, None]
            # fluid (above the chord, +n) must be on the left of the direction
            flip = (np.sum(_left(e) * n, axis=1) < 0)[:, None]
            segs_a.append(np.where(flip, b, a))
            segs_b.append(np.where(flip, a, b))
            owner.append(4 + m)
            present.append(on)
            for key, val in (("origin", ci), ("e", e), ("n", n), ("x0", x), ("x1", x + delta),
                             ("s1", s1), ("present", on)):
                rect[key].append(val)
            m += 1
        for i in range(3):
            j, k = [q for q in range(3) if q != i]
            ci, cj, ck = verts[:, i], verts[:, j], verts[:, k]
            ri = radii[:, i]
            e = _unit(ck - cj)
            foot = cj + e * np.sum((ci - cj) * e, axis=1)[:, None]
            h = np.linalg.norm(ci - foot, axis=1)
            n = _unit(ci - foot)
            xs = np.sqrt(ri**2 - (h - 0.5 * delta) ** 2)
            on = (h - ri < 0.5 * delta) & np.isfinite(xs)
            if robust:
                on &= xs > CUT_MIN * delta
            lo, hi = -0.5 * delta, min(delta, 1.0)
            # orient each cut so that the fluid (x > x* on the right cut, x < -x* on the
            # left one) is on its left; whether the left normal of +n is +e depends on the
            # vertex (the frame (e, n) flips handedness for i = 1)
            plus_e_left = (np.sum(_left(n) * e, axis=1) > 0)[:, None]
            for sign in (1.0, -1.0):
                low = foot + e * (sign * xs)[:, None] + n * lo
                high = foot + e * (sign * xs)[:, None] + n * hi
                up = plus_e_left if sign > 0 else ~plus_e_left   # direction +n
                segs_a.append(np.where(on[:, None], np.where(up, low, high), 0.0))
                segs_b.append(np.where(on[:, None], np.where(up, high, low), 0.0))
                owner.append(4 + m)
                present.append(on)
            for key, val in (("origin", foot), ("e", e), ("n", n), ("x0", -xs), ("x1", xs),
                             ("s1", h), ("present", on)):
                rect[key].append(val)
            m += 1
            # feature points of a narrow (not closed) disk-edge passage: foot of the altitude
            narrow = ~on & (h - ri < feature_width)
            edge = edge_of_pair[(min(j, k), max(j, k))]
            va = verts[:, [0, 1, 2][edge]]
            vb = verts[:, [1, 2, 0][edge]]
            t = np.sum((foot - va) * _unit(vb - va), axis=1) / np.linalg.norm(vb - va, axis=1)
            extra_line[:, edge, 0] = np.where(narrow, t, np.nan)
            th = np.arctan2(-n[:, 1], -n[:, 0])
            extra_circ[:, i, 0] = np.where(narrow, np.mod(-th, 2 * np.pi) / (2 * np.pi), np.nan)
    rects = {k: np.stack(v, axis=1) for k, v in rect.items()}
    return (np.stack(segs_a, axis=1), np.stack(segs_b, axis=1), np.array(owner),
            np.stack(present, axis=1), rects, extra_line, extra_circ)


def build_geometries(radii_star, sides_star, *, delta=DELTA_DEFAULT, feature_width=0.3):
    """Boundary curves of N canonical throats after the closing rules.

    Parameters
    ----------
    radii_star, sides_star : (N, 3) array_like
        Throats in units of r̄ (see :func:`throats.canonical_form`).
    delta : float, optional
        Passage width (units of r̄) below which a passage is closed (module docstring).
    feature_width : float, optional
        Disk–edge passages narrower than this get a mesh point at their narrowest place.

    Returns
    -------
    list of ThroatGeometry (length N); a throat whose disks cover the triangle has no loops
    and area 0.

    Notes
    -----
    Rows whose boundary cannot be assembled are built a second time with ``robust`` rules:
    no cut lower/shorter than ``CUT_MIN * delta`` (a gap exactly ``delta`` gave a 1e-8 sliver
    cut), and no disk-disk cut where the circles cross at a wide angle (deep overlaps; the
    cut is meant for cusps, whose corner lies inside the cut's strip).  Rows that succeed the
    first time keep their geometry bit for bit.
    """
    r = np.atleast_2d(np.asarray(radii_star, dtype=float))
    s = np.atleast_2d(np.asarray(sides_star, dtype=float))
    verts = triangle_vertices(s)
    out = _geometries(verts, r, delta, feature_width, False)
    again = [q for q, g in enumerate(out) if g.error]
    if again:   # second try for these rows only: the others keep their first geometry
        for q, g in zip(again, _geometries(verts[again], r[again], delta, feature_width, True)):
            out[q] = g if not g.error else out[q]
    return out


def _geometries(verts, r, delta, feature_width, robust):
    la, lb, owner, present, rects, xl, xc = _closing_rules(verts, r, delta, feature_width,
                                                           robust)
    res = region_boundary(verts, verts, r, la, lb, owner, present, rects,
                          extra_lt=xl, extra_cu=xc)
    return [extract_section(res, verts, r, q) for q in range(r.shape[0])]


def extract_section(res, verts, radii, q):
    """Pieces of throat q → points, curves, loops (small per-throat work)."""
    tol = 1e-9
    pieces = []   # (kind, p0, p1, center, radius, bc)
    lt, lon = res["lt"][q], res["lon"][q]
    la, lb, own = res["la"][q], res["lb"][q], res["lowner"]
    for li, ki in zip(*np.nonzero(lon)):
        d = lb[li] - la[li]
        p0 = la[li] + lt[li, ki] * d
        p1 = la[li] + lt[li, ki + 1] * d
        pieces.append(("line", p0, p1, None, 0.0, SYMMETRY if own[li] == 0 else NOSLIP))
    cu, con = res["cu"][q], res["con"][q]
    for ci, ki in zip(*np.nonzero(con)):
        c, rad = verts[q, ci], radii[q, ci]
        th0, th1 = -2 * np.pi * cu[ci, ki], -2 * np.pi * cu[ci, ki + 1]
        nsub = int(np.ceil(abs(th1 - th0) / (0.5 * np.pi)))   # gmsh arcs must be < pi
        ths = np.linspace(th0, th1, nsub + 1)
        for a, b in zip(ths[:-1], ths[1:]):
            pieces.append(("arc", c + rad * np.array([np.cos(a), np.sin(a)]),
                           c + rad * np.array([np.cos(b), np.sin(b)]), c, rad, NOSLIP))
    # drop degenerate pieces, snap end points
    pieces = [p for p in pieces if np.linalg.norm(p[2] - p[1]) > tol]
    if not pieces:
        return ThroatGeometry(np.zeros((0, 2)), np.zeros(0), [], [], float(res["area"][q]))
    ends = np.array([[p[1], p[2]] for p in pieces]).reshape(-1, 2)
    pts, idx = _snap(ends, 1e-8)
    idx = idx.reshape(-1, 2)
    curves = [(p[0], int(i0), int(i1), p[3], p[4], p[5]) for p, (i0, i1) in zip(pieces, idx)]
    try:
        loops = _chain(idx)
    except ValueError as exc:
        return ThroatGeometry(pts, np.zeros(len(pts)), curves, [], float(res["area"][q]),
                              error=str(exc))
    lfs = _local_feature_size(pts, curves)
    return ThroatGeometry(pts, lfs, curves, loops, float(res["area"][q]))


def _snap(x, tol):
    """Merge points closer than tol; returns unique points and the index of each input."""
    n = x.shape[0]
    idx = -np.ones(n, dtype=int)
    out = []
    for a in range(n):
        if idx[a] >= 0:
            continue
        close = np.flatnonzero((np.abs(x - x[a]).max(axis=1) < tol) & (idx < 0))
        idx[close] = len(out)
        out.append(x[a])
    return np.array(out), idx


def _chain(idx):
    """Closed loops from directed pieces (start, end); raises ValueError if not manifold."""
    starts = {}
    for c, (a, _) in enumerate(idx):
        if a in starts:
            raise ValueError("boundary is not a simple closed curve (two pieces leave one point)")
        starts[a] = c
    used = np.zeros(len(idx), dtype=bool)
    loops = []
    for c0 in range(len(idx)):
        if used[c0]:
            continue
        loop, c = [], c0
        while not used[c]:
            used[c] = True
            loop.append(c)
            nxt = starts.get(idx[c][1])
            if nxt is None:
                raise ValueError("boundary loop does not close")
            c = nxt
        if c != c0:
            raise ValueError("boundary loop does not close on its start")
        loops.append(loop)
    return loops


def _local_feature_size(pts, curves):
    """Distance from each point to the nearest boundary curve not incident to it."""
    P = pts.shape[0]
    dist = np.full((P, len(curves)), np.inf)
    for c, (kind, i0, i1, cen, rad, _) in enumerate(curves):
        a, b = pts[i0], pts[i1]
        if kind == "line":
            d = b - a
            t = np.clip(((pts - a) @ d) / (d @ d), 0.0, 1.0)
            dist[:, c] = np.linalg.norm(pts - (a + t[:, None] * d), axis=1)
        else:
            # clockwise arc from a to b
            tha = np.arctan2(*(a - cen)[::-1])
            thp = np.arctan2(pts[:, 1] - cen[1], pts[:, 0] - cen[0])
            span = np.mod(tha - np.arctan2(*(b - cen)[::-1]), 2 * np.pi)
            within = np.mod(tha - thp, 2 * np.pi) <= span
            d_arc = np.abs(np.linalg.norm(pts - cen, axis=1) - rad)
            d_end = np.minimum(np.linalg.norm(pts - a, axis=1), np.linalg.norm(pts - b, axis=1))
            dist[:, c] = np.where(within, d_arc, d_end)
        dist[[i0, i1], c] = np.inf
    return dist.min(axis=1) if len(curves) else np.zeros(P)


def disk_geometry(radius=1.0):
    """A full disk duct (no-slip all round), for analytic checks: Q* = π R⁴/8."""
    th = -0.5 * np.pi * np.arange(4)
    pts = radius * np.stack([np.cos(th), np.sin(th)], axis=1)
    curves = [("arc", k, (k + 1) % 4, np.zeros(2), float(radius), NOSLIP) for k in range(4)]
    return ThroatGeometry(pts, np.full(4, np.inf), curves, [[0, 1, 2, 3]],
                          float(np.pi * radius**2))


def polygon_geometry(vertices):
    """A polygonal duct (no-slip on every side), for analytic checks.

    ``vertices`` (P, 2) counter-clockwise; an equilateral triangle of side a has
    Q* = √3 a⁴/320.
    """
    v = np.asarray(vertices, dtype=float)
    n = v.shape[0]
    curves = [("line", k, (k + 1) % n, None, 0.0, NOSLIP) for k in range(n)]
    area = 0.5 * float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
    return ThroatGeometry(v, np.full(n, np.inf), curves, [list(range(n))], area)
