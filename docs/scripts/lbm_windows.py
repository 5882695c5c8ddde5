"""Per-window comparison of the conduit network with a resolved (lattice-Boltzmann) Stokes flow.

The lattice of ``lbm_grains.py`` (D3Q19 TRT, Guo forcing, halfway bounce-back; the network's
sample box, mirror lateral faces, box and mirror image one periodic cell along the flow, driven
by a uniform body force) is solved for Stokes flow and its field kept: density and the three
velocity components of every node of the box. Then for every conduit of the network's sample
(a Delaunay face between two pore bodies):

* the resolved flux through the face triangle, Q_LBM = ∫ u·n dA (trilinear interpolation of the
  node velocities, zero in the solid, on a barycentric grid of points about dx/2 apart);
* the resolved driving potential of each pore body, P = p - ρ g s (p = c_s² ρ, s the coordinate
  along the flow), averaged over the fluid nodes of the body's tetrahedra;
* the resolved conductance of the conduit, g_LBM = Q_LBM / (P_a - P_b), against the network's
  g (both μ g in m³), and the network's conduit flow at the lattice's mean gradient against
  Q_LBM.

Conduits are grouped by their window: *deep pair* (two spheres of one grain overlapping so much
that the tables' deep-overlap family serves the window, :func:`throats.deep_overlap`), *same
grain* (two vertices of one grain, not deep), *ordinary* (three grains); and by the grains
their two side tetrahedra span (four, or three or fewer where two of a tetrahedron's spheres
belong to one grain: a piece of a void the grain's spheres split, :func:`side_grains`; on
sphere packings every tetrahedron spans four).

    python docs/scripts/lbm_windows.py run network/data/wheat_grains.csv --resolution 16 --out .lbm/wheat_w16.npz
    python docs/scripts/lbm_windows.py compare .lbm/wheat_w16.npz --json wheat_windows.json

``mates`` needs no lattice either: the conduits' g with the grain mates taken out of the
windows and out of every section (``network.conductance.conduit_conductance``'s
``grain_mates``) over their g with the mates left in, by the window's intrusion, and with a
``compare`` JSON the resolved comparison's ratios times those:

    python docs/scripts/lbm_windows.py mates network/data/wheat_grains.csv --ref docs/data/lbm_windows_wheat.json

``classes`` needs no lattice: where a bed's Stokes dissipation goes in the network (the default
model), by window class, grain-mate class (untouched, sections cut, window cut) and radius
ratio; ``fe-check`` the network's k with FE in place of the window factors' distance-squared
estimate and of the Q* table's misses:

    python docs/scripts/lbm_windows.py classes network/data/wheat_grains.csv
    python docs/scripts/lbm_windows.py fe-check shelled_corn.csv

``intrusion`` needs no lattice: the share of each window's three-disk open area that lies inside
other spheres, the Stokes flow of those sections with every sphere cutting the face plane
against the three-disk section, and the network's k with that ratio on each conduit:

    python docs/scripts/lbm_windows.py intrusion network/data/soybean_grains.csv network/data/wheat_grains.csv
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parents[2]))     # the repository's packages
from lbm_grains import BoxLattice, mirrored_index, sample_box, voxelise_box  # noqa: E402
from lbm_periodic import C  # noqa: E402

CS2 = 1.0 / 3.0


def run_field(bed, resolution, *, tau=1.5, max_steps=12000, tol=1e-5, log=print):
    """Stokes field of the bed's sample box at ``resolution`` lattice units per d32."""
    c, rad, lo, hi, d32, _ = sample_box(bed)
    dx = d32 / resolution
    solid = voxelise_box(c, rad, lo, hi, dx)               # (n_flow=z, x, y)
    index, nf, n_nodes = mirrored_index(solid)
    lat = BoxLattice(index, nf, n_nodes)
    eps = 1.0 - solid.mean()
    nu = (tau - 0.5) / 3.0
    k_guess = resolution**2 * eps**3 / (180.0 * (1.0 - eps) ** 2)
    gx = nu * 1e-3 / k_guess
    log(f"# box {solid.shape} x2, {nf} fluid nodes, porosity {eps:.4f}")
    r = lat.run(tau, gx, tol=tol, max_steps=max_steps)
    log(f"# {r['steps']} steps, converged {r['converged']}, {r['seconds']:.0f} s, "
        f"{r['mlups']:.1f} MLUPS")
    # moments of the box (the first half of the doubled cell) as the kernel sees them
    nf0 = int((~solid).sum())
    f, idx = lat.f, lat.index
    rho = np.zeros(nf0)
    j = np.zeros((3, nf0))
    for i in range(19):
        v = f[idx[i * nf:i * nf + nf0]]
        rho += v
        for a in range(3):
            if C[i][a]:
                j[a] += C[i][a] * v
    j[0] += 0.5 * rho * gx
    u = j / rho
    return {"solid": solid, "rho": rho, "u": u, "gx": gx, "tau": tau, "dx_m": dx, "lo_m": lo,
            "hi_m": hi, "d32_m": d32, "U_lu": float(r["U"]), "steps": r["steps"],
            "converged": r["converged"], "k_lu2": nu * float(r["U"]) / gx, "bed": str(bed),
            "resolution": resolution}


def _network(bed):
    """Tessellation, the conduit network's Stokes solution in the sample box (table-only, the
    grain mates left in the sections: the model the per-conduit comparison measures)."""
    from network import tessellate
    from network.flow import ConductanceOptions, SampleOptions, solve_network
    from network.packing import read_container, read_packing

    pk = read_packing(bed)
    tess = tessellate(pk)
    off = ConductanceOptions(policy="table-only", model_options={"grain_mates": "off"})
    res = solve_network(pk, axis="z", sample=SampleOptions(container=read_container(bed)),
                        conductance=off, tessellation=tess)
    return pk, tess, res


def _voxel_tets(tess, pts):
    """Tetrahedron of the tessellation holding each point (-1: none matched)."""
    from scipy import spatial

    c = tess.packing.centers
    d = spatial.Delaunay(c, qhull_options="Qbb Qc Qz Q12")
    key = {tuple(v): i for i, v in enumerate(np.sort(tess.pore_vertices, axis=1).tolist())}
    m = np.array([key.get(tuple(v), -1) for v in np.sort(d.simplices, axis=1).tolist()])
    s = d.find_simplex(pts)
    return np.where(s >= 0, m[np.maximum(s, 0)], -1), float(np.mean(m >= 0))


def grain_ids(packing):
    """Each sphere's grain (a sphere packing's spheres: each its own grain)."""
    g = packing.grain_id
    return np.arange(packing.n) if g is None else np.asarray(g)


def window_class(tess, throats):
    """'deep' / 'same' / 'ordinary' code (2, 1, 0) of throats' windows."""
    from throats import deep_overlap

    gid = grain_ids(tess.packing)[tess.throat_vertices[throats]]
    same = (gid[:, 0] == gid[:, 1]) | (gid[:, 0] == gid[:, 2]) | (gid[:, 1] == gid[:, 2])
    deep = deep_overlap(tess.throat_radii[throats], tess.throat_sides[throats])
    return np.where(deep, 2, np.where(same, 1, 0))


def window_intrusion(tess, throats, heights=None, n_points=48, seed=0):
    """Fraction of each window's open area (the triangle minus its three vertex disks, the
    section the conduit model and the Q* tables see) that lies inside some other sphere of
    the packing, by Monte Carlo on ``n_points`` uniform points of the triangle (one
    ``np.random.default_rng(seed)`` pattern for all). ``heights`` (M,): the section at that
    height above the face, towards throat_pores[:, 0] (default the face itself). NaN where the
    three disks leave no sampled point open."""
    from scipy.spatial import cKDTree

    pk = tess.packing
    X = pk.centers[tess.throat_vertices[throats]]                         # (M, 3, 3)
    r3 = pk.radii[tess.throat_vertices[throats]]
    nrm = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    if heights is not None:
        cen = tess.pore_centroid[tess.throat_pores[throats, 0]]
        nrm *= (np.sign(np.einsum("ij,ij->i", cen - X[:, 0], nrm)) * heights)[:, None]
    b = np.random.default_rng(seed).random((n_points, 2))
    flip = b.sum(axis=1) > 1
    b[flip] = 1 - b[flip]
    bw = np.column_stack([1 - b.sum(axis=1), b])
    tree = cKDTree(pk.centers)
    out = np.full(len(throats), np.nan)
    for part in np.array_split(np.arange(len(throats)), max(1, len(throats) // 20000)):
        pts = np.einsum("pk,mkc->mpc", bw, X[part])
        if heights is not None:
            pts += nrm[part][:, None, :]
        in3 = (np.linalg.norm(pts[:, :, None, :] - X[part][:, None], axis=3)
               < r3[part][:, None, :]).any(axis=2)
        dd, ii = tree.query(pts.reshape(-1, 3), k=12)
        inall = (dd < pk.radii[ii]).any(axis=1).reshape(in3.shape)
        open3 = (~in3).sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[part] = np.where(open3 > 0, (~in3 & inall).sum(axis=1) / open3, np.nan)
    return out


def equivalent_disks(tess, throats, n_points=128, seed=0):
    """Window radii (M, 3) enlarged so that the three-disk open area equals the open area left
    by all spheres: the open points inside another sphere (Monte Carlo, ``n_points`` on the
    triangle) are given to the vertex whose sphere surface is nearest, and that vertex's disk
    grows (bisection on :func:`throats.open_area`, vertex by vertex) until the three-disk open
    area has lost that much. Returns (radii, removed area fraction of the window's open area)."""
    import throats as th_
    from scipy.spatial import cKDTree

    pk = tess.packing
    X = pk.centers[tess.throat_vertices[throats]]
    r3 = tess.throat_radii[throats].copy()
    sides = tess.throat_sides[throats]
    b = np.random.default_rng(seed).random((n_points, 2))
    flip = b.sum(axis=1) > 1
    b[flip] = 1 - b[flip]
    bw = np.column_stack([1 - b.sum(axis=1), b])
    tree = cKDTree(pk.centers)
    a3 = th_.open_area(r3, sides)
    a_tri = th_.triangle_area(sides)
    dA = np.zeros((len(throats), 3))
    for part in np.array_split(np.arange(len(throats)), max(1, len(throats) // 10000)):
        pts = np.einsum("pk,mkc->mpc", bw, X[part])
        d3 = np.linalg.norm(pts[:, :, None, :] - X[part][:, None], axis=3) - r3[part][:, None, :]
        in3 = (d3 < 0).any(axis=2)
        dd, ii = tree.query(pts.reshape(-1, 3), k=12)
        extra = ~in3 & (dd < pk.radii[ii]).any(axis=1).reshape(in3.shape)
        near = np.argmin(d3, axis=2)
        for v in range(3):
            dA[part, v] = (extra & (near == v)).sum(axis=1) / n_points * a_tri[part]
    r_new = r3.copy()
    target = a3.copy()
    for v in range(3):
        target = target - dA[:, v]
        need = dA[:, v] > 0
        lo, hi = np.zeros(len(throats)), np.where(need, r3[:, v], 0.0)
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            rr = r_new.copy()
            rr[:, v] += mid
            a = np.nan_to_num(th_.open_area(rr, sides))
            over = a < target
            hi = np.where(need & over, mid, hi)
            lo = np.where(need & ~over, mid, lo)
        r_new[:, v] += np.where(need, 0.5 * (lo + hi), 0.0)
    return r_new, float(dA.sum() / np.nansum(a3))


def _q_section(V, disks, n=40):
    """Flow rate per unit pressure gradient times viscosity of a section: the triangle ``V``
    (3, 2) minus the disks ``[(centre (2,), radius), ...]``, u = 0 on the disks, no flux
    through the triangle's edges (symmetry, as in the window problem): -lap u = 1 by finite
    volumes on an n x n pixel grid over the triangle's bounding box (first order at the
    boundaries; used for ratios of sections on one grid)."""
    from scipy import sparse
    from scipy.sparse.linalg import spsolve

    lo = V.min(0); L = (V.max(0) - lo).max(); hgrid = L / n
    xs = lo[0] + (np.arange(n) + 0.5) * hgrid; ys = lo[1] + (np.arange(n) + 0.5) * hgrid
    Xg, Yg = np.meshgrid(xs, ys, indexing="ij")
    P = np.stack([Xg.ravel(), Yg.ravel()], 1)
    def inside_tri(P):
        s = []
        for i in range(3):
            a, b = V[i], V[(i + 1) % 3]
            s.append((b[0] - a[0]) * (P[:, 1] - a[1]) - (b[1] - a[1]) * (P[:, 0] - a[0]))
        s = np.array(s)
        return (s >= 0).all(0) | (s <= 0).all(0)
    tri = inside_tri(P)
    solid = np.zeros(len(P), bool)
    for c, r in disks:
        solid |= ((P - c) ** 2).sum(1) < r * r
    fluid = tri & ~solid
    nf = fluid.sum()
    if nf == 0:
        return 0.0
    ids = -np.ones(len(P), int); ids[fluid] = np.arange(nf)
    ids = ids.reshape(n, n); fl = fluid.reshape(n, n); so = (solid & tri).reshape(n, n) | (solid.reshape(n, n))
    rows, cols, vals = [], [], []
    diag = np.zeros(nf)
    for dx_, dy_ in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        a = np.roll(np.roll(ids, -dx_, 0), -dy_, 1)
        sa = np.roll(np.roll(so, -dx_, 0), -dy_, 1)
        valid = np.ones((n, n), bool)
        if dx_ == 1: valid[-1, :] = False
        if dx_ == -1: valid[0, :] = False
        if dy_ == 1: valid[:, -1] = False
        if dy_ == -1: valid[:, 0] = False
        m = fl & valid & (a >= 0)
        rows.append(ids[m]); cols.append(a[m]); vals.append(-np.ones(m.sum()))
        np.add.at(diag, ids[m], 1.0)
        w = fl & valid & (a < 0) & sa                # wall (Dirichlet 0)
        np.add.at(diag, ids[w], 1.0)
    A = sparse.csr_matrix((np.concatenate(vals + [diag]), (np.concatenate(rows + [np.arange(nf)]),
                           np.concatenate(cols + [np.arange(nf)]))), shape=(nf, nf))
    u = spsolve(A.tocsc(), np.full(nf, hgrid * hgrid))
    return float(u.sum() * hgrid * hgrid)



def section_flow_ratio(tess, throats, intrusion, n=40):
    """Q of each window's section with every sphere that cuts the face plane, over Q of the
    three-disk section (:func:`_q_section`, one grid); 1 where no other sphere intrudes."""
    from scipy.spatial import cKDTree

    pk = tess.packing
    tree = cKDTree(pk.centers)
    rmax = pk.radii.max()
    ratio = np.ones(len(throats))
    for k in np.flatnonzero(np.nan_to_num(intrusion) > 0):
        vid = tess.throat_vertices[throats[k]]
        X, r = pk.centers[vid], pk.radii[vid]
        e1 = (X[1] - X[0]) / np.linalg.norm(X[1] - X[0])
        nn = np.cross(X[1] - X[0], X[2] - X[0])
        nn /= np.linalg.norm(nn)
        e2 = np.cross(nn, e1)
        V = np.stack([[(x - X[0]) @ e1, (x - X[0]) @ e2] for x in X])
        d3 = [(V[i], r[i]) for i in range(3)]
        extra = []
        for j in tree.query_ball_point(X.mean(0), np.linalg.norm(X - X.mean(0), axis=1).max()
                                       + rmax):
            d = (pk.centers[j] - X[0]) @ nn
            if j not in vid and abs(d) < pk.radii[j]:
                p = pk.centers[j] - X[0]
                extra.append((np.array([p @ e1, p @ e2]), np.sqrt(pk.radii[j] ** 2 - d * d)))
        q3 = _q_section(V, d3, n)
        ratio[k] = _q_section(V, d3 + extra, n) / q3 if q3 > 0 else 1.0
    return ratio


def intrusion_report(bed, log=print):
    """Window intrusion of a bed's sample (per window class, power-weighted, at the face and
    half-way to the pore centre) and the network's k with equivalent disks
    (:func:`equivalent_disks`) at every height instead of the vertex spheres."""
    import dataclasses

    from network.flow import ConductanceOptions, SampleOptions, solve_network
    from network.packing import read_container

    pk, tess, res = _network(bed)
    th = np.asarray(res.throat_ids)
    cls = window_class(tess, th) if pk.grain_id is not None else np.zeros(th.size, int)
    g = np.asarray(res.throat_conductance)
    q = np.asarray(res.throat_flow_m3_s)
    power = np.where(g > 0, q**2 / np.where(g > 0, g, 1.0), 0.0)
    out = {"bed": str(bed), "k_whole_m2": res.permeability_whole_m2, "classes": {}}
    h_half = 0.5 * np.minimum(np.asarray(_conduit_heights(tess, th))[:, 0],
                              tess.throat_radii[th].max(axis=1))
    for name, heights in (("face", None), ("half", h_half)):
        f = window_intrusion(tess, th, heights)
        ok = np.isfinite(f)
        for code in np.unique(cls):
            m = ok & (cls == code)
            out["classes"].setdefault(CLASSES[code], {"n": int((cls == code).sum())})[
                f"intrusion_{name}_power_weighted"] = float(np.sum(power[m] * f[m])
                                                            / power[m].sum())
        out[f"intrusion_{name}_power_weighted"] = float(np.sum(power[ok] * f[ok])
                                                        / power[ok].sum())
    r_new, removed = equivalent_disks(tess, th)
    tr = tess.throat_radii.copy()
    tr[th] = r_new
    res2 = solve_network(pk, axis="z", sample=SampleOptions(container=read_container(bed)),
                         conductance=ConductanceOptions(policy="table-only",
                                                        model_options={"grain_mates": "off"}),
                         tessellation=dataclasses.replace(tess, throat_radii=tr))
    out["window_area_removed"] = removed
    out["k_equivalent_disks_m2"] = res2.permeability_whole_m2
    out["k_change_equivalent_disks"] = res2.permeability_whole_m2 / res.permeability_whole_m2 - 1
    # the resolved section flow with the intruding spheres, its ratio put on each conduit
    f_face = window_intrusion(tess, th)
    ratio = section_flow_ratio(tess, th, f_face)
    hit = np.nan_to_num(f_face) > 0
    out["n_windows_intruded"] = int(hit.sum())
    out["section_ratio_median_intruded"] = float(np.median(ratio[hit])) if hit.any() else 1.0
    out["section_ratio_power_weighted"] = float(np.sum(power * ratio) / power.sum())
    rmap = dict(zip(th.tolist(), ratio.tolist()))

    def scaled(on):
        from network.conductance import conduit_conductance

        def fn(tt, ids):
            cr = conduit_conductance(tt, ids, policy="table-only", grain_mates="off")
            gg = np.asarray(cr.g).copy()
            if on:
                rr = np.array([rmap.get(i, 1.0) for i in np.asarray(ids).tolist()])
                keep = ~np.asarray(cr.internal)
                gg[keep] *= rr[keep]
            return gg
        return fn

    ks = [solve_network(pk, axis="z", sample=SampleOptions(container=read_container(bed)),
                        conductance=ConductanceOptions(function=scaled(on)),
                        tessellation=tess).permeability_whole_m2 for on in (False, True)]
    out["k_change_section_ratio"] = ks[1] / ks[0] - 1
    log(json.dumps(out, indent=1))
    return out


def _conduit_heights(tess, throats):
    """Conduit heights (M, 2) of the conduit model (merged pore bodies), m."""
    from network.conductance import conduit_conductance

    return conduit_conductance(tess, throats, policy="table-only", qstar_fn=lambda r, s:
                               np.ones(len(r))).h_m


CLASSES = ("ordinary", "same", "deep", "ordinary, neck body")


def mates_bins(bed, ref=None, log=print):
    """The conduits' g with the grain mates taken out of the windows ('window') and out of
    every section ('all') over their g with the mates left in ('off'), dissipation-weighted
    geometric means by the window's intrusion (:func:`window_intrusion`, the bins of
    :func:`compare`); with ``ref`` (a ``compare`` JSON of the same bed) also the resolved
    comparison's g_net / g_LBM per bin times those ratios."""
    from network.conductance import conduit_conductance

    pk, tess, res = _network(bed)
    th = np.asarray(res.throat_ids)
    g = np.asarray(res.throat_conductance)
    q = np.asarray(res.throat_flow_m3_s)
    power = np.where(g > 0, q**2 / np.where(g > 0, g, 1.0), 0.0)
    intr = window_intrusion(tess, th)
    gs = {m: np.asarray(conduit_conductance(tess, th, policy="table-only", grain_mates=m).g)
          for m in ("off", "window", "all")}
    bins = json.loads(Path(ref).read_text())["intrusion_bins"] if ref else None
    out = []
    for b, (lo_, hi_) in enumerate(((0.0, 0.02), (0.02, 0.1), (0.1, 0.25), (0.25, 1.01))):
        m = (intr >= lo_) & (intr < hi_) & (gs["off"] > 0)
        row = {"intrusion": [lo_, min(hi_, 1.0)], "n": int(m.sum()),
               "power_share": float(power[m].sum() / power.sum())}
        for k in ("window", "all"):
            r = np.clip(gs[k][m] / gs["off"][m], 1e-3, 10)
            row[f"g_{k}_over_off"] = float(np.exp(np.sum(power[m] * np.log(r)) / power[m].sum()))
        if bins:
            row["g_off_over_lbm"] = bins[b]["g_ratio_power_weighted_log_mean"]
            for k in ("window", "all"):
                row[f"g_{k}_over_lbm"] = row[f"g_{k}_over_off"] * row["g_off_over_lbm"]
        out.append(row)
        log(json.dumps(row))
    return out


def _window_network(bed, grain_mates="window"):
    """Tessellation and the network's Stokes solution in the sample box with the default
    conduit model (table-only, grain mates out of the windows unless told otherwise)."""
    from network import tessellate
    from network.flow import ConductanceOptions, SampleOptions, solve_network
    from network.packing import read_container, read_packing

    pk = read_packing(bed)
    tess = tessellate(pk)
    cond = ConductanceOptions(policy="table-only", model_options={"grain_mates": grain_mates})
    res = solve_network(pk, axis="z", sample=SampleOptions(container=read_container(bed)),
                        conductance=cond, tessellation=tess)
    return pk, tess, res


def mate_classes(tess, th):
    """Each conduit's grain-mate class and its g in the three modes: 'untouched' (no grain
    mate cuts the window or any section), 'sections cut' (the window is not cut, some
    section is: 'all' lowers g by 3 % or more), 'window cut' (a mate takes flow rate from the
    window); returns (codes 0 / 1 / 2, window factors, {mode: g})."""
    from network.conductance import conduit_conductance
    from network.conductance._mates import window_factors_compiled

    wf = (np.ones(len(th)) if tess.packing.grain_id is None       # spheres: no grain mates
          else window_factors_compiled(tess.packing, tess.throat_vertices[th]))
    gs = {m: np.asarray(conduit_conductance(tess, th, policy="table-only", grain_mates=m).g)
          for m in ("off", "window", "all")}
    ok = gs["window"] > 0
    ra = np.where(ok, gs["all"] / np.where(ok, gs["window"], 1.0), 1.0)
    code = np.where(wf < 1.0, 2, np.where(ra < 0.97, 1, 0))
    return code, wf, gs


MATE_CLASSES = ("untouched", "sections cut", "window cut")


def side_grains(tess, th):
    """(M, 2) grains spanned by the tetrahedra on the two sides of each conduit, the smaller
    first (a hull face's one side counted twice; 4 on sphere packings, whose every sphere is
    its own grain). A tetrahedron with two spheres of one grain (3 or fewer) is a piece of
    a void that the grain's spheres split."""
    pv = tess.pore_vertices
    gid = grain_ids(tess.packing)
    n = 1 + (np.diff(np.sort(gid[pv], axis=1), axis=1) != 0).sum(axis=1)
    tp = tess.throat_pores[np.asarray(th, dtype=np.int64)].copy()
    tp[tp[:, 1] < 0, 1] = tp[tp[:, 1] < 0, 0]
    return np.sort(n[tp], axis=1)


def fragment_overlap(tess, th):
    """(M,) the deepest overlap of two spheres of one grain in a conduit's fragment sides,
    (r_i + r_j - l_ij) / min(r_i, r_j); -inf where neither side is a fragment
    (:func:`side_grains`)."""
    pv = tess.pore_vertices
    gid = grain_ids(tess.packing)
    c, r = tess.packing.centers, tess.packing.radii
    ov = np.full(pv.shape[0], -np.inf)
    for a in range(4):
        for b in range(a + 1, 4):
            i, j = pv[:, a], pv[:, b]
            o = (r[i] + r[j] - np.linalg.norm(c[i] - c[j], axis=1)) / np.minimum(r[i], r[j])
            ov = np.where(gid[i] == gid[j], np.maximum(ov, o), ov)
    tp = tess.throat_pores[np.asarray(th, dtype=np.int64)].copy()
    tp[tp[:, 1] < 0, 1] = tp[tp[:, 1] < 0, 0]
    return ov[tp].max(axis=1)


#: :func:`side_grains` classes of ``compare``'s ``mate_class_bins``: (label, test on (M, 2))
SIDE_CLASSES = (("side tetrahedra: four grains both", lambda s: s[:, 0] == 4),
                ("side tetrahedra: three and four grains", lambda s: (s[:, 0] == 3) & (s[:, 1] == 4)),
                ("side tetrahedra: three grains both", lambda s: (s[:, 0] == 3) & (s[:, 1] == 3)),
                ("side tetrahedra: two grains on a side", lambda s: s[:, 0] <= 2))


def classes_report(bed, log=print):
    """Where a bed's dissipation goes in the network (the default model): each conduit's
    share q^2/g of the Stokes dissipation (its d ln k / d ln g) by window class (a deep pair
    of one grain or three grains), grain-mate class (:func:`mate_classes`), the smallest over
    the largest of the window's three radii, and the windows the mates nearly close
    (:func:`throats.section_ratio`'s shape-factor branch); and the first-order change of k
    from 'window' to 'off' and to 'all' per class."""
    from throats import deep_overlap, sub_triangle_centroids, triangle_vertices

    pk, tess, res = _window_network(bed)
    th = np.asarray(res.throat_ids)
    q, g = np.asarray(res.throat_flow_m3_s), np.asarray(res.throat_conductance)
    ok = np.isfinite(q) & np.isfinite(g) & (g > 0)
    power = np.where(ok, q**2 / np.where(ok, g, 1.0), 0.0)
    share = power / power.sum()
    deep = deep_overlap(tess.throat_radii[th], tess.throat_sides[th])
    code, wf, gs = mate_classes(tess, th)
    r = tess.throat_radii[th]
    ratio = r.min(axis=1) / r.max(axis=1)
    # three-disk open fraction on the 16^2 sub-triangle centroids (section_ratio's rule)
    s = tess.throat_sides[th]
    V = triangle_vertices(s)
    b1, b2 = sub_triangle_centroids(16)
    px, py = V[:, None, 1, 0] * b1 + V[:, None, 2, 0] * b2, V[:, None, 2, 1] * b2
    d3 = np.hypot(px, py) - r[:, None, 0]
    for k in (1, 2):
        d3 = np.minimum(d3, np.hypot(px - V[:, None, k, 0], py - V[:, None, k, 1])
                        - r[:, None, k])
    narrow = (wf < 1.0) & ((d3 > 0).mean(axis=1) < 0.1)
    gw = np.where(gs["window"] > 0, gs["window"], 1.0)
    out = {"bed": str(bed), "k_m2": res.permeability_m2, "n_conduits": int(th.size),
           "narrow_cut_windows": {"n": int(narrow.sum()), "share": float(share[narrow].sum())},
           "rows": []}
    groups = [("all", np.ones(th.size, bool))]
    groups += [(f"{w} / {MATE_CLASSES[c]}", (deep == d) & (code == c))
               for d, w in ((False, "three grains"), (True, "deep pair")) for c in range(3)]
    groups += [(f"radius ratio {lo}-{hi}", (ratio >= lo) & (ratio < hi))
               for lo, hi in ((0.0, 0.6), (0.6, 0.8), (0.8, 0.95), (0.95, 1.01))]
    for name, m in groups:
        row = {"class": name, "n": int(m.sum()), "share": float(share[m].sum())}
        for mode in ("off", "all"):
            rr = np.where(gs["window"][m] > 0, gs[mode][m] / gw[m], 1.0)
            row[f"dlnk_{mode}_minus_window"] = float(np.sum(share[m]
                                                            * np.log(np.maximum(rr, 1e-3))))
        out["rows"].append(row)
        log(json.dumps(row))
    return out


def fe_check(bed, log=print):
    """The network's k on a bed with FE in place of its two estimates: every cut window's
    factor by :func:`throats.section_fem` (the section with its live grain mates over the
    three-disk section) against :func:`throats.section_ratio`, and every window and section
    the Q* table cannot answer by :func:`throats.solve_fem` (table-only gives such a window
    the shape-factor estimate and continues such a section by cell-model ratios)."""
    import throats
    from network.conductance import _conduit
    from network.conductance._mates import _live, grain_mates, mate_radii
    from network.conductance._qstar import QstarResult
    from network.flow import ConductanceOptions, SampleOptions, solve_network
    from network.packing import read_container

    pk, tess, res = _window_network(bed)
    th = np.asarray(res.throat_ids)
    solve = lambda: solve_network(pk, axis="z",                           # noqa: E731
                                  sample=SampleOptions(container=read_container(bed)),
                                  conductance=ConductanceOptions(policy="table-only"),
                                  tessellation=tess).permeability_m2
    k0 = res.permeability_m2
    wf = _conduit.window_factors_compiled(pk, tess.throat_vertices[th])
    cut = np.flatnonzero(wf < 1.0)
    vt = tess.throat_vertices[th[cut]]
    sides, radii = tess.throat_sides[th[cut]], tess.throat_radii[th[cut]]
    mates = grain_mates(pk, vt, np.zeros((cut.size, 2)), np.ones((cut.size, 2)))
    rho = mate_radii(mates, np.zeros(mates.rows.size))
    live = _live(mates, rho, throats.triangle_vertices(sides[mates.rows]), radii[mates.rows])
    fe = np.full(cut.size, np.nan)
    for j, i in enumerate(mates.rows):
        e = live[j]
        V = throats.triangle_vertices(sides[i:i + 1])
        qa, sa = throats.section_fem(sides[i:i + 1],
                                     np.concatenate([V[0], mates.center[j][e]])[None],
                                     np.concatenate([radii[i], rho[j][e]])[None])
        q3, s3 = throats.section_fem(sides[i:i + 1], V, radii[i:i + 1])
        if s3[0] == "ok" and sa[0] in ("ok", "closed"):
            fe[i] = qa[0] / q3[0]
    good = np.isfinite(fe) & (fe > 0)
    err = wf[cut][good] / fe[good] - 1.0
    out = {"bed": str(bed), "k_m2": k0, "n_cut_windows": int(cut.size),
           "n_fe": int(good.sum()), "ratio_error_median_abs": float(np.median(np.abs(err))),
           "ratio_error_p95_abs": float(np.percentile(np.abs(err), 95)),
           "ratio_error_max_abs": float(np.abs(err).max()),
           "ratio_error_signed_median": float(np.median(err))}
    key = {tuple(v): f for v, f in zip(map(tuple, vt[np.isfinite(fe)]), fe[np.isfinite(fe)])}
    orig_wf, orig_q = _conduit.window_factors_compiled, _conduit.policy_qstar

    def fe_factors(packing, vertices, **kw):
        f = orig_wf(packing, vertices, **kw)
        for a, v in enumerate(map(tuple, np.asarray(vertices))):
            f[a] = key.get(v, f[a])
        return f

    count = {"n": 0}

    def fe_outside(r, s, **kw):
        q = orig_q(r, s, **kw)
        src = np.asarray(q.source)
        bad = np.flatnonzero(src == "shape-factor")
        if bad.size == 0:
            return q
        qf = np.asarray(throats.solve_fem(np.asarray(r)[bad], np.asarray(s)[bad],
                                          rtol=1e-2).qstar, float)
        fine = np.isfinite(qf) & (qf >= 0)
        qq, ss = np.asarray(q.qstar, float).copy(), src.astype("<U24")
        qq[bad[fine]], ss[bad[fine]] = qf[fine], "fe"
        count["n"] += int(fine.sum())
        return QstarResult(qq, ss, q.error_estimate, q.stats)

    try:
        _conduit.window_factors_compiled = fe_factors
        out["k_fe_window_factors_m2"] = solve()
        _conduit.window_factors_compiled = orig_wf
        _conduit.policy_qstar = fe_outside
        out["k_fe_outside_table_m2"] = solve()
    finally:
        _conduit.window_factors_compiled, _conduit.policy_qstar = orig_wf, orig_q
    out["n_fe_outside_table"] = count["n"]
    out["change_fe_window_factors"] = out["k_fe_window_factors_m2"] / k0 - 1.0
    out["change_fe_outside_table"] = out["k_fe_outside_table_m2"] / k0 - 1.0
    log(json.dumps(out, indent=1))
    return out


def _network_with_resolved_g(pk, tess, bed, th, g_res, g_net, qn):
    """k (m², whole sample) of the network whose conduits ``th`` take the resolved
    conductance ``g_res`` (m³ Pa⁻¹ s⁻¹, where finite and positive; the network's ``g_net``
    elsewhere and in merged bodies), and the share of the network's Stokes dissipation
    (flows ``qn``) those conduits carry. The sum of the per-conduit errors is then the
    network's k over this one; this one over the lattice's is the estimator's own error (its
    body potentials) and the network's topology."""
    from network.flow import ConductanceOptions, SampleOptions, solve_network
    from network.packing import read_container

    internal = g_net > 1e3 * np.median(g_net[g_net > 0])
    use = np.isfinite(g_res) & (g_res > 0) & ~internal
    table = dict(zip(np.asarray(th)[use].tolist(), g_res[use].tolist()))
    def g_of(t, ids):
        from network.conductance import conduit_conductance

        g = np.asarray(conduit_conductance(t, ids, policy="table-only", grain_mates="off").g)
        swap = np.array([table.get(int(i), np.nan) for i in np.asarray(ids)])
        return np.where(np.isfinite(swap), swap, g)

    res = solve_network(pk, axis="z", sample=SampleOptions(container=read_container(bed)),
                        conductance=ConductanceOptions(function=g_of), tessellation=tess)
    power = np.where(g_net > 0, qn**2 / np.where(g_net > 0, g_net, 1.0), 0.0)
    return float(res.permeability_whole_m2), float(power[use].sum() / power.sum())


def compare(field_npz, log=print):
    """Per-conduit resolved flux and conductance against the network's (module docstring)."""
    z = np.load(field_npz)
    shape = tuple(int(v) for v in z["shape"])
    solid = np.unpackbits(z["bits"], count=int(np.prod(shape))).reshape(shape).astype(bool)
    dx, lo, gx, tau = float(z["dx_m"]), z["lo_m"], float(z["gx"]), float(z["tau"])
    nu = (tau - 0.5) / 3.0
    rho, u = z["rho"], z["u"]
    pk, tess, res = _network(str(z["bed"]))
    # node positions (bed coordinates) of the fluid nodes; lattice axes (z, x, y) of the bed
    fl = np.flatnonzero(~solid.ravel())
    i0, i1, i2 = np.unravel_index(fl, shape)
    pts = np.column_stack([lo[0] + (i1 + 0.5) * dx, lo[1] + (i2 + 0.5) * dx,
                           lo[2] + (i0 + 0.5) * dx])
    tet, matched = _voxel_tets(tess, pts)
    log(f"# {fl.size} fluid nodes, {np.mean(tet >= 0):.4f} located in a tetrahedron "
        f"({matched:.4f} of qhull's simplices matched)")
    # resolved flux through each sample face: midpoint rule on n^2 sub-triangles (n: sides
    # split to <= dx/2), velocity trilinear between nodes, zero in the solid; sign: towards
    # the tetrahedron throat_pores[:, 1]
    from scipy import ndimage

    th = np.asarray(res.throat_ids)
    grid_u = np.zeros((3,) + shape)
    for a_ in range(3):
        grid_u[a_].ravel()[fl] = u[a_]
    ub = [grid_u[1], grid_u[2], grid_u[0]]                    # bed x, y, z components
    X = tess.packing.centers[tess.throat_vertices[th]]        # (M, 3, 3)
    nrm = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    area = 0.5 * np.linalg.norm(nrm, axis=1)
    nrm /= 2.0 * area[:, None]
    cen1 = tess.pore_centroid[tess.throat_pores[th, 1]]
    nrm *= np.sign(np.einsum("ij,ij->i", cen1 - X[:, 0], nrm))[:, None]
    side = np.max(np.linalg.norm(X - np.roll(X, 1, axis=1), axis=2), axis=1)
    nsub = np.maximum(np.ceil(side / (0.5 * dx)).astype(int), 1)
    q_face = np.zeros(th.size)
    for n in np.unique(nsub):
        rows = np.flatnonzero(nsub == n)
        i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        up = (i + j) <= n - 1
        dn = (i + j) <= n - 2
        b1 = np.r_[(i[up] + 1 / 3) / n, (i[dn] + 2 / 3) / n]
        b2 = np.r_[(j[up] + 1 / 3) / n, (j[dn] + 2 / 3) / n]
        bw = np.stack([1 - b1 - b2, b1, b2])                  # (3, P)
        for part in np.array_split(rows, max(1, rows.size * bw.shape[1] // 2_000_000)):
            P = np.einsum("kp,mkc->mpc", bw, X[part])         # (m, P, 3)
            # node (i0 flow, i1, i2) at lo + (i + 1/2) dx: fractional index = (x - lo)/dx - 1/2
            fi = (P - lo) / dx - 0.5
            coords = np.stack([fi[..., 2].ravel(), fi[..., 0].ravel(), fi[..., 1].ravel()])
            un = np.zeros(coords.shape[1])
            nn = np.repeat(nrm[part], bw.shape[1], axis=0)
            for c_ in range(3):
                un += nn[:, c_] * ndimage.map_coordinates(ub[c_], coords, order=1, mode="nearest")
            q_face[part] = un.reshape(part.size, -1).mean(axis=1) * area[part] / dx**2
    q_t = np.zeros(tess.n_throats)
    q_t[th] = q_face                                          # lu^3 / step
    # pore bodies of the sample: mean driving potential P = c_s^2 rho - rho0 g s
    n_t = tess.n_pores
    labels = np.asarray(res.pore_groups) if res.pore_groups is not None else np.arange(n_t)
    body_ids = np.asarray(res.pore_ids)
    loc = np.full(labels.max() + 2, -1, dtype=np.int64)
    loc[body_ids] = np.arange(body_ids.size)
    node_body = np.where(tet >= 0, loc[labels[np.maximum(tet, 0)]], -1)
    s_lu = i0 + 0.5
    P = CS2 * rho - rho.mean() * gx * s_lu
    inb = node_body >= 0
    cnt = np.bincount(node_body[inb], minlength=body_ids.size)
    Pb = np.bincount(node_body[inb], P[inb], minlength=body_ids.size) / np.maximum(cnt, 1)
    # the sample's conduits
    conns = np.asarray(res.conns)
    mu = res.viscosity_pa_s
    g_net = np.asarray(res.throat_conductance) * mu                       # m^3
    dP = Pb[conns[:, 0]] - Pb[conns[:, 1]]
    good = (cnt[conns[:, 0]] > 0) & (cnt[conns[:, 1]] > 0)
    g_lbm = np.where(good & (np.abs(dP) > 0), nu * q_t[th] / np.where(dP != 0, dP, 1), np.nan) \
        * dx**3                                                          # mu g, m^3
    # network flows at the lattice's mean gradient, as mu Q / G (m^4)
    G_net = mu * res.velocity_m_s / res.permeability_whole_m2            # (p_in - p_out) / L
    qn = np.asarray(res.throat_flow_m3_s) * mu / G_net
    ql = q_t[th] * nu / (rho.mean() * gx) * dx**4
    k_lbm = float(z["k_lu2"]) * dx**2
    # conservation of the resolved face fluxes on the bodies (lateral and end bodies lose
    # conduits cut by the sample's faces: the median is the check)
    nb = body_ids.size
    net_b = np.bincount(conns[:, 0], -ql, nb) + np.bincount(conns[:, 1], ql, nb)
    tot_b = np.bincount(conns[:, 0], np.abs(ql), nb) + np.bincount(conns[:, 1], np.abs(ql), nb)
    imbalance = float(np.median(np.abs(net_b[tot_b > 0]) / tot_b[tot_b > 0]))
    log(f"# body flux imbalance |sum q| / sum |q|: median {imbalance:.3f}")
    cls = window_class(tess, th)
    # pore bodies holding a tetrahedron with two spheres of one grain (a neck inside the body)
    gv = grain_ids(tess.packing)[tess.pore_vertices]
    neck_t = np.zeros(n_t, dtype=bool)
    for i_ in range(4):
        for j_ in range(i_ + 1, 4):
            neck_t |= gv[:, i_] == gv[:, j_]
    neck_b = np.zeros(body_ids.size, dtype=bool)
    sel = loc[labels] >= 0
    np.logical_or.at(neck_b, loc[labels][sel], neck_t[sel])
    cls = np.where((cls == 0) & (neck_b[conns[:, 0]] | neck_b[conns[:, 1]]), 3, cls)
    closed = ~(g_net > 0)
    out = {"field": str(field_npz), "bed": str(z["bed"]), "resolution": float(z["resolution"]),
           "k_lbm_m2": k_lbm, "k_net_whole_m2": res.permeability_whole_m2,
           "k_net_over_lbm": res.permeability_whole_m2 / k_lbm,
           "body_imbalance_median": imbalance, "classes": {}}
    # the estimator's own check: the network with the resolved conductance of every conduit
    # that has one (the network's elsewhere, and inside merged bodies), against the lattice's k
    k_res, share = _network_with_resolved_g(pk, tess, str(z["bed"]), th, g_lbm / mu,
                                            g_net / mu, qn)
    out["k_net_resolved_g_over_lbm"] = k_res / k_lbm
    out["resolved_g_dissipation_share"] = share
    log(f"# the network with the resolved g of {share:.3f} of its dissipation: k "
        f"{k_res / k_lbm - 1:+.3f} against the lattice")
    power_net = np.where(g_net > 0, qn**2 / np.where(g_net > 0, g_net, 1), 0.0)
    for code, name in enumerate(CLASSES):
        m = (cls == code) & ~closed
        r = g_net[m] / g_lbm[m]
        fin = np.isfinite(r) & (r > 0)
        w = np.abs(ql[m])
        out["classes"][name] = {
            "n": int(m.sum()), "n_closed": int(((cls == code) & closed).sum()),
            "abs_flux_share_lbm": float(np.abs(ql[m]).sum() / np.abs(ql[~closed]).sum()),
            "abs_flux_share_net": float(np.abs(qn[m]).sum() / np.abs(qn[~closed]).sum()),
            "power_share_net": float(power_net[m].sum() / power_net.sum()),
            "flux_ratio_net_over_lbm": float(np.abs(qn[m]).sum() / np.abs(ql[m]).sum()),
            "g_ratio_median": float(np.median(r[fin])) if fin.any() else None,
            "g_ratio_power_weighted_log_mean": float(np.exp(
                np.sum(power_net[m][fin] * np.log(np.clip(r[fin], 0.1, 10)))
                / power_net[m][fin].sum())) if fin.any() else None,
            "dlnk_contribution": float(np.sum(power_net[m][fin] * np.log(np.clip(r[fin], 0.1, 10)))
                                       / power_net.sum()) if fin.any() else None,
            "g_ratio_flux_weighted_log_mean": float(np.exp(np.sum(w[fin] * np.log(r[fin]))
                                                           / w[fin].sum())) if fin.any() else None,
        }
        # closed windows that carry resolved flux
        mc = (cls == code) & closed
        out["classes"][name]["closed_abs_flux_share_lbm"] = float(
            np.abs(ql[mc]).sum() / np.abs(ql).sum())
    # the same by the window's intrusion (open area of the three-disk section inside other
    # spheres)
    intr = window_intrusion(tess, th)
    out["intrusion_bins"] = []
    for lo_, hi_ in ((0.0, 0.02), (0.02, 0.1), (0.1, 0.25), (0.25, 1.01)):
        m = (intr >= lo_) & (intr < hi_) & ~closed
        r = g_net[m] / g_lbm[m]
        fin = np.isfinite(r) & (r > 0)
        out["intrusion_bins"].append({
            "intrusion": [lo_, min(hi_, 1.0)], "n": int(m.sum()),
            "n_deep": int((m & (cls == 2)).sum()),
            "power_share_net": float(power_net[m].sum() / power_net.sum()),
            "flux_ratio_net_over_lbm": float(np.abs(qn[m]).sum() / np.abs(ql[m]).sum()),
            "g_ratio_median": float(np.median(r[fin])) if fin.any() else None,
            "g_ratio_power_weighted_log_mean": float(np.exp(
                np.sum(power_net[m][fin] * np.log(np.clip(r[fin], 0.1, 10)))
                / power_net[m][fin].sum())) if fin.any() else None})
    # the same conduits' g with the grain mates out of the windows and out of every section,
    # each mode's g over the resolved g, by grain-mate class (:func:`mate_classes`) and by the
    # window's intrusion; weights: the dissipation with the mates left in, as above
    mcode, _, gs = mate_classes(tess, th)
    off = np.where(gs["off"] > 0, gs["off"], np.nan)
    g_mode = {m: g_net * gs[m] / off for m in ("off", "window", "all")}

    def mode_ratios(m):
        row = {}
        for mode, gm in g_mode.items():
            r = gm[m] / g_lbm[m]
            fin = np.isfinite(r) & (r > 0)
            row[f"g_{mode}_over_lbm"] = float(np.exp(
                np.sum(power_net[m][fin] * np.log(np.clip(r[fin], 0.1, 10)))
                / power_net[m][fin].sum())) if fin.any() else None
        return row

    out["mate_class_bins"] = []
    deep = cls == 2
    sides = side_grains(tess, th)
    f_ov = fragment_overlap(tess, th)
    r3 = tess.throat_radii[th]
    ratio = r3.min(axis=1) / r3.max(axis=1)          # the window's smallest radius / largest
    for name, m in ([(MATE_CLASSES[c], mcode == c) for c in range(3)]
                    + [(f"{w} / {MATE_CLASSES[c]}", (deep == d) & (mcode == c))
                       for d, w in ((False, "three grains"), (True, "deep pair"))
                       for c in range(3)]
                    + [(f"intrusion {lo_}-{min(hi_, 1.0)}", (intr >= lo_) & (intr < hi_))
                       for lo_, hi_ in ((0.0, 0.02), (0.02, 0.1), (0.1, 0.25), (0.25, 1.01))]
                    + [(f"radius ratio {op} 0.6{c}", ((ratio < 0.6) == small) & m_c)
                       for op, small in (("<", True), (">=", False))
                       for c, m_c in (("", True), (" / untouched", mcode == 0))]
                    + [(label, test(sides)) for label, test in SIDE_CLASSES]
                    + [(f"fragment pair overlap {lo_}-{hi_}", (f_ov >= lo_) & (f_ov < hi_))
                       for lo_, hi_ in ((0.0, 0.5), (0.5, 1.0), (1.0, 1.5), (1.5, 2.0))]
                    + [("all", np.ones(th.size, bool))]):
        m = m & ~closed
        out["mate_class_bins"].append({"class": name, "n": int(m.sum()),
                                       "power_share_net": float(power_net[m].sum()
                                                                / power_net.sum()),
                                       **mode_ratios(m)})
    out["per_conduit"] = {"intrusion": np.nan_to_num(intr, nan=-1.0).tolist(),"throat": th.tolist(), "class": cls.tolist(), "q_lbm_m4": ql.tolist(),
                          "q_net_m4": qn.tolist(), "mu_g_net_m3": g_net.tolist(),
                          "mu_g_lbm_m3": np.nan_to_num(g_lbm, nan=-1.0).tolist()}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="Stokes field of a bed's sample box")
    r.add_argument("bed")
    r.add_argument("--resolution", type=float, default=16.0, help="lattice units per d32")
    r.add_argument("--max-steps", type=int, default=12000)
    r.add_argument("--tau", type=float, default=1.5,
                   help="relaxation time (TRT with Lambda 3/16: the steady field does not "
                        "depend on it; a smaller one relaxes the density faster)")
    r.add_argument("--tol", type=float, default=1e-5)
    r.add_argument("--out", required=True, help="NPZ of the field")
    c = sub.add_parser("compare", help="per-conduit comparison with the network")
    c.add_argument("field")
    c.add_argument("--json", default=None)
    g = sub.add_parser("mates", help="the conduits' g with grain mates out, by intrusion")
    g.add_argument("bed")
    g.add_argument("--ref", default=None, help="a compare JSON of the same bed")
    k = sub.add_parser("classes", help="the network's dissipation by window and mate class")
    k.add_argument("beds", nargs="+")
    k.add_argument("--json", default=None)
    f = sub.add_parser("fe-check", help="k with FE for the window factors and the sections "
                       "outside the table")
    f.add_argument("beds", nargs="+")
    f.add_argument("--json", default=None)
    i = sub.add_parser("intrusion", help="window area inside spheres off the face")
    i.add_argument("beds", nargs="+")
    i.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    if a.cmd == "mates":
        mates_bins(a.bed, a.ref)
        return 0
    if a.cmd in ("classes", "fe-check"):
        fn = classes_report if a.cmd == "classes" else fe_check
        rows = [fn(b) for b in a.beds]
        if a.json:
            Path(a.json).write_text(json.dumps(rows, indent=1) + "\n")
        return 0
    if a.cmd == "intrusion":
        rows = [intrusion_report(b) for b in a.beds]
        if a.json:
            Path(a.json).write_text(json.dumps(rows, indent=1) + "\n")
        return 0
    if a.cmd == "run":
        res = run_field(a.bed, a.resolution, tau=a.tau, max_steps=a.max_steps, tol=a.tol)
        solid = res.pop("solid")
        np.savez_compressed(a.out, bits=np.packbits(solid.ravel()), shape=solid.shape,
                            **{k: np.asarray(v) for k, v in res.items()})
        print(f"wrote {a.out}: k {res['k_lu2'] * res['dx_m']**2:.4e} m2")
        return 0
    res = compare(a.field)
    print(json.dumps({k: res[k] for k in ("k_net_over_lbm", "body_imbalance_median", "classes",
                                          "intrusion_bins", "mate_class_bins")}, indent=1))
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
