r"""Paths on the Delaunay tessellation: greedy step-increment walks (:func:`walk_paths`), the
shortest chain of face centroids (:func:`shortest_paths`, Dijkstra), the maximin-bottleneck
widest path (:func:`maximin_paths`, maximum spanning tree), and :func:`trace_paths`, which
traces paths of any kind, built (:func:`build_paths`) or on the tessellation.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy import sparse

from .._deferred import csgraph
from ..pores import axis_index
from ._build import build_paths
from ._faces import MIN_QUALITY, FaceGraph, entry_faces, passable_pores, path_ends
from ._geometry import as_points, bed_depth
from ._record import path_record

logger = logging.getLogger(__name__)

#: Path kinds accepted by :func:`trace_paths`.
PATH_KINDS = ("widest", "narrowest", "maximin", "shortest")


def _faces_to_tetra(graph, faces):
    """Tetrahedra (inlet face first) and exit rows of a chain of Delaunay faces."""
    faces = np.asarray(faces, dtype=np.intp)
    tp = graph.throat_pores
    a, b = tp[faces[:-1]], tp[faces[1:]]
    same = (a[:, :, None] == b[:, None, :]) & (a[:, :, None] >= 0)
    pores = a[np.arange(a.shape[0]), np.argmax(same.any(axis=2), axis=1)]
    pv = graph.pore_vertices[pores]  # (m, 4)
    pt = graph.pore_throats[pores]
    k_in = np.argmax(pt == faces[:-1, None], axis=1)
    base = np.take_along_axis(pv, np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])[k_in],
                              axis=1)
    apex = pv[np.arange(pores.size), k_in]
    tetra = np.column_stack([base, apex])
    k_out = np.argmax(pt == faces[1:, None], axis=1)
    left = pv[np.arange(pores.size), k_out]  # the vertex the exit face leaves behind
    exit_local = 2 - np.argmax(base == left[:, None], axis=1)  # LEFT_BEHIND inverse
    return tetra, exit_local, pores


def walk_paths(graph, entry_face, entry_pore, *, kind="widest", axis="z", max_steps=None,
               min_quality=MIN_QUALITY):
    r"""Step-increment paths walked through the Delaunay tetrahedra (thesis 3.4.1 rules).

    The tessellation fixes each next tetrahedron (the one behind the chosen face), so only the
    exit choice and the reselection rules carry over from the thesis's construction
    (:func:`build_paths`); all entries advance together.

    Parameters
    ----------
    graph : FaceGraph
    entry_face, entry_pore : (n,) array_like of int
        Start face and tetrahedron of each path (see :func:`entry_faces`).
    kind : {'widest', 'narrowest'}
        Exit face of largest or smallest open area.
    axis : {'x', 'y', 'z'}
        Flow direction (+axis).
    max_steps : int, optional
        Step limit per path (default 50 x the bed depth in mean diameters, at least 1000).
    min_quality : float, optional
        Slivers not entered, see :func:`passable_pores`.

    Returns
    -------
    faces : list of (m_i,) int ndarrays
        Faces crossed by each path, start face first, end face last.
    status : (n,) ndarray of str
    n_relaxed, n_backtracks : (n,) int ndarrays

    Notes
    -----
    Per step and path: candidates are the three faces of the current tetrahedron other than
    the one it was entered by; a face is allowed if it is open (:math:`S_f > 0`), interior,
    and leads to an enterable tetrahedron not yet on the path (rules 2 and 1 of the thesis).
    The allowed faces whose centroid is higher (along ``axis``) than the entry face's are
    ranked by open area; if none is higher, all allowed faces are ranked (a relaxed step); if
    none is allowed, the path steps back (the dead tetrahedron stays marked). A path ends in
    a tetrahedron within :data:`END_BAND_DIAMETERS` of the top, through its highest face.
    """
    if kind not in ("widest", "narrowest"):
        raise ValueError(f"greedy kind must be 'widest' or 'narrowest', got {kind!r}")
    ax = axis_index(axis)
    f0 = np.atleast_1d(np.asarray(entry_face, dtype=np.intp))
    p0 = np.atleast_1d(np.asarray(entry_pore, dtype=np.intp))
    n = f0.size
    tp, pt = graph.throat_pores, graph.pore_throats
    hull = graph.hull_mask()
    passable = passable_pores(graph, min_quality=min_quality)
    _, high, _, top, _ = path_ends(graph, ax, passable)
    h = graph.throat_centroid[:, ax]
    area = graph.throat_open_area
    sign = 1.0 if kind == "widest" else -1.0
    if max_steps is None:
        depth_d = np.ptp(graph.points[:, ax]) / graph.mean_diameter
        max_steps = int(max(1000, 50 * depth_d))

    stack_pore = np.full((n, max_steps + 1), -1, dtype=np.intp)
    stack_face = np.full((n, max_steps + 1), -1, dtype=np.intp)
    stack_pore[:, 0] = p0
    stack_face[:, 0] = f0
    ptr = np.zeros(n, dtype=np.intp)
    visited = np.zeros((n, graph.n_pores), dtype=bool)
    visited[np.arange(n), p0] = True
    exit_face = np.full(n, -1, dtype=np.intp)
    status = np.full(n, "running", dtype=object)
    n_relaxed = np.zeros(n, dtype=np.intp)
    n_back = np.zeros(n, dtype=np.intp)
    active = np.arange(n)
    steps = 0
    while active.size:
        steps += 1
        p = stack_pore[active, ptr[active]]
        fin = stack_face[active, ptr[active]]
        # finish in a tetrahedron at the top, through its highest face
        done = high[p] & (top[p] != fin)
        exit_face[active[done]] = top[p[done]]
        status[active[done]] = "ok"
        active, p, fin = active[~done], p[~done], fin[~done]
        if not active.size:
            break
        faces = pt[p]  # (a, 4)
        pair = tp[faces]  # (a, 4, 2)
        nb = np.where(pair[..., 0] == p[:, None], pair[..., 1], pair[..., 0])
        nb0 = np.where(nb >= 0, nb, 0)
        ok = (faces != fin[:, None]) & (area[faces] > 0) & ~hull[faces]
        ok &= passable[nb0] & ~visited[active[:, None], nb0]
        up = ok & (h[faces] > h[fin][:, None])
        has_up = up.any(axis=1)
        allowed = np.where(has_up[:, None], up, ok)
        go = allowed.any(axis=1)
        n_relaxed[active[go & ~has_up]] += 1
        score = np.where(allowed, sign * area[faces], -np.inf)
        j = np.argmax(score, axis=1)
        ga = active[go]
        nf = faces[go, j[go]]
        npore = nb[go, j[go]]
        ptr[ga] += 1
        stack_pore[ga, ptr[ga]] = npore
        stack_face[ga, ptr[ga]] = nf
        visited[ga, npore] = True
        ba = active[~go]
        n_back[ba] += 1
        ptr[ba] -= 1
        status[ba[ptr[ba] < 0]] = "stuck"
        status[ga[ptr[ga] >= max_steps]] = "max-steps"
        active = active[status[active] == "running"]
    out = []
    for i in range(n):  # assembling n result lists, not a hot loop
        if status[i] == "ok":
            out.append(np.append(stack_face[i, : ptr[i] + 1], exit_face[i]))
        else:
            out.append(stack_face[i, : max(ptr[i], 0) + 1].copy())
    logger.info("walked %s paths: %d entries, %d steps, %d ok", kind, n, steps,
                int(np.sum(status == "ok")))
    return out, status.astype(str), n_relaxed, n_back


def _face_edges(graph, usable, pore_ok):
    """Pairs of usable faces sharing a tetrahedron that may be entered: (E, 2) int."""
    pt = graph.pore_throats[pore_ok]
    i, j = np.triu_indices(4, k=1)
    e = np.stack([pt[:, i].ravel(), pt[:, j].ravel()], axis=1)
    return e[usable[e[:, 0]] & usable[e[:, 1]]]


def _graph_setup(graph, ax, entry_face, entry_pore, min_quality):
    """Usable faces, enterable pores and end faces of the face graph."""
    passable = passable_pores(graph, min_quality=min_quality)
    _, high, _, top, _ = path_ends(graph, ax, passable)
    end_faces = np.unique(top[high])
    usable = ~graph.hull_mask() & (graph.throat_open_area > 0)
    usable[end_faces] = True
    usable[entry_face] = True
    pore_ok = passable.copy()
    pore_ok[entry_pore] = True
    return end_faces, usable, pore_ok


def _follow(pred, start, sink):
    """Walk predecessor links from every start node to ``sink``: list of node arrays."""
    n = start.size
    paths = [[int(s)] for s in start]
    cur = start.copy()
    alive = np.flatnonzero(cur != sink)
    ok = np.ones(n, dtype=bool)
    limit = pred.size
    steps = 0
    while alive.size and steps < limit:
        nxt = pred[cur[alive]]
        bad = nxt < 0
        ok[alive[bad]] = False
        alive, nxt = alive[~bad], nxt[~bad]
        cur[alive] = nxt
        for i, v in zip(alive.tolist(), nxt.tolist()):
            paths[i].append(v)
        alive = alive[nxt != sink]
        steps += 1
    return [np.array(p[:-1] if okk else p, dtype=np.intp) for p, okk in zip(paths, ok)], ok


def shortest_paths(graph, entry_face, entry_pore, *, axis="z", min_quality=MIN_QUALITY):
    """Shortest chains of face centroids from each entry face to the outlet (Dijkstra).

    One Dijkstra run from a virtual node joined to every end face (the highest face of each
    enterable tetrahedron within :data:`END_BAND_DIAMETERS` of the top) serves all entries.
    Interior faces are usable if open (open area > 0); slivers are not entered (see
    :func:`passable_pores`, ``min_quality``).

    Returns
    -------
    faces : list of int ndarrays (start face first, end face last)
    ok : (n,) bool ndarray
        False where the entry is not connected to the outlet.
    """
    ax = axis_index(axis)
    f0 = np.atleast_1d(np.asarray(entry_face, dtype=np.intp))
    out, usable, pore_ok = _graph_setup(graph, ax, f0, entry_pore, min_quality)
    nt = graph.n_throats
    e = _face_edges(graph, usable, pore_ok)
    c = graph.throat_centroid
    w = np.linalg.norm(c[e[:, 0]] - c[e[:, 1]], axis=1)
    tiny = 1e-9 * graph.mean_diameter
    w = np.maximum(w, tiny)
    rows = np.concatenate([e[:, 0], np.full(out.size, nt)])
    cols = np.concatenate([e[:, 1], out])
    vals = np.concatenate([w, np.full(out.size, tiny)])
    g = sparse.csr_array((vals, (rows, cols)), shape=(nt + 1, nt + 1))
    _, pred = csgraph.dijkstra(g, directed=False, indices=nt, return_predecessors=True)
    return _follow(pred, f0, nt)


def maximin_paths(graph, entry_face, entry_pore, *, axis="z", tiebreak="shortest",
                  min_quality=MIN_QUALITY):
    r"""Widest paths in the maximin-bottleneck sense, from each entry face to the outlet.

    The width of a path is that of its narrowest interior face (open area, Eq. 3.23); the
    maximin path maximises it. Every maximin path between two nodes lies in a maximum spanning
    tree, so one Kruskal tree of the face graph (plus a virtual node joined to all end faces,
    see :func:`shortest_paths`) serves all entries. Hull faces do not count in the bottleneck.

    Parameters
    ----------
    graph : FaceGraph
    entry_face : (n,) array_like of int
    axis : {'x', 'y', 'z'}
    tiebreak : {'shortest', 'tree'}
        ``'tree'``: the path in the spanning tree (for distinct areas, the lexicographically
        widest one: it may wander). ``'shortest'`` (default): the shortest path among all
        paths whose narrowest face is at least the maximin bottleneck (one Dijkstra run per
        distinct bottleneck value).
    min_quality : float, optional
        Slivers not entered, see :func:`passable_pores`.

    Returns
    -------
    faces : list of int ndarrays
    ok : (n,) bool ndarray
    bottleneck_m2 : (n,) ndarray
        Maximin open area of each entry (NaN where not connected).
    """
    if tiebreak not in ("shortest", "tree"):
        raise ValueError(f"tiebreak must be 'shortest' or 'tree', got {tiebreak!r}")
    ax = axis_index(axis)
    f0 = np.atleast_1d(np.asarray(entry_face, dtype=np.intp))
    out, usable, pore_ok = _graph_setup(graph, ax, f0, entry_pore, min_quality)
    nt = graph.n_throats
    amax = float(graph.throat_open_area.max())
    w = np.where(graph.hull_mask(), 2.0 * amax, graph.throat_open_area)  # node widths
    e = _face_edges(graph, usable, pore_ok)
    ew = np.minimum(w[e[:, 0]], w[e[:, 1]])
    cost = 3.0 * amax - ew  # > 0; minimum tree of cost = maximum tree of width
    rows = np.concatenate([e[:, 0], np.full(out.size, nt)])
    cols = np.concatenate([e[:, 1], out])
    vals = np.concatenate([cost, np.full(out.size, 1e-6 * amax)])
    g = sparse.csr_array((vals, (rows, cols)), shape=(nt + 1, nt + 1))
    tree = csgraph.minimum_spanning_tree(g)
    _, pred = csgraph.breadth_first_order(tree, nt, directed=False, return_predecessors=True)
    faces, ok = _follow(pred, f0, nt)
    bott = np.array([w[f].min() if okk and f.size else np.nan for f, okk in zip(faces, ok)])
    if tiebreak == "tree":
        return faces, ok, bott
    c = graph.throat_centroid
    length = np.maximum(np.linalg.norm(c[e[:, 0]] - c[e[:, 1]], axis=1),
                        1e-9 * graph.mean_diameter)
    for b in np.unique(bott[ok]):  # one Dijkstra per distinct bottleneck value
        keep = ew >= b * (1.0 - 1e-9)   # equal faces may differ by rounding (the audit: a
        #                                 maximin path 22 % longer than an equal-bottleneck one)
        gb = sparse.csr_array(
            (np.concatenate([length[keep], np.full(out.size, 1e-9 * graph.mean_diameter)]),
             (np.concatenate([e[keep, 0], np.full(out.size, nt)]),
              np.concatenate([e[keep, 1], out]))),
            shape=(nt + 1, nt + 1))
        _, pb = csgraph.dijkstra(gb, directed=False, indices=nt, return_predecessors=True)
        idx = np.flatnonzero(ok & (bott == b))
        fb, okb = _follow(pb, f0[idx], nt)
        for i, f, k in zip(idx, fb, okb):
            if k:
                faces[i] = f
    return faces, ok, bott


def trace_paths(points, radii, entry_xy, *, kind="widest", method="build", graph=None,
                axis="z", depth_m=None, tiebreak="shortest", angle_rule="eq3.25",
                min_quality=MIN_QUALITY):
    """Trace paths of one kind from entry points on the floor; list of :class:`AirflowPath`.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    entry_xy : (n, 2) array_like, m
        Entry points in the plane normal to ``axis`` (the other two axes in x, y, z order).
    kind : {'widest', 'narrowest', 'maximin', 'shortest'}
    method : {'build', 'delaunay'}
        For 'widest'/'narrowest': the thesis's construction (:func:`build_paths`, default) or
        the step-increment rule walked on the tessellation (:func:`walk_paths`).
        'maximin' and 'shortest' always use the tessellation.
    graph : FaceGraph, optional
        Needed unless ``kind`` is built (see :func:`face_graph`).
    axis : {'x', 'y', 'z'}
    depth_m : float, optional
        Bed depth for the tortuosity; default :func:`bed_depth`.
    tiebreak : {'shortest', 'tree'}
        For ``'maximin'``, see :func:`maximin_paths`.
    angle_rule : {'eq3.25', 'appendix-d'}
        Angle rule of the smoothed length, see :func:`interior_angles`.
    min_quality : float
        Slivers not entered on the tessellation, see :func:`passable_pores`.
    """
    if kind not in PATH_KINDS:
        raise ValueError(f"unknown path kind {kind!r}; expected one of {PATH_KINDS}")
    if method not in ("build", "delaunay"):
        raise ValueError(f"unknown method {method!r}; expected 'build' or 'delaunay'")
    x = as_points(points)
    r = np.asarray(radii, dtype=float)
    xy = np.atleast_2d(np.asarray(entry_xy, dtype=float))
    depth = bed_depth(x, r, axis) if depth_m is None else float(depth_m)
    if kind in ("widest", "narrowest") and method == "build":
        return build_paths(x, r, xy, kind=kind, axis=axis, depth_m=depth, angle_rule=angle_rule)
    if not isinstance(graph, FaceGraph):
        raise TypeError(f"kind {kind!r} with method {method!r} needs graph=FaceGraph")
    f0, p0 = entry_faces(graph, xy, axis=axis, min_quality=min_quality)
    n = f0.size
    relaxed = back = np.zeros(n, dtype=int)
    if kind in ("widest", "narrowest"):
        faces, status, relaxed, back = walk_paths(graph, f0, p0, kind=kind, axis=axis,
                                                  min_quality=min_quality)
        label = "delaunay"
    else:
        if kind == "shortest":
            faces, ok = shortest_paths(graph, f0, p0, axis=axis, min_quality=min_quality)
        else:
            faces, ok, _ = maximin_paths(graph, f0, p0, axis=axis, tiebreak=tiebreak,
                                         min_quality=min_quality)
        status = np.where(ok, "ok", "stuck")
        label = "graph"
    out = []
    for i in range(n):  # one record per path
        f = faces[i] if status[i] == "ok" else faces[i][:1]
        tetra, exit_local, pores = _faces_to_tetra(graph, f)
        out.append(path_record(x, r, kind, label, xy[i], axis, str(status[i]), tetra,
                                exit_local, depth, pores=pores, n_relaxed=relaxed[i],
                                n_back=back[i], angle_rule=angle_rule,
                                exit_open_m2=graph.throat_open_area[f[1:]]))
    return out

