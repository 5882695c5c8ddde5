r"""Step-increment paths built tetrahedron by tetrahedron, as the thesis does (3.4.1, after
Sobieski et al. 2012; Appendices D, E): tetrahedra are built sphere by sphere upward from the
three spheres nearest to the entry point, leaving each through the exit face of largest
(smallest) open area :math:`S_f` (Eq. 3.23), with the thesis's two reselection rules.

Where section 3.4.1 and the scripts of Appendices D-E can be read two ways, :class:`BuildRules`
names both readings; its defaults are the ones docs/airpaths.md argues for and measures.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from .._deferred import spatial
from ..pores import axis_index
from ._geometry import EXIT_FACES, LEFT_BEHIND, as_points, bed_depth, face_areas, plane_axes
from ._record import path_record

logger = logging.getLogger(__name__)


def eq323_area(points, radii, triangles):
    r"""Open area of triangles of sphere centres as Eq. 3.23 writes it, m² (may be negative).

    .. math:: S_f = S_\triangle - \sum_{i=1}^{3} \tfrac12 \theta_i r_i^2

    the triangle (Heron, Eq. 3.18) less the three disk sectors at its corners (Eq. 3.22,
    :math:`\theta_i` the corner angle). Two overlapping disks make the lens between them count
    twice, so the result can be negative (Fig. 3.8); ``throats.open_area`` is the exact area.

    Examples
    --------
    >>> a = 2 * np.sqrt(3.0)                 # equilateral, side 2 sqrt(3), unit disks
    >>> pts = [[0, 0, 0], [a, 0, 0], [a / 2, 3.0, 0]]
    >>> round(float(eq323_area(pts, [1.0, 1.0, 1.0], [[0, 1, 2]])[0]), 6)  # 3 sqrt 3 - pi / 2
    3.625356
    """
    x = np.asarray(points, dtype=float)[np.asarray(triangles)]  # (..., 3, 3)
    r = np.asarray(radii, dtype=float)[np.asarray(triangles)]
    full = 0.5 * np.linalg.norm(np.cross(x[..., 1, :] - x[..., 0, :],
                                         x[..., 2, :] - x[..., 0, :]), axis=-1)
    sectors = 0.0
    for i in range(3):  # the three corners
        u = x[..., (i + 1) % 3, :] - x[..., i, :]
        v = x[..., (i + 2) % 3, :] - x[..., i, :]
        cos = np.einsum("...j,...j->...", u, v) / (np.linalg.norm(u, axis=-1)
                                                   * np.linalg.norm(v, axis=-1))
        sectors = sectors + 0.5 * np.arccos(np.clip(cos, -1.0, 1.0)) * r[..., i] ** 2
    return full - sectors


def eq323_negative(points, radii, triangles):
    r"""Reselection rule 2 of the thesis: is Eq. 3.23 negative for these triangles?

    Appendix D: ``if ai1<0 || ai2<0 || ai3<0``, a grain reaching into the exit triangle
    (Fig. 3.8); see :func:`eq323_area`.
    """
    return eq323_area(points, radii, triangles) < 0


@dataclasses.dataclass(frozen=True, kw_only=True)
class BuildRules:
    """How :func:`build_paths` reads the steps of thesis 3.4.1 that allow two readings.

    Each default is the reading docs/airpaths.md argues for; the other is kept to measure it.

    Attributes
    ----------
    exits : {'upward', 'all'}
        Exits allowed: ``'upward'`` (default, Appendix D: an exit whose centroid is not above
        the base centroid gets area 0) or ``'all'`` three (the text of 3.4.1).
    overlap : {'exit', 'ball', 'none'}
        Reselection rule 1 (Fig. 3.7), when the next tetrahedron would overlap the current
        one (its fourth sphere on the current one's side of the exit face): ``'exit'``
        (default, the text: "another triangle ... would be selected as the base triangle"),
        ``'ball'``: the nearest fourth sphere on the far side instead, or ``'none'``: the
        overlap is kept (Appendix D's script has no test for it).
    closed : {'next', 'second'}
        Reselection rule 2 (Fig. 3.8), an exit face with Eq. 3.23 negative: ``'next'``
        (default, the text: "another particle would be selected", the nearest whose three
        faces are all non-negative) or ``'second'`` (Appendix D: the second-nearest sphere,
        once, unchecked).
    area : {'eq3.23', 'exact'}
        Open area that chooses the exit and gives the width (Eq. 3.24): Eq. 3.23 as written
        (default; :func:`eq323_area`) or the exact area (``throats.open_area``), which counts
        the lens of two overlapping grains once.
    insphere : bool
        Condition (2) of 3.4.1 on the fourth sphere, the inscribed sphere of the tetrahedron
        of centres smaller than a mean grain radius (default True; Appendix D has no such
        test).
    start : {'floor', 'lowest-centre'}
        Height of the AEP: the floor, the lowest sphere bottom (default; the thesis's AEPs lie
        at z = 0, the bin floor), or the lowest sphere centre.
    """

    exits: str = "upward"
    overlap: str = "exit"
    closed: str = "next"
    area: str = "eq3.23"
    insphere: bool = True
    start: str = "floor"

    def __post_init__(self):
        for name, allowed in (("exits", ("upward", "all")), ("overlap", ("exit", "ball", "none")),
                              ("closed", ("next", "second")), ("area", ("eq3.23", "exact")),
                              ("start", ("floor", "lowest-centre"))):
            if getattr(self, name) not in allowed:
                raise ValueError(f"BuildRules.{name} must be one of {allowed}, "
                                 f"got {getattr(self, name)!r}")


def build_paths(points, radii, entry_xy, *, kind="widest", axis="z", rules=BuildRules(),
                k_neighbors=32, max_steps=None, depth_m=None, angle_rule="eq3.25"):
    r"""Step-increment paths built tetrahedron by tetrahedron, as the thesis does (3.4.1).

    All entries advance together, one tetrahedron per step.

    1. Start: the air entry point (AEP) lies on the floor, the lowest sphere bottom
       (``rules.start``); the three spheres nearest to it are the first base triangle.
    2. Fourth sphere: the nearest to the base centroid that (a) is higher than the centroid
       along ``axis``, (b) is on no earlier base triangle of the path (Appendix D), (c) makes
       a tetrahedron of centres whose inscribed sphere is smaller than a mean grain radius
       (3.4.1 condition 2; ``rules.insphere``), and (d) leaves none of the three exit faces
       with Eq. 3.23 negative (rule 2, Fig. 3.8; ``rules.closed``).
    3. Rule 1 (Fig. 3.7): when that sphere lies on the side of the base face where the
       previous tetrahedron is, the two would overlap; the previous tetrahedron's next-best
       exit is taken instead (``rules.overlap``). A base with no fourth sphere is treated the
       same way; a tetrahedron with no exit left is dropped (both counted in
       ``n_backtracks``).
    4. Exit: among the allowed faces (``rules.exits``; open, :math:`S_f > 0`), the one of
       largest (``'widest'``) or smallest (``'narrowest'``) open area :math:`S_f`
       (``rules.area``); it is the next base, and its width is
       :math:`d_f = 2\sqrt{S_f/\pi}` (Eq. 3.24).
    5. Stop: when the base centroid is within one mean radius of the highest centre (the
       last tetrahedron reached the bed top).

    The path is the polyline of the base centroids (Fig. 3.9); its length, Eq. 3.27 smoothed
    length (``angle_rule``) and local turning angles are those of :class:`AirflowPath`.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    entry_xy : (n, 2) array_like, m
        Entry points (the two axes normal to ``axis``, in x, y, z order).
    kind : {'widest', 'narrowest'}
    axis : {'x', 'y', 'z'}
    rules : BuildRules, optional
        Readings of the ambiguous steps (defaults: see :class:`BuildRules`).
    k_neighbors : int, optional
        Candidates examined per step (nearest spheres to the base centroid; default 32).
    max_steps : int, optional
        Default 20 x the bed depth in mean diameters.
    depth_m : float, optional
        Bed depth for tortuosity (default :func:`bed_depth`).
    angle_rule : {'eq3.25', 'appendix-d'}
        Angle of Eq. 3.25 in the smoothed length (:func:`interior_angles`).

    Returns
    -------
    list of AirflowPath
        ``n_relaxed`` counts the fourth spheres taken under ``rules.closed='second'`` with a
        face still closed.
    """
    if not isinstance(rules, BuildRules):
        raise TypeError(f"rules must be a BuildRules, got {type(rules).__name__}")
    if kind not in ("widest", "narrowest"):
        raise ValueError(f"build kind must be 'widest' or 'narrowest', got {kind!r}")
    ax = axis_index(axis)
    x = as_points(points)
    r = np.asarray(radii, dtype=float)
    if r.shape != (x.shape[0],):
        raise ValueError(f"radii must have shape ({x.shape[0]},), got {r.shape}")
    xy = np.atleast_2d(np.asarray(entry_xy, dtype=float))
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise ValueError(f"entry points must have shape (n, 2), got {xy.shape}")
    n, ns = xy.shape[0], x.shape[0]
    rbar = float(r.mean())
    h = x[:, ax]
    h_top = h.max()
    depth = bed_depth(x, r, axis) if depth_m is None else float(depth_m)
    if max_steps is None:
        max_steps = int(max(200, 20 * np.ptp(h) / (2 * rbar)))
    sign = 1.0 if kind == "widest" else -1.0
    k = int(min(k_neighbors, ns))
    tree = spatial.cKDTree(x)

    def open_areas(tri):
        if rules.area == "exact":
            return np.nan_to_num(face_areas(x, r, tri)[1], nan=0.0)
        return eq323_area(x, r, tri)

    aep = np.zeros((n, 3))
    aep[:, plane_axes(ax)] = xy
    aep[:, ax] = (h - r).min() if rules.start == "floor" else h.min()
    _, base = tree.query(aep, k=3)
    base = np.asarray(base, dtype=np.intp).reshape(n, 3)
    used = np.zeros((n, ns), dtype=bool)
    used[np.arange(n)[:, None], base] = True
    prev = np.full(n, -1, dtype=np.intp)
    tetra = np.full((n, max_steps, 4), -1, dtype=np.intp)
    exits = np.full((n, max_steps), -1, dtype=np.intp)
    step_areas = np.full((n, max_steps, 3), np.nan)
    step_ok = np.zeros((n, max_steps, 3), dtype=bool)  # allowed exits not yet tried
    count = np.zeros(n, dtype=np.intp)
    relaxed = np.zeros(n, dtype=np.intp)
    n_back = np.zeros(n, dtype=np.intp)

    def choose_exit(i, t):
        """Exit of tetrahedron t of paths i: best allowed face; it becomes the next base."""
        if not i.size:
            return
        score = np.where(step_ok[i, t], sign * step_areas[i, t], -np.inf)
        j = np.argmax(score, axis=1)
        exits[i, t] = j
        step_ok[i, t, j] = False  # tried: a reselection takes the next best
        tet_ = tetra[i, t]
        prev[i] = tet_[np.arange(i.size), LEFT_BEHIND[j]]
        base[i] = tet_[np.arange(i.size)[:, None], EXIT_FACES[j]]

    status = np.full(n, "running", dtype=object)
    active = np.arange(n)
    while active.size:
        b = base[active]
        pb = x[b]  # (a, 3, 3)
        hc = pb.mean(axis=1)[:, ax]
        top = hc >= h_top - rbar
        status[active[top]] = "ok"
        active, b, pb, hc = active[~top], b[~top], pb[~top], hc[~top]
        if not active.size:
            break
        a = active.size
        _, cand = tree.query(pb.mean(axis=1), k=k)
        cand = np.asarray(cand, dtype=np.intp).reshape(a, k)
        cand = np.where(cand < ns, cand, 0)
        xc = x[cand]  # (a, k, 3)
        feas = (h[cand] > hc[:, None]) & ~used[active[:, None], cand]
        nrm = np.cross(pb[:, 1] - pb[:, 0], pb[:, 2] - pb[:, 0])
        s_new = np.einsum("akj,aj->ak", xc - pb[:, None, 0], nrm)
        feas &= s_new != 0
        pv = prev[active]
        s_prev = np.einsum("aj,aj->a", x[np.where(pv >= 0, pv, 0)] - pb[:, 0], nrm)
        same_side = (pv >= 0)[:, None] & (s_new * s_prev[:, None] > 0)
        if rules.overlap == "ball":
            feas &= ~same_side
        if rules.insphere:  # r_in = 3 V / (sum of face areas) of the tetrahedron of centres
            vol = np.abs(s_new) / 6.0
            e0, e1, e2 = (xc - pb[:, None, i] for i in range(3))
            s_faces = 0.5 * (np.linalg.norm(np.cross(e0, e1), axis=2)
                             + np.linalg.norm(np.cross(e0, e2), axis=2)
                             + np.linalg.norm(np.cross(e1, e2), axis=2)
                             + np.linalg.norm(nrm, axis=1)[:, None])
            feas &= 3.0 * vol / s_faces < rbar
        # feasible candidates nearest first; rule 2 on each until one passes
        order = np.argsort(~feas, axis=1, kind="stable")
        n_feas = feas.sum(axis=1)
        slot_of = np.full(a, -1, dtype=np.intp)
        pending = np.flatnonzero(n_feas > 0)
        last = 1 if rules.closed == "second" else k  # 'second': the next one, unchecked
        for slot in range(k):  # rarely more than two rounds
            pending = pending[n_feas[pending] > slot]
            if not pending.size:
                break
            cj = cand[pending, order[pending, slot]]
            tri = np.column_stack([b[pending], cj])[:, EXIT_FACES]
            neg = np.any(eq323_negative(x, r, tri), axis=1)
            good = ~neg | (slot >= last)
            relaxed[active[pending[neg & good]]] += 1
            slot_of[pending[good]] = slot
            pending = pending[~good]
        pick = order[np.arange(a), np.maximum(slot_of, 0)]
        choice = np.where(slot_of >= 0, cand[np.arange(a), pick], -1)
        ov = (choice >= 0) & (rules.overlap == "exit") & same_side[np.arange(a), pick]
        go = (choice >= 0) & ~ov
        ga = active[go]
        tet = np.column_stack([b[go], choice[go]])
        tri = tet[:, EXIT_FACES]
        areas = open_areas(tri)
        allowed = areas > 0
        if rules.exits == "upward":
            allowed &= x[tri].mean(axis=2)[:, :, ax] > hc[go, None]
        t_new = count[ga]
        step_areas[ga, t_new] = areas
        step_ok[ga, t_new] = allowed
        tetra[ga, t_new] = tet
        used[ga, choice[go]] = True
        count[ga] += 1
        has = allowed.any(axis=1)
        choose_exit(ga[has], t_new[has])
        # dead ends: no fourth sphere, rule 1's overlap, or a new tetrahedron without an
        # allowed exit: the last tetrahedron's next-best exit; none left: it is dropped
        dead = np.concatenate([active[~go], ga[~has]])
        n_back[dead] += 1
        stuck = (count[dead] == 0) | (n_back[dead] > max_steps)
        status[dead[stuck]] = "stuck"
        dead = dead[~stuck]
        t = count[dead] - 1
        more = step_ok[dead, t].any(axis=1)
        choose_exit(dead[more], t[more])
        pop = dead[~more]  # its base is tried again (its fourth sphere stays used)
        count[pop] -= 1
        tp_ = count[pop]
        base[pop] = tetra[pop, tp_, :3]
        prev_t = np.maximum(tp_ - 1, 0)
        prev[pop] = np.where(tp_ > 0, tetra[pop, prev_t, LEFT_BEHIND[exits[pop, prev_t]]], -1)
        full = active[count[active] >= max_steps]
        status[full] = "max-steps"
        active = active[status[active] == "running"]
    logger.info("built %d %s paths: %d ok, %d backtracks", n, kind,
                int(np.sum(status == "ok")), int(n_back.sum()))
    return [
        path_record(x, r, kind, "build", xy[i], axis, str(status[i]), tetra[i, : count[i]],
                    exits[i, : count[i]], depth, n_relaxed=relaxed[i], n_back=n_back[i],
                    angle_rule=angle_rule,
                    exit_open_m2=step_areas[i, np.arange(count[i]), exits[i, : count[i]]])
        for i in range(n)
    ]
