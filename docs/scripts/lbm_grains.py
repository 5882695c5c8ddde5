r"""Lattice-Boltzmann reference for a grain bed in the network's own sample box.

Research script (``docs/validation-grains.md``, runs in ``docs/data/lbm_grains_reference.json``): the resolved Stokes permeability and k/k_app at
Re_p 5, 10, 20 of the pore space inside the box that ``network.solve`` samples (its JSON's
``sample_lo_m`` / ``sample_hi_m``), flow along the bed's z axis, with the lattice, collision,
forcing and steady-state test of ``lbm_periodic.py`` (D3Q19 TRT, Lambda 3/16, Guo forcing, halfway
bounce-back, body force; same kernels, numba or CUDA).

The box's faces:

* **lateral faces: mirror planes** (symmetry: no flow through them, no shear on them), as if the
  box were surrounded by its own mirror images: a link that leaves the box through a lateral face
  pulls, from the node it re-enters at, the population with that velocity component reversed.
  The network's lateral faces are no-flow faces too (the conduits they cut are left out);
* **flow faces: the box and its mirror image along the flow**, a periodic cell of twice the
  box's length (the grains the outlet face cuts continue as their mirror image), driven by a
  uniform body force g: k = nu U / g with U the superficial velocity over the whole cell.

Spheres are voxelised at node centres ``lo + (i + 1/2) dx``, a node solid when strictly inside a
sphere; ``dx = d32 / D`` (D, ``--resolution``: lattice units per Sauter diameter, the diameter of
Re_p = U d32 / nu, as ``network.solve`` reports it).

Steps:

    # here: the voxel masks (one NPZ per bed and resolution, bits packed)
    python docs/scripts/lbm_grains.py voxelise network/data/wheat_grains.csv --resolution 24 48 \
        --out .lbm/wheat
    # on the device (or here, numba): Stokes, then Re_p 5, 10, 20 from the Stokes field
    python docs/scripts/lbm_grains.py run .lbm/wheat_D48.npz --backend cuda --json out.json
    # here: the network's k and k_app/k at the Reynolds numbers the LBM obtained
    python docs/scripts/lbm_grains.py network docs/data/lbm_grains_reference.json \
        --bed corn=shelled_corn.csv
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parents[2]))     # the repository's packages
from lbm_periodic import C, CudaLattice, Lattice, plan   # noqa: E402  (beside this script)

OPP = np.r_[0, np.arange(10, 19), np.arange(1, 10)]


def _mirror_direction(axis):
    """Direction index with component ``axis`` reversed, per direction (19,)."""
    flip = C.copy()
    flip[:, axis] *= -1
    return np.array([int(np.flatnonzero((C == f).all(axis=1))[0]) for f in flip])


MIRROR = {1: _mirror_direction(1), 2: _mirror_direction(2)}


# --------------------------------------------------------------------------- geometry -------
def sample_box(bed, axis="z"):
    """(centers (n, 3), radii (n,), lo (3,), hi (3,), d32) of a bed and the network's sample box
    (``network.solve``'s default region for the flow axis)."""
    from network.flow import SampleOptions, solve_network
    from network.packing import read_container, read_packing

    pk = read_packing(bed)
    res = solve_network(pk, axis=axis, sample=SampleOptions(container=read_container(bed)))
    return (np.asarray(pk.centers, float), np.asarray(pk.radii, float),
            np.asarray(res.region_lo, float), np.asarray(res.region_hi, float),
            float(res.sauter_diameter_m), res)


def voxelise_box(centers, radii, lo, hi, dx, axis=2):
    """Solid mask of the box [lo, hi] at node spacing ``dx``: shape (n_flow, n_a, n_b) with the
    flow axis (``axis`` of the bed) first, node centres at lo + (i + 1/2) dx."""
    n = np.maximum(np.rint((hi - lo) / dx).astype(int), 1)
    solid = np.zeros(tuple(n), dtype=bool)
    near = np.all((centers + radii[:, None] > lo) & (centers - radii[:, None] < lo + n * dx), axis=1)
    for c, r in zip(centers[near], radii[near]):
        a = np.maximum(np.floor((c - r - lo) / dx - 0.5).astype(int), 0)
        b = np.minimum(np.ceil((c + r - lo) / dx - 0.5).astype(int), n - 1)
        idx = [np.arange(a[k], b[k] + 1) for k in range(3)]
        d2 = [(lo[k] + (ix + 0.5) * dx - c[k]) ** 2 for k, ix in enumerate(idx)]
        inside = (d2[0][:, None, None] + d2[1][None, :, None] + d2[2][None, None, :]) < r * r
        solid[np.ix_(*idx)] |= inside
    order = [axis] + [k for k in range(3) if k != axis]
    return np.ascontiguousarray(np.transpose(solid, order))


def mirrored_index(solid, xp=np):
    """Pull-gather index (19 n_fluid,) int32 and n_fluid of the box and its mirror image along
    axis 0 (periodic, period twice the box), mirror planes on the faces of axes 1 and 2; fluid
    node ids in raster order of the doubled box. ``xp``: numpy or cupy."""
    cell = xp.concatenate([xp.asarray(solid), xp.asarray(solid)[::-1]], axis=0)
    fluid = ~cell
    ids = xp.full(cell.shape, -1, dtype=xp.int64)
    nf = int(fluid.sum())
    ids[fluid] = xp.arange(nf, dtype=xp.int64)
    own = ids[fluid]
    index = xp.empty(19 * nf, dtype=xp.int32)
    pad = xp.pad(ids, ((0, 0), (1, 1), (1, 1)), mode="symmetric")
    n1, n2 = cell.shape[1], cell.shape[2]
    for i in range(19):
        cx, cy, cz = (int(v) for v in C[i])
        up = xp.roll(pad, cx, axis=0)[:, 1 - cy:1 - cy + n1, 1 - cz:1 - cz + n2]
        # the population pulled: direction i, with a component reversed where the link
        # re-enters through a mirror plane
        src = xp.full(cell.shape, i, dtype=xp.int8)
        if cy:
            plane = 0 if cy > 0 else n1 - 1
            src[:, plane, :] = MIRROR[1][i]
        if cz:
            plane = 0 if cz > 0 else n2 - 1
            s = src[:, :, plane]
            src[:, :, plane] = xp.asarray(MIRROR[2])[s.astype(xp.int64)]
        upf, srcf = up[fluid], src[fluid].astype(xp.int64)
        index[i * nf:(i + 1) * nf] = xp.where(upf >= 0, srcf * nf + upf,
                                              int(OPP[i]) * nf + own).astype(xp.int32)
    return index, nf, int(cell.size)


class BoxLattice(Lattice):
    """:class:`lbm_periodic.Lattice` on a given gather index (numba)."""

    def __init__(self, index, nf, n_nodes):
        from lbm_periodic import _equilibrium

        self.n_nodes, self.index, self.nf = n_nodes, index, nf
        self.f = np.empty(19 * nf)
        self.g = np.empty(19 * nf)
        self.ux = np.zeros(nf)
        _equilibrium(self.f, nf, self.ux)


class CudaBoxLattice(CudaLattice):
    """:class:`lbm_periodic.CudaLattice` on a given (device) gather index."""

    def __init__(self, index, nf, n_nodes):
        import cupy as cp
        from lbm_periodic import _CUDA_SRC

        self.cp, self.n_nodes, self.nf = cp, n_nodes, nf
        self.index = cp.asarray(index)
        self.f = cp.empty(19 * nf)
        self.g = cp.empty(19 * nf)
        self.usum = cp.zeros(1)
        self.kernel = cp.RawKernel(_CUDA_SRC, "lbm_step")
        self.start_from(cp.zeros(nf))


# --------------------------------------------------------------------------- runs -----------
def curve(mask_npz, *, backend="numba", reynolds=(0.1, 5, 10, 20), u_max=0.02, tau_stokes=1.5,
          max_steps=30000, log=print):
    """Stokes k and k/k_app(Re_p) of one voxel mask (NPZ of ``voxelise``)."""
    z = np.load(mask_npz)
    shape = tuple(int(v) for v in z["shape"])
    solid = np.unpackbits(z["bits"], count=int(np.prod(shape))).reshape(shape).astype(bool)
    d_lu = float(z["d_lu"])
    t0 = time.perf_counter()
    if backend == "cuda":
        import cupy as cp

        try:
            index, nf, n_nodes = mirrored_index(solid, xp=cp)
        except Exception as exc:         # a CuPy without some numpy function: the host builds it
            log(f"# gather index on the GPU failed ({exc!r}): built on the host")
            index, nf, n_nodes = mirrored_index(solid)
        lat = CudaBoxLattice(index, nf, n_nodes)
        del index
    else:
        index, nf, n_nodes = mirrored_index(solid)
        lat = BoxLattice(index, nf, n_nodes)
    setup = time.perf_counter() - t0
    eps = 1.0 - float(solid.mean())
    log(f"# {mask_npz}: box {shape} (x2 along the flow), d32 = {d_lu:.2f} lu, "
        f"voxel porosity {eps:.4f}, {nf} fluid nodes, setup {setup:.1f} s, {backend}")
    res = {"mask": str(mask_npz), "bed": str(z["bed"]), "shape": list(shape), "d_lu": d_lu,
           "resolution": float(z["resolution"]), "dx_m": float(z["dx_m"]),
           "d32_m": float(z["d32_m"]), "porosity_voxel": eps, "n_fluid": nf,
           "setup_s": setup, "backend": backend, "rows": []}
    k_stokes = None
    k_guess = d_lu**2 * eps**3 / (180.0 * (1.0 - eps) ** 2)
    for re in sorted(reynolds):
        tau, u_t = plan(re, d_lu, u_max=u_max, tau_stokes=tau_stokes)
        nu = (tau - 0.5) / 3.0
        k_use = k_stokes if k_stokes is not None else k_guess
        gx = nu * u_t / k_use * (1.0 + 0.012 * re)
        if res["rows"]:
            lat.start_from(lat.ux * (u_t / res["rows"][-1]["U_lu"]))
        r = lat.run(tau, gx, max_steps=max_steps)
        u = r["U"]
        k_app = nu * u / gx
        if k_stokes is None:
            k_stokes = k_app
            res["k_stokes_lu2"] = k_stokes
            res["k_stokes_m2"] = k_stokes * res["dx_m"] ** 2
        row = {"re_target": re, "re": u * d_lu / nu, "tau": tau, "g": gx, "U_lu": u,
               "k_app_lu2": k_app, "k_ratio": k_stokes / k_app, "steps": r["steps"],
               "converged": r["converged"], "last_rel_change": r["last_rel_change"],
               "spread_last5": r["spread_last5"], "seconds": r["seconds"], "mlups": r["mlups"]}
        res["rows"].append(row)
        log(f"Re_p {row['re']:7.3f}  tau {tau:.4f}  k/k_app {row['k_ratio']:.4f}  steps "
            f"{r['steps']} ({'converged' if r['converged'] else 'step cap'}, spread "
            f"{r['spread_last5']:.1e})  {r['seconds']:.0f} s  {r['mlups']:.0f} MLUPS")
        if not np.isfinite(u):
            break
    return res


def network_rows(ref, policy="table-only", beds=None, grain_mates="window"):
    """The network's Stokes k (``permeability_m2``, as ``network.solve`` reports it: the whole
    sample in the grain beds' narrow samples, the inset window in wider ones; the whole sample's
    beside it) and k_app/k at the Reynolds numbers each LBM run obtained, per bed of ``ref``
    (``beds``: bed name -> file, for beds not bundled)."""
    from network import tessellate
    from network.flow import ConductanceOptions, FlowOptions, SampleOptions, solve_network
    from network.packing import read_container, read_packing
    from throats import deep_overlap

    out = {}
    for run in ref["runs"]:
        bed = run["bed_name"]
        if bed in out:
            continue
        path = (beds or {}).get(bed, run["bed"])
        pk, box = read_packing(path), read_container(path)
        sample = SampleOptions(container=box)
        cond = ConductanceOptions(policy=policy, model_options={"grain_mates": grain_mates})
        tess = tessellate(pk)
        res = solve_network(pk, axis="z", sample=sample, conductance=cond, tessellation=tess)
        # each conduit's share of the dissipated power, q^2/g (Stokes), by window class: a
        # window with a deep pair (two spheres of one grain) or not; d ln k / d ln g_t = share_t
        ids = np.asarray(res.throat_ids)
        q, g = np.asarray(res.throat_flow_m3_s), np.asarray(res.throat_conductance)
        ok = np.isfinite(q) & np.isfinite(g) & (g > 0)
        power = np.where(ok, q**2 / np.where(ok, g, 1.0), 0.0)
        deep = deep_overlap(tess.throat_radii[ids], tess.throat_sides[ids])
        d32, mu, rho = res.sauter_diameter_m, res.viscosity_pa_s, 1.2
        re = sorted({round(r["re"], 3) for rr in ref["runs"] if rr["bed_name"] == bed
                     for r in rr["rows"] if r["re"] > 1})
        vel = [x * mu / (rho * d32) for x in re]
        flow = FlowOptions(inertia=True, velocity_m_s=vel[0], curve_velocities_m_s=vel[1:],
                           density_kg_m3=rho)
        inert = solve_network(pk, axis="z", sample=sample, conductance=cond, flow=flow,
                              tessellation=tess)
        pts = inert.curve_points()
        k = res.permeability_m2        # the gradients' own base (whole or inset sample)
        out[bed] = {"k_m2": res.permeability_m2, "sample_estimator": res.sample_estimator,
                    "n_conduits": int(len(ids)), "n_deep_pair_conduits": int(deep.sum()),
                    "deep_pair_dissipation_share": float(power[deep].sum() / power.sum()),
                    "qstar_stats": res.qstar_stats.get("qstar_stats", res.qstar_stats), "k_whole_m2": res.permeability_whole_m2, "d32_m": d32,
                    "rows": [{"re": p["reynolds_particle"],
                              "k_ratio": k / p["apparent_permeability_m2"]} for p in pts]}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    v = sub.add_parser("voxelise", help="voxel masks of a bed's sample box")
    v.add_argument("bed")
    v.add_argument("--resolution", type=float, nargs="+", default=[24.0],
                   help="lattice units per Sauter diameter")
    v.add_argument("--out", required=True, help="prefix: PREFIX_D<res>.npz")
    r = sub.add_parser("run", help="LBM on voxel masks")
    r.add_argument("masks", nargs="+")
    r.add_argument("--backend", choices=("numba", "cuda"), default="numba")
    r.add_argument("--reynolds", type=float, nargs="+", default=[0.1, 5, 10, 20])
    r.add_argument("--u-max", type=float, default=0.02)
    r.add_argument("--tau-stokes", type=float, default=1.5)
    r.add_argument("--max-steps", type=int, default=30000)
    r.add_argument("--time-budget", type=float, default=None,
                   help="start no new mask after this many seconds")
    r.add_argument("--json", required=True)
    r.add_argument("--check-index", action="store_true",
                   help="first compare the GPU's gather index with the host's on the first mask")
    n = sub.add_parser("network", help="the network on the beds of an LBM JSON")
    n.add_argument("ref")
    n.add_argument("--json", default=None)
    n.add_argument("--bed", action="append", default=[], metavar="NAME=FILE",
                   help="a bed of the reference that is not bundled (corn=shelled_corn.csv)")
    n.add_argument("--grain-mates", choices=("off", "window", "all"), default="window",
                   help="where the conduit model takes grain mates out of the sections "
                        "(network.conductance.conduit_conductance's grain_mates)")
    a = ap.parse_args(argv)
    if a.cmd == "voxelise":
        c, rad, lo, hi, d32, _ = sample_box(a.bed)
        for res in a.resolution:
            dx = d32 / res
            t0 = time.perf_counter()
            solid = voxelise_box(c, rad, lo, hi, dx)
            path = f"{a.out}_D{res:g}.npz"
            np.savez_compressed(path, bits=np.packbits(solid.ravel()), shape=solid.shape,
                                d_lu=res, resolution=res, dx_m=dx, d32_m=d32, lo_m=lo, hi_m=hi,
                                bed=str(a.bed))
            print(f"wrote {path}: {solid.shape}, porosity {1 - solid.mean():.4f}, "
                  f"{time.perf_counter() - t0:.1f} s")
        return 0
    if a.cmd == "run":
        t0 = time.perf_counter()
        out = {"runs": []}
        if a.check_index:
            import cupy as cp

            z = np.load(a.masks[0])
            shape = tuple(int(v) for v in z["shape"])
            solid = np.unpackbits(z["bits"], count=int(np.prod(shape))).reshape(shape).astype(bool)
            host, gpu = mirrored_index(solid), mirrored_index(solid, xp=cp)
            same = bool(np.array_equal(host[0], cp.asnumpy(gpu[0])) and host[1:] == gpu[1:])
            out["index_check"] = {"mask": a.masks[0], "identical": same}
            print(f"# gather index, GPU against host on {a.masks[0]}: identical {same}")
        for m in a.masks:
            if a.time_budget is not None and time.perf_counter() - t0 > a.time_budget:
                print(f"# time budget spent: {m} not run")
                continue
            out["runs"].append(curve(m, backend=a.backend, reynolds=a.reynolds, u_max=a.u_max,
                                     tau_stokes=a.tau_stokes, max_steps=a.max_steps))
            with open(a.json, "w") as fh:
                json.dump(out, fh, indent=1)
        return 0
    ref = json.load(open(a.ref))
    rows = network_rows(ref, beds=dict(b.split("=", 1) for b in a.bed),
                        grain_mates=a.grain_mates)
    print(json.dumps(rows, indent=1, default=float))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows, fh, indent=1, default=float)
    return 0


if __name__ == "__main__":
    sys.exit(main())
