"""PNG plots of airflow paths (matplotlib, imported inside the functions).

Functions
---------
plot_paths(points, paths, out_png, *, axis="z", title="")
    3-D paths over the packing, their 2-D projection, width and turning-angle histograms.
"""

from __future__ import annotations

import logging

import numpy as np

from ..pores import axis_index

__all__ = ["plot_paths"]

logger = logging.getLogger(__name__)

_COLOURS = {"widest": "tab:blue", "narrowest": "tab:red", "maximin": "tab:green",
            "shortest": "tab:purple"}


def plot_paths(points, paths, out_png, *, axis="z", title="", max_spheres=4000, seed=0):
    """Write a 2 x 2 figure of airflow paths to ``out_png``.

    Panels (thesis Figs. 4.4-4.8): (a) the paths in 3-D over the sphere centres (a random
    subset of at most ``max_spheres``), (b) their projection on the plane of the flow axis and
    the first other axis, (c) the distribution of local path widths (Eq. 3.24) and (d) of
    local turning angles, one colour per path kind.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    paths : sequence of AirflowPath
    out_png : str or path-like
    axis : {'x', 'y', 'z'}
    title : str
    max_spheres : int
    seed : int
        Picks the subset of sphere centres drawn.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.asarray(points, dtype=float)
    ax_i = axis_index(axis)
    other = [i for i in range(3) if i != ax_i][0]
    rng = np.random.default_rng(seed)
    sub = x if x.shape[0] <= max_spheres else x[rng.choice(x.shape[0], max_spheres, False)]
    fig = plt.figure(figsize=(11, 9))
    a3 = fig.add_subplot(2, 2, 1, projection="3d")
    a3.scatter(sub[:, 0] * 1e3, sub[:, 1] * 1e3, sub[:, 2] * 1e3, s=1, c="0.75", alpha=0.3)
    a2 = fig.add_subplot(2, 2, 2)
    aw = fig.add_subplot(2, 2, 3)
    at = fig.add_subplot(2, 2, 4)
    seen = set()
    widths, turns = {}, {}
    for p in paths:
        if p.points.shape[0] < 2:
            continue
        c = _COLOURS.get(p.kind, "k")
        lab = p.kind if p.kind not in seen else None
        seen.add(p.kind)
        q = p.points * 1e3
        a3.plot(q[:, 0], q[:, 1], q[:, 2], color=c, lw=1, label=lab)
        a2.plot(q[:, other], q[:, ax_i], color=c, lw=1, label=lab)
        widths.setdefault(p.kind, []).append(p.widths_m * 1e3)
        turns.setdefault(p.kind, []).append(p.turning_angles_deg)
    a3.set_xlabel("x (mm)")
    a3.set_ylabel("y (mm)")
    a3.set_zlabel("z (mm)")
    a3.set_title("(a) paths over the packing")
    a2.set_xlabel(f"{'xyz'[other]} (mm)")
    a2.set_ylabel(f"{axis} (mm)")
    a2.set_aspect("equal", adjustable="datalim")
    a2.set_title("(b) projection")
    wb = np.arange(0.0, 8.5, 0.5)
    tb = np.arange(0.0, 181.0, 10.0)
    for kind in widths:
        w = np.concatenate(widths[kind])
        t = np.concatenate(turns[kind])
        c = _COLOURS.get(kind, "k")
        aw.hist(np.clip(w, 0, wb[-1]), bins=wb, histtype="step", color=c, label=kind,
                weights=np.full(w.size, 100.0 / max(w.size, 1)))
        at.hist(t, bins=tb, histtype="step", color=c, label=kind,
                weights=np.full(t.size, 100.0 / max(t.size, 1)))
    aw.set_xlabel("local path width (mm), Eq. 3.24")
    aw.set_ylabel("frequency (%)")
    aw.set_title("(c) widths")
    at.set_xlabel("local turning angle (deg)")
    at.set_ylabel("frequency (%)")
    at.set_title("(d) turning angles")
    for a in (a2, aw, at):
        if a.get_legend_handles_labels()[0]:
            a.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)
    logger.info("wrote %s", out_png)
