"""Plots of the vibration study (matplotlib, optional: imported only when plotting).

* ``porosity_time.png``: global porosity and the mean local porosity of B1–B5 against time,
  one line per intensity (thesis Figs. 4.11 and 4.13).
* ``porosity_intensity.png``: porosity before and after against intensity (Fig. 4.14).
* ``pressure_drop_intensity.png``: the network model's pressure drop against intensity, the
  unvibrated bed as a line (written when network results exist).
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_study"]


def plot_study(study, out_dir):
    """Write the study's plots into ``out_dir``; returns their paths ([] without matplotlib)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    paths = []
    rows = study["rows"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    for tag, s in study["series"].items():
        t = np.asarray(s["times_s"])
        a1.plot(t, s["porosity_global"], label=f"{s['intensity_g']:.2f} g")
        a2.plot(t, np.mean(np.asarray(s["porosity_spheres"]), axis=1), label=f"{s['intensity_g']:.2f} g")
    a1.set(xlabel="time, s", ylabel="global porosity", title="global porosity (cf. thesis Fig. 4.11)")
    a2.set(xlabel="time, s", ylabel="local porosity, mean of B1–B5", title="local porosity (cf. Fig. 4.13)")
    if study["series"]:
        a1.legend(fontsize=8)
    fig.tight_layout()
    paths.append(_save(fig, out_dir / "porosity_time.png", plt))

    g = [r["intensity_g"] for r in rows]
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.plot(g, [r["porosity_global_after"] for r in rows], "o-", label="global, after")
    ax.plot(g, [r["porosity_interior_after"] for r in rows], "s-", label="interior, after")
    ax.plot(g, [float(np.mean(r["porosity_spheres_after"])) for r in rows], "^-", label="B1–B5 mean, after")
    if rows:
        ax.axhline(rows[0]["porosity_global_before"], color="k", lw=0.8, ls="--", label="global, before")
    ax.set(xlabel="vibration intensity Γ = Aω²/g", ylabel="porosity", title="porosity after vibration (cf. Fig. 4.14)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths.append(_save(fig, out_dir / "porosity_intensity.png", plt))

    dp = [((r.get("network_after") or {}).get("solve") or {}).get("pressure_drop_pa") for r in rows]
    if any(v is not None for v in dp):
        fig, ax = plt.subplots(figsize=(5.5, 4.2))
        ax.plot([x for x, v in zip(g, dp) if v is not None], [v for v in dp if v is not None], "o-",
                label="after vibration")
        before = (((study["bed"].get("network") or {}).get("solve")) or {}).get("pressure_drop_pa")
        if before is not None:
            ax.axhline(before, color="k", lw=0.8, ls="--", label="before")
        ax.set(xlabel="vibration intensity Γ, g", ylabel="pressure drop, Pa (network model)",
               title="pressure drop over the bed depth")
        ax.legend(fontsize=8)
        fig.tight_layout()
        paths.append(_save(fig, out_dir / "pressure_drop_intensity.png", plt))

    curves = [("before", (study["bed"].get("network") or {}).get("curve"))]
    curves += [(f"{gi:.2f} g", (r.get("network_after") or {}).get("curve")) for gi, r in zip(g, rows)]
    curves = [(lab, c) for lab, c in curves if c and c.get("velocity_m_s")]
    if curves:
        fig, ax = plt.subplots(figsize=(5.5, 4.2))
        for lab, c in curves:
            ax.loglog(c["velocity_m_s"], c["pressure_gradient_pa_per_m"], "k--" if lab == "before" else "o-",
                      ms=3, label=lab)
        ax.set(xlabel="superficial air velocity, m/s", ylabel="pressure gradient, Pa/m (network, with inertia)",
               title="resistance before and after vibration")
        ax.legend(fontsize=8)
        fig.tight_layout()
        paths.append(_save(fig, out_dir / "resistance_curves.png", plt))
    return paths


def _save(fig, path, plt):
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
