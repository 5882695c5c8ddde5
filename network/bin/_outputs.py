r"""What an engineer reads from a solved bin: uniformity, the least aerated grain, the cooling
estimate, the r-z figure and a VTK file for ParaView.

Local airflow per tonne. A grain parcel of bulk density ρ_b = ρ_p (1 - ε) crossed by the
superficial velocity |u| has the specific airflow s = |u|/ρ_b; the bin's mass-weighted mean is
s̄ = ∫|u| dV / M (M the grain mass). The local airflow per tonne is the bin's airflow per
tonne q_t = 60 Q/(M/1000) m³/(min t) times s/s̄, so its mass-weighted mean is q_t and a flat
bed on a full floor has q_t everywhere. The under-aerated fraction is the grain volume where
s < s̄/2 (elements with every node on the plenum or on the surface, whose gradient the mesh
cannot resolve, left out of it and of the least aerated point). Cooling estimate at the least aerated element (the smallest s): the time for one
grain volume of air to pass it, t = 1/q_v with q_v = (q_t,local/60)(ρ_b/1000) m³ of air per s
per m³ of grain (a flat bed: q_v = U/H, the whole bed's air exchange);
a temperature front moves slower by ρ_b c_g/(ρ_a c_a), the grain's and the air's volumetric
heat capacities, given when the grain's specific heat c_g is.
"""

from __future__ import annotations

import numpy as np

__all__ = ["aeration", "write_vtk", "write_figure", "C_AIR_J_KG_K"]

#: specific heat of dry air at constant pressure near 20 °C, J/(kg K)
C_AIR_J_KG_K = 1006.0


def aeration(problem, sol, *, grain_heat_capacity=None) -> dict:
    """Uniformity, least aerated point and cooling estimate of one solution (see the module)."""
    u = np.linalg.norm(sol.velocity, axis=0)
    vol = problem.volumes
    rho_b = problem.material.particle_density_kg_m3 * (1 - problem.porosity)
    mass = float(np.sum(rho_b * vol))
    s = u / rho_b
    s_mean = float(np.sum(u * vol)) / mass
    q_t = 60.0 * sol.inflow_m3_s / (mass / 1000.0)
    local = q_t * s / s_mean
    # an element whose nodes all lie on one Dirichlet boundary (a sliver at the apex or at a
    # corner) has a zero gradient whatever the flow: left out of the fraction and the minimum
    free = np.zeros(problem.skmesh.p.shape[1], dtype=bool)
    free[problem.free] = True
    inner = free[problem.mesh.cells].any(axis=0)
    under = (s < 0.5 * s_mean) & inner
    i = int(np.flatnonzero(inner)[np.argmin(s[inner])])
    c = problem.centroids[:, i]
    where = ({"r_m": float(c[0]), "z_m": float(c[1])} if problem.axisymmetric else
             {"x_m": float(c[0]), "y_m": float(c[1]), "z_m": float(c[2]),
              "r_m": float(np.hypot(c[0], c[1]))})
    where["depth_below_surface_m"] = float(problem.depth_m[i])
    q_v = local[i] / 60.0 * rho_b[i] / 1000.0           # 1/s
    t_air = float(1.0 / q_v) if q_v > 0 else float("inf")
    out = {"grain_mass_t": mass / 1000.0, "airflow_m3_per_min_t": q_t,
           "underaerated_fraction": float(np.sum(vol[under]) / np.sum(vol[inner])),
           "least_aerated": {**where, "airflow_m3_per_min_t": float(local[i]),
                             "ratio_to_mean": float(s[i] / s_mean)},
           "local_airflow_m3_per_min_t": local, "underaerated_mask": under,
           "cooling_estimate": {
               "air_exchange_time_h": t_air / 3600.0,
               "what": "grain volume over the local airflow at the least aerated point: the "
                       "time one grain volume of air takes to pass it (an estimate)"}}
    if grain_heat_capacity is not None:
        ratio = rho_b[i] * grain_heat_capacity / (problem.material.density_kg_m3 * C_AIR_J_KG_K)
        out["cooling_estimate"].update(
            front_time_h=ratio * t_air / 3600.0, heat_capacity_ratio=float(ratio),
            front_what=f"times rho_b c_g/(rho_a c_a) = {ratio:.4g} (c_g {grain_heat_capacity:g} "
                       f"J/(kg K), c_a {C_AIR_J_KG_K:g} J/(kg K)): a temperature front's "
                       "passage, an estimate")
    return out


def write_vtk(path, problem, sol, local, under) -> None:
    """Legacy ASCII VTK unstructured grid: nodal pressure; per cell velocity, porosity,
    airflow per tonne and the under-aerated flag (r-z meshes as z = 0 slices, r along x)."""
    p = problem.mesh.points
    t = problem.mesh.cells
    n, ne = p.shape[1], t.shape[1]
    xyz = np.zeros((n, 3))
    xyz[:, :p.shape[0]] = p.T
    ctype = 5 if problem.axisymmetric else 10
    vel = np.zeros((ne, 3))
    vel[:, :sol.velocity.shape[0]] = sol.velocity.T
    with open(path, "w") as f:
        f.write("# vtk DataFile Version 3.0\ngrainflow network.bin\nASCII\n"
                "DATASET UNSTRUCTURED_GRID\n")
        f.write(f"POINTS {n} double\n")
        np.savetxt(f, xyz, fmt="%.9g")
        f.write(f"CELLS {ne} {ne * (t.shape[0] + 1)}\n")
        np.savetxt(f, np.column_stack([np.full(ne, t.shape[0]), t.T]), fmt="%d")
        f.write(f"CELL_TYPES {ne}\n")
        np.savetxt(f, np.full(ne, ctype), fmt="%d")
        f.write(f"POINT_DATA {n}\nSCALARS pressure_pa double 1\nLOOKUP_TABLE default\n")
        np.savetxt(f, sol.p, fmt="%.9g")
        f.write(f"CELL_DATA {ne}\nVECTORS velocity_m_s double\n")
        np.savetxt(f, vel, fmt="%.9g")
        for name, arr, fmt in (("porosity", problem.porosity, "%.9g"),
                               ("airflow_m3_per_min_t", local, "%.9g"),
                               ("underaerated", under.astype(int), "%d")):
            f.write(f"SCALARS {name} {'int' if fmt == '%d' else 'double'} 1\n"
                    "LOOKUP_TABLE default\n")
            np.savetxt(f, arr, fmt=fmt)


def _locate_tets(points, cells, xyz, k=24):
    """Tetrahedron holding each point (-1 outside): the k elements with the nearest
    centroids (scipy's cKDTree), tested by barycentric coordinates, vectorised."""
    from scipy.spatial import cKDTree

    cen = points[:, cells].mean(axis=1).T
    _, cand = cKDTree(cen).query(xyz.T, k=k)
    v = points[:, cells]                                    # (3, 4, Ne)
    out = np.full(xyz.shape[1], -1)
    for j in range(k):
        e = cand[:, j]
        todo = out < 0
        if not np.any(todo):
            break
        e, x = e[todo], xyz[:, todo]
        T = np.stack([v[:, 1, e] - v[:, 0, e], v[:, 2, e] - v[:, 0, e],
                      v[:, 3, e] - v[:, 0, e]], axis=-1)      # (3, n, 3)
        lam = np.linalg.solve(np.moveaxis(T, 0, 1), (x - v[:, 0, e]).T[:, :, None])[:, :, 0]
        hit = (lam >= -1e-9).all(axis=1) & (lam.sum(axis=1) <= 1 + 1e-9)
        idx = np.flatnonzero(todo)[hit]
        out[idx] = e[hit]
    return out


def _section(problem, sol, local, under, geom, n=140):
    """Regular grid over the r-z section (3-D: the vertical plane x = 0, across the ducts):
    (R, Z, |u|, u_h, u_z, local airflow per tonne, under-aerated) with NaN outside."""
    r_max, z_max = geom.radius_m, float(max(geom.surface_height(0.0), geom.depth_m))
    if problem.axisymmetric:
        h = np.linspace(0, r_max, n)
    else:
        h = np.linspace(-r_max, r_max, 2 * n)
    z = np.linspace(0, z_max, n)
    H, Z = np.meshgrid(h, z)
    if problem.axisymmetric:
        pts = np.vstack([H.ravel(), Z.ravel()])
    else:
        pts = np.vstack([np.zeros(H.size), H.ravel(), Z.ravel()])
    el = np.full(H.size, -1)
    inside = Z.ravel() <= geom.surface_height(np.abs(H.ravel())) + 1e-12
    if problem.axisymmetric:
        import matplotlib.tri as mtri

        tri = mtri.Triangulation(problem.mesh.points[0], problem.mesh.points[1],
                                 problem.mesh.cells.T)
        el[inside] = tri.get_trifinder()(pts[0, inside], pts[1, inside])
    else:
        el[inside] = _locate_tets(problem.mesh.points, problem.mesh.cells, pts[:, inside])
    ok = el >= 0
    out = []
    vh = sol.velocity[1] if not problem.axisymmetric else sol.velocity[0]
    for arr in (np.linalg.norm(sol.velocity, axis=0), vh, sol.velocity[-1], local,
                under.astype(float)):
        a = np.full(H.size, np.nan)
        a[ok] = arr[el[ok]]
        out.append(a.reshape(H.shape))
    return (H, Z, *out)


def write_figure(path, problem, sol, info, geom, title) -> None:
    """The r-z section: airflow per tonne (colour), streamlines, the under-aerated region
    (hatched outline) and the least aerated point."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    H, Z, speed, uh, uz, local, under = _section(problem, sol, info["local_airflow_m3_per_min_t"],
                                                 info["underaerated_mask"], geom)
    width = (1 if problem.axisymmetric else 2) * geom.radius_m
    height = float(max(geom.surface_height(0.0), geom.depth_m))
    fig, ax = plt.subplots(figsize=(min(2.5 + 4.2 * width / height, 12.0), 5.0))
    q_t = info["airflow_m3_per_min_t"]
    im = ax.pcolormesh(H, Z, local, shading="auto", cmap="viridis",
                       vmin=0, vmax=np.nanpercentile(local, 98))
    fig.colorbar(im, ax=ax, label="local airflow, m$^3$/(min t)")
    ax.streamplot(H, Z, np.nan_to_num(uh), np.nan_to_num(uz), color="w", linewidth=0.7,
                  density=1.1, arrowsize=0.7)
    if np.nanmax(under) > 0:
        ax.contour(H, Z, np.nan_to_num(under), levels=[0.5], colors="r", linewidths=1.5)
    la = info["least_aerated"]
    ax.plot(la["r_m"] if problem.axisymmetric else la["y_m"], la["z_m"], "r*", ms=12,
            label=f"least aerated: {la['airflow_m3_per_min_t']:.3g} m$^3$/(min t)"
                  + ("" if problem.axisymmetric else f" (at x = {la['x_m']:.2f} m)"))
    rr = np.linspace(0 if problem.axisymmetric else -geom.radius_m, geom.radius_m, 200)
    ax.plot(rr, geom.surface_height(np.abs(rr)), "k-", lw=1)
    ax.set_xlabel("r, m" if problem.axisymmetric else "y, m (section x = 0)")
    ax.set_ylabel("z, m")
    ax.set_aspect("equal")
    ax.set_title(f"{title}\nmean {q_t:.3g} m$^3$/(min t); red: below half the mean "
                 f"({100 * info['underaerated_fraction']:.1f} % of the grain)", fontsize=9)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.13), fontsize=8, frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
