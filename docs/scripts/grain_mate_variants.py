"""The grain beds' Stokes k under variants of the conduit model's grain-mate treatment and pore
bodies, against the fine lattice-Boltzmann k of ``docs/data/lbm_grains_reference.json``.

Research script of ``docs/validation-grains.md`` ("Where the difference comes from"); the
network is ``network.solve``'s (conduit model, table-only, flow along z, the bed's own box).
Each variant is a question about the model, answered on all three beds; none is a candidate
fitted to the reference, and none changes the package.

``sections``  k with the grain mates left in (``off``), out of the windows (``window``) and
              out of every section (``all``) at 6 (the default), 12 and 24 section intervals:
              whether a treatment's k is converged in the conduit's discretisation.
``tetra``     k with a mate counted at a section only where its circle enters the section of
              the tetrahedron on that side (the face triangle contracted towards the projection
              of the fourth vertex by 1 - h / h_4); halves into merged pore bodies keep the
              whole section. Asks whether ``all`` counts mates that lie in neighbouring pores.
``slope``     k with the conduit integral's slope factor 1 + s/(1+s) set to 1 (every section's y
              alone, :func:`network.conductance._sections.side_resistance`): whether the
              bounded second-order correction is what the grain beds' short, steep conduit
              halves get wrong.
``merge``     k with no pore bodies merged, and with each *fragment* (a tetrahedron whose four
              spheres belong to three grains: two spheres of one grain) joined to the
              neighbour across the wider of its two three-grain faces (the larger flow-rate
              estimate, cell model times the grain mates' factor; the narrower face stays the
              window), when that neighbour spans four grains, is no sliver and the face is
              open. Asks whether the pieces a grain's spheres cut one void into add spurious
              resistance in series.

    python docs/scripts/grain_mate_variants.py sections --bed corn=shelled_corn.csv
    python docs/scripts/grain_mate_variants.py tetra --bed corn=shelled_corn.csv
    python docs/scripts/grain_mate_variants.py merge --bed corn=shelled_corn.csv

(``shelled_corn.csv``: the corn bed of ``lbm_grains_reference.json``'s ``beds`` entry; the
soybean and wheat beds are bundled.)
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))                                     # the repository's packages

REFERENCE = ROOT / "docs" / "data" / "lbm_grains_reference.json"
GRAIN_BEDS = ("soybean", "wheat", "corn")


def fine_reference(path=REFERENCE):
    """{bed: (file, the finest lattice's Stokes k, m²)} of the grain beds."""
    ref = json.loads(Path(path).read_text())
    out = {}
    for run in ref["runs"]:
        name = run["bed_name"]
        if name in GRAIN_BEDS and run["resolution"] > out.get(name, (None, 0, 0))[2]:
            out[name] = (run["bed"], run["k_stokes_m2"], run["resolution"])
    return {k: (v[0], v[1]) for k, v in out.items()}


def solve_k(packing, box, tess, *, grain_mates="window", n_sections=6, merge=None, threads=None):
    """``network.solve``'s ``permeability_m2`` along z; ``merge``: None (the default pore
    bodies), False (none merged) or a callable ``tess -> PoreMerge``."""
    import network.flow._pipeline as pipeline
    from network.flow import ConductanceOptions, SampleOptions, solve_network

    opts = {"grain_mates": grain_mates, "n_sections": n_sections,
            **({} if threads is None else {"threads": threads})}
    saved = pipeline.merge_pores
    if callable(merge):
        pipeline.merge_pores = merge
    try:
        cond = ConductanceOptions(policy="table-only", merge_ties=merge is not False,
                                  model_options={**opts, **({"merge": False}
                                                            if merge is False else {})})
        res = solve_network(packing, axis="z", sample=SampleOptions(container=box),
                            conductance=cond, tessellation=tess)
    finally:
        pipeline.merge_pores = saved
    return float(res.permeability_m2)


# -- tetra: mates counted only inside the tetrahedron's own section ------------------------

def _circle_points_inside(mates, rho, region, n_angles=16):
    """(R, E, A) bool: each of ``n_angles`` points of each mate circle (radii ``rho`` (R, E))
    inside the row's counter-clockwise triangle ``region`` (R, 3, 2); NaN rows: True."""
    th = np.linspace(0.0, 2.0 * np.pi, n_angles, endpoint=False)
    px = mates.center[..., 0, None] + rho[..., None] * np.cos(th)          # (R, E, A)
    py = mates.center[..., 1, None] + rho[..., None] * np.sin(th)
    inside = np.ones(px.shape, dtype=bool)
    for k in range(3):
        p0, p1 = region[:, k], region[:, (k + 1) % 3]
        ex = (p1[:, 0] - p0[:, 0])[:, None, None]
        ey = (p1[:, 1] - p0[:, 1])[:, None, None]
        inside &= ex * (py - p0[:, 1, None, None]) - ey * (px - p0[:, 0, None, None]) >= 0
    return inside | ~np.isfinite(region[:, 0, 0])[:, None, None], px, py


def _live_in_region(mates, rho, V, rv, region, n_angles=16):
    """``_mates._live``'s test with the circle's points also inside ``region``: (R, E) bool,
    the mates with a circle point inside the face triangle ``V``, outside the vertex disks
    ``rv`` (R, 3) and inside the tetrahedron's section ``region``."""
    in_v, px, py = _circle_points_inside(mates, rho, V, n_angles)
    in_r, _, _ = _circle_points_inside(mates, rho, region, n_angles)
    ok = in_v & in_r & (rho > 0)[..., None]
    for k in range(3):
        ok &= (np.hypot(px - V[:, k, None, None, 0], py - V[:, k, None, None, 1])
               >= rv[:, k, None, None])
    return ok.any(axis=2)


def tetrahedron_apex(tess, idx, whole):
    """(M, 2, 3): per half, the fourth vertex of its side's tetrahedron in the face frame of
    ``network.conductance._mates.grain_mates`` (u, v, |height|); NaN where ``whole``."""
    idx = np.asarray(idx, dtype=np.int64)
    tv = tess.throat_vertices[idx]
    tp = tess.throat_pores[idx].copy()
    tp[tp[:, 1] < 0, 1] = tp[tp[:, 1] < 0, 0]
    cen = tess.packing.centers
    x0 = cen[tv[:, 0]]
    e1 = cen[tv[:, 1]] - x0
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    nrm = np.cross(cen[tv[:, 1]] - x0, cen[tv[:, 2]] - x0)
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    e2 = np.cross(nrm, e1)
    out = np.full((idx.size, 2, 3), np.nan)
    for c in (0, 1):
        pv = tess.pore_vertices[tp[:, c]]
        fourth = (pv != tv[:, :1]) & (pv != tv[:, 1:2]) & (pv != tv[:, 2:3])
        x4 = cen[pv[np.arange(idx.size), np.argmax(fourth, axis=1)]] - x0
        out[:, c] = np.column_stack([np.einsum("nk,nk->n", x4, e1),
                                     np.einsum("nk,nk->n", x4, e2),
                                     np.abs(np.einsum("nk,nk->n", x4, nrm))])
        out[(fourth.sum(axis=1) != 1) | ~(out[:, c, 2] > 0), c] = np.nan
    out[np.asarray(whole, dtype=bool)] = np.nan
    return out


def tetra_k(packing, box, tess):
    """k with ``all``'s section factors restricted to mates that enter the tetrahedron's own
    section (module docstring), by wrapping the conduit model's ``grain_mates_of``,
    ``section_factors`` and ``_live`` (one thread: ``_live`` is swapped per call)."""
    import network.conductance._conduit as conduit
    import network.conductance._mates as mates_mod
    from network.pores import merge_pores
    from throats import triangle_vertices

    pm = merge_pores(tess)
    throat_of = {tuple(v): i for i, v in enumerate(tess.throat_vertices.tolist())}
    live0, factors0, grain_mates0 = mates_mod._live, conduit.section_factors, conduit.grain_mates_of
    state = {}

    def grain_mates(packing_, vertices, heights, signs):
        state["idx"] = np.array([throat_of[tuple(v)] for v in np.asarray(vertices).tolist()],
                                dtype=np.int64)
        return grain_mates0(packing_, vertices, heights, signs)

    def factors(mates, rows, h_nodes, signs, radii, sides, *, n=16):
        idx = state["idx"]
        tp = tess.throat_pores[idx]
        merged = pm.group_size[pm.labels[np.maximum(tp, 0)]] > 1
        merged[:, 1] = np.where(tp[:, 1] < 0, merged[:, 0], merged[:, 1])
        apex = tetrahedron_apex(tess, idx, merged)[rows]
        V = triangle_vertices(sides[rows])
        hn = h_nodes[rows]
        calls = iter([(c, j) for c in (0, 1) for j in range(0 if c == 0 else 1, hn.shape[1])])

        def live(m_, rho, V_, rv, n_angles=16):
            c, j = next(calls)
            with np.errstate(divide="ignore", invalid="ignore"):
                lam = np.clip(hn[:, j] / apex[:, c, 2], 0.0, 1.0)[:, None, None]
            region = V + lam * (apex[:, c, None, :2] - V)
            return _live_in_region(m_, rho, V_, rv, region, n_angles)

        mates_mod._live = live
        try:
            return factors0(mates, rows, h_nodes, signs, radii, sides, n=n)
        finally:
            mates_mod._live = live0

    conduit.grain_mates_of, conduit.section_factors = grain_mates, factors
    try:
        return solve_k(packing, box, tess, grain_mates="all", threads=1)
    finally:
        conduit.grain_mates_of, conduit.section_factors = grain_mates0, factors0


# -- slope: the integral without its slope factor ----------------------------------------

class _FlatGradient:
    """``numpy`` as ``_sections`` sees it, with ``gradient`` zero: s = 0, the factor 1."""

    def __getattr__(self, name):
        return getattr(np, name)

    @staticmethod
    def gradient(a, axis=None):
        return np.zeros_like(a)


def slope_k(packing, box, tess, grain_mates):
    """k with the slope factor of the conduit integral set to 1."""
    import network.conductance._sections as sections

    saved = sections.np
    sections.np = _FlatGradient()
    try:
        return solve_k(packing, box, tess, grain_mates=grain_mates, threads=1)
    finally:
        sections.np = saved


# -- merge: grain fragments joined to a four-grain neighbour ------------------------------

def fragment_merge(tess):
    """``merge_pores`` with each fragment joined to the four-grain neighbour across the wider
    of its three-grain faces (module docstring): a PoreMerge."""
    import scipy.sparse as sp
    from scipy.sparse import csgraph

    from network.pores import merge_pores
    from network.pores._merge import PoreMerge
    from network.conductance._mates import window_factors_compiled
    from network.conductance._sections import section_estimate

    base = merge_pores(tess)
    pv = tess.pore_vertices
    gid = np.asarray(tess.packing.grain_id)[pv]
    n_grains = 1 + (np.diff(np.sort(gid, axis=1), axis=1) != 0).sum(axis=1)
    cc = tess.pore_circumcenter
    rad = np.linalg.norm(cc - tess.packing.centers[pv[:, 0]], axis=1)
    fa = tess.throat_area[tess.pore_throats].sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        sliver = ~(9.0 * tess.pore_volume / (fa * rad) >= 0.05)
    frag = np.flatnonzero((n_grains == 3) & ~sliver)
    gk = gid[frag]
    dup = np.zeros((frag.size, 4), dtype=bool)       # face k (opposite vertex k) has 3 grains
    for a in range(4):
        for b in range(4):
            if a != b:
                dup[:, a] |= gk[:, a] == gk[:, b]
    nb = tess.pore_neighbors[frag]
    faces = tess.pore_throats[frag]
    # each three-grain face's flow-rate estimate with its grain mates: the cell model of the
    # three-disk section times the mates' factor; the narrower face stays the window
    flat = faces.ravel()
    rate = (section_estimate(tess.throat_radii[flat], tess.throat_sides[flat])
            * window_factors_compiled(tess.packing, tess.throat_vertices[flat])).reshape(faces.shape)
    wide = np.argmax(np.where(dup, rate, -1.0), axis=1)
    rows_ = np.arange(frag.size)
    pick = nb[rows_, wide]
    ok = ((n_grains[np.maximum(pick, 0)] == 4) & (pick >= 0) & ~sliver[np.maximum(pick, 0)]
          & (rate[rows_, wide] > 0))
    n_p = pv.shape[0]
    # the base groups (each tetrahedron to its group's first member) and the new joins
    first = np.full(base.n_groups, -1)
    order = np.arange(n_p)[::-1]
    first[base.labels[order]] = order
    rows = np.concatenate([np.arange(n_p), frag[ok]])
    cols = np.concatenate([first[base.labels], pick[ok]])
    g = sp.coo_array((np.ones(rows.size), (rows, cols)), shape=(n_p, n_p))
    n_g, labels = csgraph.connected_components(g, directed=False)
    size = np.bincount(labels, minlength=n_g)
    # centres: the mean of each group's distinct sphere centres (singletons: the centroid)
    x = tess.packing.centers
    center = np.zeros((n_g, 3))
    single = size[labels] == 1
    center[labels[single]] = x[pv[single]].mean(axis=1)
    key = np.unique(labels[~single, None].astype(np.int64) * (x.shape[0] + 1) + pv[~single])
    grp, vtx = key // (x.shape[0] + 1), key % (x.shape[0] + 1)
    cnt = np.bincount(grp, minlength=n_g)
    for k in range(3):
        s = np.bincount(grp, weights=x[vtx, k], minlength=n_g)
        center[cnt > 0, k] = s[cnt > 0] / cnt[cnt > 0]
    tp = tess.throat_pores
    internal = np.zeros(tp.shape[0], dtype=bool)
    inner = tp[:, 1] >= 0
    internal[inner] = labels[tp[inner, 0]] == labels[tp[inner, 1]]
    return PoreMerge(labels, int(n_g), size, center, internal, base.tolerance)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cmd", choices=("sections", "tetra", "slope", "merge"))
    ap.add_argument("--bed", action="append", default=[],
                    help="NAME=FILE for a bed not bundled (the corn bed)")
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    from network import tessellate
    from network.packing import read_container, read_packing

    ref = fine_reference()
    files = {n: str(ROOT / f) for n, (f, _) in ref.items()}     # the reference's: repository
    for item in a.bed:
        name, _, path = item.partition("=")
        if name not in GRAIN_BEDS or not path:
            print(f"error: --bed {item!r}: give NAME=FILE, NAME one of {', '.join(GRAIN_BEDS)}",
                  file=sys.stderr)
            return 2
        files[name] = str(Path(path).resolve())                   # the caller's: working folder
    if a.json and not Path(a.json).resolve().parent.is_dir():
        print(f"error: --json {a.json}: its folder does not exist", file=sys.stderr)
        return 2
    paths = files
    for name in GRAIN_BEDS:
        if not Path(paths[name]).is_file():
            print(f"error: --bed {name}: no file {paths[name]}", file=sys.stderr)
            return 2
    rows = []
    for name in GRAIN_BEDS:
        path = paths[name]
        pk, box = read_packing(path), read_container(path)
        tess = tessellate(pk)
        k_lbm = ref[name][1]
        cases = {"sections": [(f"{m}, {n} sections", dict(grain_mates=m, n_sections=n))
                              for m in ("off", "window", "all") for n in (6, 12, 24)],
                 "tetra": [("all", dict(grain_mates="all")), ("all, tetrahedron", None)],
                 "slope": [(f"{m}{v}", dict(grain_mates=m, slope=v == ", no slope factor"))
                           for m in ("window", "all") for v in ("", ", no slope factor")],
                 "merge": [(f"{m}, {v}", dict(grain_mates=m, merge=mg))
                           for m in ("window", "all")
                           for v, mg in (("default bodies", None), ("none merged", False),
                                         ("fragments joined", fragment_merge))]}[a.cmd]
        for label, kw in cases:
            if kw is None:
                k = tetra_k(pk, box, tess)
            elif kw.pop("slope", False):
                k = slope_k(pk, box, tess, kw["grain_mates"])
            else:
                k = solve_k(pk, box, tess, **kw)
            rows.append({"bed": name, "case": label, "k_m2": k, "k_lbm_m2": k_lbm,
                         "net_over_lbm_minus_1": k / k_lbm - 1.0})
            print(f"{name:8s} {label:32s} k {k:.4e} m2  network / LBM - 1 {k / k_lbm - 1:+.1%}",
                  flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps({"what": a.cmd, "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
