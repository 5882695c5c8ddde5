"""Figures and the self-contained HTML page of ``network.report`` (matplotlib imported lazily).

:func:`write_figures` draws three PNGs from the report dict (the JSON document): the resistance
curve (vertical, horizontal, D272, Ergun, the porosity band ±0.02 shaded), the system curve with
the fan and its operating point, and the band's ln(ΔP/L) against porosity; :func:`write_html`
writes one HTML file with the tables and those PNGs embedded as base64 (no other file needed).
"""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import numpy as np

__all__ = ["FIGURES", "write_figures", "write_html"]

#: the figures a report draws, ``report_<name>.png`` (the band's only with a band)
FIGURES = ("curve", "system", "band")


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return buf.getvalue()


def _curve(plt, r):
    pts = [p for p in r["points"] if p["converged"]]
    u = np.array([p["velocity_m_s"] for p in pts])
    fig, ax = plt.subplots(figsize=(6, 4.4))
    if pts and pts[0]["pressure_gradient_band_pa_per_m"]:
        lo = [p["pressure_gradient_band_pa_per_m"]["+0.02"] for p in pts]
        hi = [p["pressure_gradient_band_pa_per_m"]["-0.02"] for p in pts]
        ax.fill_between(u, lo, hi, color="C0", alpha=0.18, label="porosity +-0.02")
    ax.loglog(u, [p["pressure_gradient_pa_per_m"] for p in pts], "o-", label="network vertical")
    ax.loglog(u, [p["pressure_gradient_horizontal_pa_per_m"] for p in pts], "s-",
              label="network horizontal", ms=4)
    lo, hi = r["d272"].get("velocity_range_m_s") or (0.0, np.inf)
    inside = [p for p in pts if lo <= p["velocity_m_s"] <= hi
              and p["d272_pressure_gradient_pa_per_m"] is not None]
    if inside:                  # D272 only over the velocities it is stated for
        ax.loglog([p["velocity_m_s"] for p in inside],
                  [p["d272_pressure_gradient_pa_per_m"] for p in inside], "--",
                  label=f"ASABE D272 {r['grain']} ({lo:g}-{hi:g} m/s)")
    ax.loglog(u, [p["ergun_pressure_gradient_pa_per_m"] for p in pts], ":", label="Ergun")
    ax.set_xlabel("superficial velocity U (m/s)")
    ax.set_ylabel("pressure gradient (Pa/m)")
    ax.set_title(f"{r['grain']}, porosity {r['porosity']:.3f}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def _system(plt, r):
    s = r["system_curve"]
    fig, ax = plt.subplots(figsize=(6, 4.4))
    ax.plot([x["airflow_m3_s"] for x in s], [x["static_pressure_pa"] for x in s], "o-",
            label=f"grain, depth {r['bin']['depth_m']:g} m")
    fan = r.get("fan_curve")
    if fan:
        ax.plot(fan["airflow_m3_s"], fan["static_pressure_pa"], "s--", label="fan")
    op = r.get("operating_point")
    if op and op.get("found"):
        ax.plot([op["airflow_m3_s"]], [op["static_pressure_pa"]], "k*", ms=12,
                label="operating point")
    ax.set_xlabel("airflow (m^3/s)")
    ax.set_ylabel("static pressure (Pa)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def _band(plt, r):
    b = r["band"]
    j = len(b["velocities_m_s"]) // 2
    fig, ax = plt.subplots(figsize=(6, 4.4))
    for seed in sorted({x["seed"] for x in b["beds"]}):
        beds = [x for x in b["beds"] if x["seed"] == seed]
        ax.semilogy([x["porosity"] for x in beds],
                    [x["pressure_gradient_pa_per_m"][j] for x in beds], "o-",
                    label=f"seed {seed}")
    ax.set_xlabel("porosity")
    ax.set_ylabel(f"pressure gradient at {b['velocities_m_s'][j]:.3g} m/s (Pa/m)")
    ax.set_title(f"common slope d ln(dP/L)/d porosity = {b['slopes'][j]:.2f} "
                 f"+- {b['slope_stderrs'][j]:.2f}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def write_figures(r: dict, plot_dir=None) -> dict:
    """PNG bytes of the report's figures, ``{"png": {name: bytes}, "files": [paths],
    "removed": [paths]}``; with ``plot_dir`` also written there as ``report_<name>.png``, and a
    ``report_<name>.png`` of :data:`FIGURES` this report does not draw (the band's, without a
    band) removed from it, so the folder holds this run's figures only."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    makers = {"curve": _curve, "system": _system}
    if r.get("band"):
        makers["band"] = _band
    png, files, removed = {}, [], []
    for name in FIGURES:
        stale = None if plot_dir is None else Path(plot_dir) / f"report_{name}.png"
        if name not in makers and stale is not None and stale.is_file():
            stale.unlink()              # an earlier run's figure this run does not draw
            removed.append(str(stale))
    for name, make in makers.items():
        fig = make(plt, r)
        png[name] = _png(fig)
        plt.close(fig)
        if plot_dir is not None:
            path = Path(plot_dir) / f"report_{name}.png"
            path.write_bytes(png[name])
            files.append(str(path))
    return {"png": png, "files": files, "removed": removed}


def _table(head, rows) -> str:
    th = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><tr>{th}</tr>{body}</table>"


def _f(v, fmt=".4g") -> str:
    return "-" if v is None else format(v, fmt)


def _converged(p) -> str:
    bad = [ax for ax, ok in (("z", p["converged"]), ("x", p.get("converged_horizontal", True)))
           if not ok]
    return f"NO ({', '.join(bad)}): not a result" if bad else "yes"


def write_html(path, r: dict, png: dict) -> None:
    """One self-contained HTML file: summary, curve table, system table, embedded plots."""
    band = r.get("band")
    offs = ["-0.02", "-0.01", "+0.01", "+0.02"]
    curve = _table(["U m/s", "Re_p", "dP/L vertical Pa/m", "dP/L horizontal Pa/m",
                    "D272 Pa/m", "Ergun Pa/m"] + [f"porosity {o} Pa/m" for o in offs]
                   + ["converged"],
                   [[_f(p["velocity_m_s"]), _f(p["reynolds_particle"], ".3g"),
                     _f(p["pressure_gradient_pa_per_m"]),
                     _f(p["pressure_gradient_horizontal_pa_per_m"]),
                     _f(p["d272_pressure_gradient_pa_per_m"]),
                     _f(p["ergun_pressure_gradient_pa_per_m"])]
                    + [_f((p["pressure_gradient_band_pa_per_m"] or {}).get(o)) for o in offs]
                    + [_converged(p)] for p in r["points"]])
    system = _table(["U m/s", "airflow m^3/s", "airflow m^3/(min t)", "airflow m^3/(min m^3)",
                     "static pressure Pa"],
                    [[_f(s["velocity_m_s"]), _f(s["airflow_m3_s"]), _f(s["airflow_m3_min_t"]),
                      _f(s["airflow_m3_min_m3"]), _f(s["static_pressure_pa"])]
                     for s in r["system_curve"]])
    op = r.get("operating_point")
    if op and op.get("found"):
        op_text = (f"Operating point: {op['airflow_m3_s']:.4g} m^3/s, "
                   f"{op['airflow_m3_min_t']:.4g} m^3/(min t), static pressure "
                   f"{op['static_pressure_pa']:.4g} Pa, U {op['velocity_m_s']:.4g} m/s.")
    else:
        op_text = op["message"] if op else "No fan curve given (--fan)."
    fits = "".join(f"<li>{html.escape(name)}: " + ", ".join(
        f"{k} = {_f(v)}" for k, v in f.items()) + "</li>"
        for name, f in (("vertical", r["fits"]), ("horizontal", r["fits_horizontal"]))
        if f and f["permeability_m2"] is not None)
    band_text = ("Porosity band skipped (--no-band)." if not band else
                 "d ln(dP/L)/d(porosity) = " + ", ".join(
                     f"{s:.2f} &plusmn; {se:.2f} at {u:.3g} m/s" for s, se, u in
                     zip(band["slopes"], band["slope_stderrs"], band["velocities_m_s"]))
                 + f" from {len(band['beds'])} beds of {html.escape(band['packer'])}.")
    bn = r["bin"]
    way = ("vertical airflow (z), depth" if bn["flow_axis"] == "z"
           else "horizontal airflow (x), thickness crossed")
    size = (f"{way} {bn['depth_m']:g} m, "
            + (f"diameter {bn['diameter_m']:g} m, " if bn.get("diameter_m") else "")
            + f"floor {bn['floor_area_m2']:.4g} m^2, {bn['grain_mass_t']:.4g} t")
    a = r.get("airflow")
    if a:
        op_text = (f"Airflow asked: {a['airflow_m3_min_t']:.4g} m^3/(min t) = "
                   f"{a['velocity_m_s']:.4g} m/s, {a['airflow_m3_s']:.4g} m^3/s, static pressure "
                   f"{a['static_pressure_pa']:.4g} Pa"
                   + ("" if a.get("converged", True) else
                      " (NOT CONVERGED: the nonlinear solve stopped short, not a result)")
                   + ". " + op_text)
    imgs = "".join(f'<p><img alt="{n}" src="data:image/png;base64,'
                   f'{base64.b64encode(b).decode("ascii")}"></p>' for n, b in png.items())
    doc = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>grainflow report: {html.escape(r['grain'])}</title>
<style>body{{font-family:sans-serif;max-width:70em;margin:1em auto}}
table{{border-collapse:collapse}}td,th{{border:1px solid #aaa;padding:2px 6px;text-align:right}}
</style></head><body>
<h1>Airflow resistance: {html.escape(r['grain'])}</h1>
<p>Packing {html.escape(r['packing'])} ({r['n_spheres']} spheres), porosity
{r['porosity']:.4f} ({html.escape(r['porosity_source'])}); bulk density
{r['bulk_density_kg_m3']:.1f} kg/m^3 (kernel density {r['particle_density_kg_m3']:g} kg/m^3,
{html.escape(r['particle_density_source'])}).</p>
<h2>Resistance curve</h2>{curve}<p>{band_text}</p><ul>{fits}</ul>
<h2>System curve</h2><p>{html.escape(size)}; static pressure of the grain only.</p>{system}
<p>{html.escape(op_text)}</p>
<h2>Plots</h2>{imgs}
</body></html>
"""
    Path(path).write_text(doc)
