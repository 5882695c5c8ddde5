r"""Step-increment paths built tetrahedron by tetrahedron, as the thesis does (3.4.1, after
Sobieski et al. 2012; Appendices D, E): tetrahedra are built sphere by sphere upward from the
three spheres nearest to the entry point, leaving each through the open exit face of largest
(smallest) open area :math:`S_f` (Eq. 3.23), with the thesis's two reselection rules.
"""

from __future__ import annotations

import logging

import numpy as np

from .._deferred import spatial
from ..pores import axis_index
from ._geometry import EXIT_FACES, LEFT_BEHIND, as_points, bed_depth, face_areas, plane_axes
from ._record import path_record

logger = logging.getLogger(__name__)


def eq323_negative(points, radii, triangles):
    r"""Reselection rule 2 of the thesis: is Eq. 3.23 negative for these triangles?

    Eq. 3.23 subtracts the three sectors :math:`\tfrac12\theta_i r_i^2` from the triangle,
    counting the lens of two overlapping disks twice; the thesis reselects a tetrahedron when
    the result is negative (Fig. 3.8, Appendix D ``if ai1<0 || ai2<0 || ai3<0``). This is
    that test only; open areas themselves come from ``throats.open_area``.
    """
    x = np.asarray(points, dtype=float)[np.asarray(triangles)]  # (..., 3, 3)
    r = np.asarray(radii, dtype=float)[np.asarray(triangles)]
    full = 0.5 * np.linalg.norm(np.cross(x[..., 1, :] - x[..., 0, :],
                                         x[..., 2, :] - x[..., 0, :]), axis=-1)
    sectors = 0.0
    for i in range(3):  # the three vertices
        u = x[..., (i + 1) % 3, :] - x[..., i, :]
        v = x[..., (i + 2) % 3, :] - x[..., i, :]
        cos = np.einsum("...j,...j->...", u, v) / (np.linalg.norm(u, axis=-1)
                                                   * np.linalg.norm(v, axis=-1))
        sectors = sectors + 0.5 * np.arccos(np.clip(cos, -1.0, 1.0)) * r[..., i] ** 2
    return full - sectors < 0



def build_paths(points, radii, entry_xy, *, kind="widest", axis="z", k_neighbors=24,
                max_steps=None, depth_m=None, angle_rule="eq3.25", closed_rule="eq3.23",
                min_quality=0.0):
    r"""Step-increment paths built tetrahedron by tetrahedron, as the thesis does (3.4.1).

    All entries advance together, one tetrahedron per step.

    1. The base triangle of the first tetrahedron is the three spheres nearest to the entry
       point on the floor (the lowest centre height).
    2. The fourth sphere is the one nearest to the base centroid that (a) is higher than the
       centroid along ``axis``, (b) is not yet on the path (Appendix D), (c) lies on the other
       side of the base plane from the previous tetrahedron, so the new one does not fold back
       over it (reselection rule 1, Fig. 3.7), (d) makes a tetrahedron whose inscribed sphere
       is smaller than a mean grain (3.4.1), and (e) leaves no exit face closed
       (reselection rule 2, Fig. 3.8; see ``closed_rule``). Without any candidate meeting
       (e), the nearest meeting (a)-(d) with an open upward exit is taken (counted in
       ``n_relaxed``).
    3. The exit is the open face higher than the base centroid of largest (``'widest'``) or
       smallest (``'narrowest'``) open area (Eq. 3.23, exact: ``throats.open_area``); it is
       the next base. When a later tetrahedron finds no fourth sphere, the path returns to
       the previous one and takes its next-best exit (the thesis's "another triangle from the
       current tetrahedron would be selected"), dropping tetrahedra that have none left
       (counted in ``n_backtracks``).
    4. The path ends when the base centroid is within one mean radius of the highest centre.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    entry_xy : (n, 2) array_like, m
        Entry points (the two axes normal to ``axis``, in x, y, z order).
    kind : {'widest', 'narrowest'}
    axis : {'x', 'y', 'z'}
    k_neighbors : int, optional
        Candidates examined per step (nearest spheres to the base centroid; default 24).
    max_steps : int, optional
        Default 20 x the bed depth in mean diameters.
    depth_m : float, optional
        Bed depth for tortuosity (default :func:`bed_depth`).
    angle_rule : {'eq3.25', 'appendix-d'}
    min_quality : float, optional
        Not in the thesis (default 0, off): also refuse fourth spheres that make a sliver
        (:func:`pore_quality` below this). Against flat walls the nearest sphere above is
        often in the wall layer, and the flat tetrahedron it makes has faces of up to 100 mm²
        lying in the wall plane, which the widest rule then picks.
    closed_rule : {'eq3.23', 'exact'}
        When a face counts as closed for rule 2: ``'eq3.23'`` (default, as the thesis) when
        the triangle minus the three sectors is negative, which also rejects faces whose
        overlapping grains leave only a sliver of open area; ``'exact'`` when the exact open
        area is 0. With ``'exact'`` narrowest paths squeeze through faces a few micrometres
        wide.

    Returns
    -------
    list of AirflowPath
    """
    if closed_rule not in ("eq3.23", "exact"):
        raise ValueError(f"closed_rule must be 'eq3.23' or 'exact', got {closed_rule!r}")

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

    aep = np.zeros((n, 3))
    aep[:, plane_axes(ax)] = xy
    aep[:, ax] = h.min()
    _, base = tree.query(aep, k=3)
    base = np.asarray(base, dtype=np.intp).reshape(n, 3)
    used = np.zeros((n, ns), dtype=bool)
    used[np.arange(n)[:, None], base] = True
    prev = np.full(n, -1, dtype=np.intp)
    tetra = np.full((n, max_steps, 4), -1, dtype=np.intp)
    exits = np.full((n, max_steps), -1, dtype=np.intp)
    step_areas = np.full((n, max_steps, 3), np.nan)
    step_up = np.zeros((n, max_steps, 3), dtype=bool)
    banned = np.zeros((n, max_steps, 3), dtype=bool)
    count = np.zeros(n, dtype=np.intp)
    relaxed = np.zeros(n, dtype=np.intp)
    n_back = np.zeros(n, dtype=np.intp)

    def step_ok(i, t):
        return (step_areas[i, t] > 0) & step_up[i, t] & ~banned[i, t]

    def _choose_exit(i, t):
        """Exit of tetrahedron t of paths i: best allowed face; it becomes the next base."""
        if not i.size:
            return
        score = np.where(step_ok(i, t), sign * step_areas[i, t], -np.inf)
        j = np.argmax(score, axis=1)
        exits[i, t] = j
        tet_ = tetra[i, t]
        prev[i] = tet_[np.arange(i.size), LEFT_BEHIND[j]]
        base[i] = tet_[np.arange(i.size)[:, None], EXIT_FACES[j]]

    status = np.full(n, "running", dtype=object)
    active = np.arange(n)
    while active.size:
        b = base[active]
        pb = x[b]  # (a, 3, 3)
        c = pb.mean(axis=1)
        hc = c[:, ax]
        top = hc >= h_top - rbar
        status[active[top]] = "ok"
        active, b, pb, c, hc = active[~top], b[~top], pb[~top], c[~top], hc[~top]
        if not active.size:
            break
        a = active.size
        _, cand = tree.query(c, k=k)
        cand = np.asarray(cand, dtype=np.intp).reshape(a, k)
        cand = np.where(cand < ns, cand, 0)
        xc = x[cand]  # (a, k, 3)
        feas = (h[cand] > hc[:, None]) & ~used[active[:, None], cand]
        nrm = np.cross(pb[:, 1] - pb[:, 0], pb[:, 2] - pb[:, 0])
        s_new = np.einsum("akj,aj->ak", xc - pb[:, None, 0], nrm)
        pv = prev[active]
        s_prev = np.einsum("aj,aj->a", x[np.where(pv >= 0, pv, 0)] - pb[:, 0], nrm)
        feas &= np.where((pv >= 0)[:, None], s_new * s_prev[:, None] < 0, s_new != 0)
        # inscribed sphere of the tetrahedron of centres: r_in = 3 V / (sum of face areas)
        vol = np.abs(s_new) / 6.0
        e0, e1, e2 = (xc - pb[:, None, i] for i in range(3))
        s_faces = 0.5 * (np.linalg.norm(np.cross(e0, e1), axis=2)
                         + np.linalg.norm(np.cross(e0, e2), axis=2)
                         + np.linalg.norm(np.cross(e1, e2), axis=2)
                         + np.linalg.norm(nrm, axis=1)[:, None])
        feas &= 3.0 * vol / s_faces < rbar
        if min_quality > 0:  # not in the thesis: refuse slivers (see passable_pores)
            i_, j_ = np.triu_indices(4, k=1)
            allv = np.concatenate([np.broadcast_to(pb[:, None], (a, k, 3, 3)), xc[:, :, None]],
                                  axis=2)  # (a, k, 4, 3)
            ebar = np.linalg.norm(allv[:, :, i_] - allv[:, :, j_], axis=3).mean(axis=2)
            feas &= 6.0 * np.sqrt(2.0) * vol / ebar**3 >= min_quality
        # walk the feasible candidates nearest first; open areas only where needed
        order = np.argsort(~feas, axis=1, kind="stable")  # feasible first, by distance
        n_feas = feas.sum(axis=1)
        choice = np.full(a, -1, dtype=np.intp)
        fallback = np.full(a, -1, dtype=np.intp)
        areas = np.full((a, 3), np.nan)
        fb_areas = np.full((a, 3), np.nan)
        pending = np.flatnonzero(n_feas > 0)
        for slot in range(k):  # rarely more than two rounds
            pending = pending[n_feas[pending] > slot]
            if not pending.size:
                break
            cj = cand[pending, order[pending, slot]]
            tet = np.column_stack([b[pending], cj])
            tri = tet[:, EXIT_FACES]  # (p, 3, 3)
            _, op = face_areas(x, r, tri)
            if closed_rule == "eq3.23":
                op = np.where(eq323_negative(x, r, tri), 0.0, op)
            upf = x[tri].mean(axis=2)[:, :, ax] > hc[pending, None]
            good = np.all(op > 0, axis=1)
            usable = np.any((op > 0) & upf, axis=1)
            first_fb = usable & (fallback[pending] < 0)
            fallback[pending[first_fb]] = cj[first_fb]
            fb_areas[pending[first_fb]] = op[first_fb]
            choice[pending[good]] = cj[good]
            areas[pending[good]] = op[good]
            pending = pending[~good]
        use_fb = (choice < 0) & (fallback >= 0)
        relaxed[active[use_fb]] += 1
        choice = np.where(use_fb, fallback, choice)
        areas = np.where(use_fb[:, None], fb_areas, areas)
        go = choice >= 0
        ga = active[go]
        tet = np.column_stack([b[go], choice[go]])
        tri = tet[:, EXIT_FACES]
        up = x[tri].mean(axis=2)[:, :, ax] > hc[go, None]
        step_areas[ga, count[ga]] = areas[go]
        step_up[ga, count[ga]] = up
        banned[ga, count[ga]] = False  # the slot may hold bans of a tetrahedron dropped before
        tetra[ga, count[ga]] = tet
        used[ga, choice[go]] = True
        count[ga] += 1
        _choose_exit(ga, count[ga] - 1)
        # dead end: the thesis selects another exit of the previous tetrahedron (rule 1);
        # when it has none left, that tetrahedron is dropped and its base tried again
        dead = active[~go]
        n_back[dead] += 1
        status[dead[(count[dead] == 0) | (n_back[dead] > max_steps)]] = "stuck"
        dead = dead[status[dead] == "running"]
        t = count[dead] - 1
        banned[dead, t, exits[dead, t]] = True
        has = np.any(step_ok(dead, t), axis=1)
        _choose_exit(dead[has], t[has])
        pop = dead[~has]
        count[pop] -= 1
        tp_ = count[pop]
        base[pop] = tetra[pop, tp_, :3]
        prev_t = np.maximum(tp_ - 1, 0)
        prev_j = exits[pop, prev_t]
        prev[pop] = np.where(tp_ > 0, tetra[pop, prev_t, LEFT_BEHIND[prev_j]], -1)
        full = active[count[active] >= max_steps]
        status[full] = "max-steps"
        active = active[status[active] == "running"]
    logger.info("built %d %s paths: %d ok, %d relaxed steps", n, kind,
                int(np.sum(status == "ok")), int(relaxed.sum()))
    return [
        path_record(x, r, kind, "build", xy[i], axis, str(status[i]), tetra[i, : count[i]],
                     exits[i, : count[i]], depth, n_relaxed=relaxed[i], n_back=n_back[i],
                     angle_rule=angle_rule,
                     exit_open_m2=step_areas[i, np.arange(count[i]), exits[i, : count[i]]])
        for i in range(n)
    ]

