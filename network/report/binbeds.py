r"""The bin's beds of ``network.report``: resistance through the whole depth of a bin.

Given a bin (``--diameter`` B with ``--depth`` H), a grain with a **bed set** (rain-filled beds
of ``dem.pack --fill rain --stress σ_1 σ_2 ...``: one pour, each stress loaded through a lid from
the same poured state) is reported layer by layer. The vertical stress at depth z is Janssen's,

.. math:: \sigma_v(z) = \frac{\rho_b g B}{4 \mu_w K}\left(1 - e^{-4 \mu_w K z / B}\right),

with the grain library's wall friction μ_w and lateral pressure ratio K (copies,
``network._grains.JANSSEN``) and ρ_b = ρ_p (1 - ε_0) from the kernel density and the
surface bed's porosity ε_0 (network's sample region, as ``dem.pack --depth`` takes it). Each bed
of the set is solved by the network (inertial, both directions) at the bin velocities; its
porosity ε_i and pressure gradients g_i(U) are interpolated **linearly in stress** between the
set's beds (:func:`interpolate_in_stress`; held at the last bed within the lid's 2 % beyond it),
so at a bed's own stress the interpolation is that bed's solve. The grain's layers are in
series for vertical airflow,

.. math:: \Delta P_v(U) = \int_0^H g_z\big(U, \sigma_v(z)\big)\,dz

(:func:`layers_in_series`), beside D272's H g_{D272}(U) for loose fill; the horizontal
gradient is reported at the surface, mid-depth and bottom and as its depth mean
(1/H)∫ g_x dz. The bin velocities are the report's velocities where there are at most three,
else the first, the one nearest their geometric mean and the last (:func:`bin_velocities`):
each bed is solved once per direction at those only.

Solves are cached in ``--bed-dir`` (``bin_solves/<key>.json``), keyed by the bed file's SHA-256,
the code version (package version and a hash of the network, throats and cache sources) and the
solve's inputs: a second report on the same beds reads them. Where the bundled data hold no set
for a grain with a ``dem`` template (barley, canola), the set is packed on first use
(``dem.pack``, a progress bar; :func:`pack_bed_set`) into ``--bed-dir`` and reused. A grain
without μ_w and K (rough rice, sorghum) or without a template gets one line saying the report is
for its single bed alone.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .._cli import EXIT_BAD_INPUT, EXIT_FAILED, CliError
from .._grains import BED, JANSSEN, janssen_stress
from ..flow import asabe_d272_gradient
from ._binsolves import BIN_SOLVES, solve_cache_key, solve_set
from .bed import TEMPLATE_GRAINS
from .porosity import DATA_DIR, packing_meta

__all__ = ["BED_SET_STRESSES_PA", "BUNDLED_SETS", "BIN_SOLVES", "N_LAYERS", "STRESS_TOL", "bed_set_files",
           "bed_set_inputs", "bin_velocities", "interpolate_in_stress", "layers_in_series", "janssen_inputs",
           "plan_bin_beds", "pack_bed_set", "set_box", "solve_cache_key", "solve_set", "bin_section"]

#: the grains whose bed sets ship in network/data (the others with a dem template pack theirs on
#: first use)
BUNDLED_SETS = ("soybean", "wheat", "shelled_corn")
#: the stresses of a bed set packed on first use, Pa: the surface, and past Janssen's stress at
#: 10 m of a 6 m bin (38-44 kPa for soybean, wheat and shelled corn at their rain-filled bulk
#: density), so most bins' bottoms lie inside the set
BED_SET_STRESSES_PA = (0.0, 20_000.0, 45_000.0)
#: the lid holds its stress within this fraction (dem._load's stress_tol): a bottom stress this
#: far beyond the set's largest is that bed's
STRESS_TOL = 0.02
#: points of the depth integral (composite Simpson, an odd count)
N_LAYERS = 2001
#: kernels of a bed set packed on first use (the bundled sets hold 250-700)
SET_GRAINS = 600
_G = 9.80665
_ROOT = Path(__file__).resolve().parents[2]
_SET_RE = re.compile(r"^(?P<grain>[a-z_]+)_rain_(?P<kpa>[0-9.]+)kPa\.csv$")


def bed_set_files(grain: str, folder=DATA_DIR) -> list[tuple[float, Path]]:
    """[(stress Pa, CSV path)] of the bed set ``<grain>_rain_<kPa>kPa.csv`` in ``folder``,
    ascending in stress; the stress is the lid's measured one from each companion JSON (0 for
    the poured bed). [] if the folder holds none."""
    out = []
    folder = Path(folder)
    if not folder.is_dir():
        return []
    for p in folder.glob(f"{grain}_rain_*kPa.csv"):
        m = _SET_RE.match(p.name)
        if m is None or m["grain"] != grain:
            continue
        meta = packing_meta(p)
        if not meta or meta.get("converged") is False:
            continue
        load = meta.get("load") or {}
        s = float(load.get("lid_stress_pa") or 0.0) if load.get("target_pa") else 0.0
        out.append((s, p))
    out.sort()
    return out


def bin_velocities(velocities) -> list[float]:
    """The report's velocities where there are at most three, else the first, the one nearest
    their geometric mean (in ln U) and the last.

    >>> bin_velocities([0.01, 0.1])
    [0.01, 0.1]
    >>> bin_velocities([0.005, 0.01, 0.04, 0.1, 0.3])
    [0.005, 0.04, 0.3]
    """
    us = sorted(float(u) for u in velocities)
    if len(us) <= 3:
        return us
    mid = math.exp(0.5 * (math.log(us[0]) + math.log(us[-1])))
    k = int(np.argmin([abs(math.log(u / mid)) for u in us[1:-1]])) + 1
    return [us[0], us[k], us[-1]]


def interpolate_in_stress(stresses_pa, values, sigma_pa):
    """Values of the set's beds interpolated linearly in stress at ``sigma_pa`` (array), held at
    the end beds beyond them.

    >>> float(interpolate_in_stress([0.0, 2e4], [10.0, 14.0], 5e3))
    11.0
    """
    s = np.asarray(stresses_pa, dtype=float)
    v = np.asarray(values, dtype=float)
    if s.ndim != 1 or len(s) < 1 or v.shape[0] != len(s):
        raise ValueError("a bed set needs one value per stress")
    if np.any(np.diff(s) <= 0):
        raise ValueError(f"the set's stresses must increase, got {s.tolist()}")
    if len(s) == 1:
        return np.broadcast_to(v[0], np.shape(sigma_pa)).astype(float)
    return np.interp(np.asarray(sigma_pa, dtype=float), s, v)


def layers_in_series(depth_m: float, gradient_of_depth, n: int = N_LAYERS) -> float:
    r"""ΔP = ∫_0^H g(z) dz, Pa, of a gradient ``gradient_of_depth`` (vectorised, Pa/m, z in m)
    by composite Simpson on ``n`` (odd) points: the pressure drop across layers in series.

    >>> round(layers_in_series(2.0, lambda z: 3.0 + 4.0 * z), 9)   # 3 H + 2 H^2
    14.0
    """
    if not (math.isfinite(depth_m) and depth_m > 0):
        raise ValueError(f"depth must be finite and > 0, got {depth_m!r}")
    if n < 3 or n % 2 == 0:
        raise ValueError(f"Simpson's rule needs an odd n >= 3, got {n}")
    z = np.linspace(0.0, depth_m, n)
    g = np.asarray(gradient_of_depth(z), dtype=float)
    h = depth_m / (n - 1)
    return float(h / 3.0 * (g[0] + g[-1] + 4.0 * g[1:-1:2].sum() + 2.0 * g[2:-1:2].sum()))


def janssen_inputs(grain: str):
    """(K, μ_w) of the grain library (``network._grains.JANSSEN``), or None."""
    return JANSSEN.get(grain)


def _janssen(z, rho_b, diameter_m, k_lat, mu_w):
    return janssen_stress(z, bulk_density_kg_m3=rho_b, diameter_m=diameter_m,
                          wall_friction=mu_w, lateral_ratio=k_lat)


def set_box(grain: str) -> tuple[float, float, float]:
    """The cube (lx, ly, h m) of a bed set packed on first use: :data:`SET_GRAINS` kernels of
    the grain's volume at its loose-fill solid fraction (0.6 without one), side rounded to mm."""
    if grain not in TEMPLATE_GRAINS:
        raise ValueError(f"{grain} has no dem template")
    vol = _TEMPLATE_VOLUME_M3[grain]
    phi = BED[grain].loose_fill_porosity or 0.4
    side = round((SET_GRAINS * vol / (1 - phi)) ** (1 / 3), 3)
    return side, side, side


#: kernel volumes of dem's templates, m^3 (a copy: network does not import dem; the test of
#: tests/network/test_report_binbeds.py checks it against dem.templates)
_TEMPLATE_VOLUME_M3 = {"soybean": 1.4877665881225434e-07, "wheat": 3.6124005251161877e-08,
                       "shelled_corn": 1.4695563591763196e-07, "barley": 3.972006698120529e-08,
                       "canola": 2.1928725783600206e-09}


def bed_set_inputs(plan: dict | None) -> list[tuple[str, Path]]:
    """``(what, path)`` of every file of a used bin plan's bed set, to keep the report's outputs
    off them: each bed's CSV, companion JSON and ``.grains.csv``, bundled or in ``bed_dir`` (a set
    still to pack: the files it will have there). [] where no set is used."""
    if not plan or not plan.get("used"):
        return []
    if plan.get("beds"):
        csvs = [p for _, p in plan["beds"]]
    else:
        csvs = [Path(plan["bed_dir"]) / f"{plan['grain']}_rain_{s / 1000:g}kPa.csv"
                for s in BED_SET_STRESSES_PA]
    return [("a bed of the bin's bed set", f) for p in csvs
            for f in (Path(p), Path(p).with_suffix(".json"), Path(p).with_name(Path(p).stem + ".grains.csv"))]


def _set_in(grain: str, folder) -> list[tuple[float, Path]]:
    """A complete packed-on-first-use set in ``folder`` (its JSONs record the planned stresses)."""
    beds = bed_set_files(grain, folder)
    want = [s / 1000 for s in BED_SET_STRESSES_PA]
    names = {p.name for _, p in beds}
    if sorted(names) != sorted(f"{grain}_rain_{k:g}kPa.csv" for k in want):
        return []
    return beds


def plan_bin_beds(grain: str, *, depth_m: float, diameter_m, depth_given: bool,
                  particle_density: float, bed_dir, other: str | None = None,
                  data_dir=DATA_DIR) -> dict | None:
    """What the report does for the bin, decided before any work (no file written).

    Returns None where no bin is given (``--diameter`` with ``--depth``); else a dict with
    ``used`` (bool) and, when not used, ``why`` (one line); when used: ``beds`` [(stress, path)]
    (None: to pack into ``bed_dir``), ``source`` ("bundled" or "packed"), ``k_lat``, ``mu_w``,
    ``bed_dir``. ``other`` names an option that asks for one bed (``--packing``, ``--porosity``,
    ...); ``data_dir`` holds the bundled sets. ValueError for a depth whose bottom stress lies
    beyond the set's largest.
    """
    if diameter_m is None or not depth_given:
        return None
    jk = janssen_inputs(grain)
    if jk is None:
        return {"used": False, "why": (
            f"{grain} has no lateral pressure ratio K and wall friction mu_w in the grain library "
            "(Janssen's stress needs both; docs/grain-library.md): the report is for its single "
            "bed, not the bin's beds")}
    if other is not None:
        return {"used": False, "why": f"{other} asks for one bed: the report is for that bed "
                                      "alone, not the bin's beds"}
    beds = bed_set_files(grain, data_dir)
    plan = {"used": True, "grain": grain, "k_lat": jk[0], "mu_w": jk[1], "bed_dir": str(bed_dir),
            "depth_m": float(depth_m), "diameter_m": float(diameter_m),
            "particle_density_kg_m3": float(particle_density)}
    if beds:
        plan.update(beds=beds, source="bundled")
    elif grain in BUNDLED_SETS:
        return {"used": False, "why": (
            f"the bundled bed set of {grain} is missing from network/data: "
            "the report is for its single bed, not the bin's beds")}
    elif grain in TEMPLATE_GRAINS:
        found = _set_in(grain, bed_dir)
        plan.update(beds=found or None, source="packed", reused=bool(found))
    else:
        return {"used": False, "why": (
            f"{grain} has no bed set and no dem template to pack one: the report is for its "
            "single bed at its loose-fill porosity, not the bin's beds")}
    check_bin_depth(plan)
    return plan


def _surface_porosity(plan) -> tuple[float, str]:
    """(ε_0 of ρ_b, where from): the set's poured bed's network-region porosity, or (a set not
    yet packed) the grain's loose-fill porosity."""
    if plan.get("beds"):
        meta = packing_meta(plan["beds"][0][1])
        e = meta.get("porosity_network_region")
        if isinstance(e, (int, float)) and 0 < e < 1:
            return float(e), f"the surface bed's own ({plan['beds'][0][1].name})"
    e = BED[plan.get("grain", "")].loose_fill_porosity if plan.get("grain") in BED else None
    return (0.4 if e is None else float(e)), "the grain's loose-fill porosity (set not yet packed)"


def check_bin_depth(plan: dict) -> None:
    """ValueError naming ``--depth`` where Janssen's bottom stress lies more than the lid's 2 %
    beyond the set's largest stress (the deepest depth it covers quoted)."""
    e0, _ = _surface_porosity(plan)
    rho_b = plan["particle_density_kg_m3"] * (1 - e0)
    top = (max(s for s, _ in plan["beds"]) if plan.get("beds") else max(BED_SET_STRESSES_PA))
    top *= 1 + STRESS_TOL
    d, k, mu = plan["diameter_m"], plan["k_lat"], plan["mu_w"]
    bottom = float(_janssen(plan["depth_m"], rho_b, d, k, mu))
    if bottom > top:
        a = 4 * mu * k / d
        limit = rho_b * _G / a
        deepest = (math.inf if top >= limit else -math.log1p(-top / limit) / a)
        raise ValueError(
            f"--depth {plan['depth_m']:g} m: Janssen's stress at the bottom of this "
            f"{d:g} m bin, {bottom / 1000:.1f} kPa, is beyond the bed set's largest, "
            f"{top / (1 + STRESS_TOL) / 1000:.1f} kPa: its beds cover a depth of at most "
            f"{deepest:.2f} m here")


def bin_section(plan: dict, solved: list[dict], velocities, d272) -> dict:
    """The ``bin_beds`` entry of the report from the set's solves (module notes).

    ``d272``: (a, b) of the grain's D272 constants or None; ``velocities`` the bin velocities.
    """
    H, B = plan["depth_m"], plan["diameter_m"]
    k_lat, mu_w = plan["k_lat"], plan["mu_w"]
    e0, e0_src = _surface_porosity(plan)
    rho_b = plan["particle_density_kg_m3"] * (1 - e0)
    s = np.array([b["stress_pa"] for b in solved])
    eps = np.array([b["porosity"] for b in solved])
    gz = np.array([b["gradient_z_pa_per_m"] for b in solved])      # (beds, velocities)
    gx = np.array([b["gradient_x_pa_per_m"] for b in solved])
    sig = lambda z: _janssen(z, rho_b, B, k_lat, mu_w)
    depths = {"surface": 0.0, "mid": H / 2, "bottom": H}
    st = {k: float(sig(z)) for k, z in depths.items()}
    por = {k: float(interpolate_in_stress(s, eps, v)) for k, v in st.items()}
    rows = []
    for j, u in enumerate(velocities):
        fz = lambda z, j=j: interpolate_in_stress(s, gz[:, j], sig(z))
        fx = lambda z, j=j: interpolate_in_stress(s, gx[:, j], sig(z))
        dp = layers_in_series(H, fz)
        dpx_mean = layers_in_series(H, fx) / H
        row = {"velocity_m_s": float(u), "vertical_pressure_drop_pa": dp,
               "vertical_mean_gradient_pa_per_m": dp / H,
               "vertical_gradient_pa_per_m": {k: float(fz(z)) for k, z in depths.items()},
               "horizontal_gradient_pa_per_m": {k: float(fx(z)) for k, z in depths.items()},
               "horizontal_mean_gradient_pa_per_m": dpx_mean,
               "horizontal_to_vertical": dpx_mean / (dp / H),
               "converged": bool(all(b["converged"][j] for b in solved))}
        if d272 is not None:
            g = float(asabe_d272_gradient(u, a=d272[0], b=d272[1]))
            row["d272_pressure_drop_pa"] = g * H
            row["ratio_to_d272"] = dp / (g * H)
        else:
            row["d272_pressure_drop_pa"] = row["ratio_to_d272"] = None
        rows.append(row)
    mean_eps = layers_in_series(H, lambda z: interpolate_in_stress(s, eps, sig(z))) / H
    return {
        "used": True, "depth_m": H, "diameter_m": B, "source": plan["source"],
        "janssen": {"lateral_ratio_K": k_lat, "wall_friction_mu_w": mu_w,
                    "bulk_density_kg_m3": rho_b, "bulk_density_porosity": e0,
                    "bulk_density_porosity_source": e0_src,
                    "source": "network._grains.JANSSEN (copies of the grain library's "
                              "lateral_pressure_ratio and wall_friction_steel)"},
        "stress_pa": st, "porosity": por, "porosity_depth_mean": mean_eps,
        "beds": [{"stress_pa": b["stress_pa"], "path": _name(b["path"]), "porosity": b["porosity"],
                  "gradient_z_pa_per_m": list(b["gradient_z_pa_per_m"]),
                  "gradient_x_pa_per_m": list(b["gradient_x_pa_per_m"]),
                  "converged": list(b["converged"]), "cached": b["cached"]} for b in solved],
        "velocities_m_s": [float(u) for u in velocities],
        "points": rows,
        "note": ("each bed of the set solved by the network (inertial, both directions) at these "
                 "velocities; porosity and pressure gradients interpolated linearly in stress "
                 "between the set's beds, the stress Janssen's at each depth; vertical: layers in "
                 "series, the integral of the gradient over the depth; horizontal: the gradient "
                 "at each depth and its depth mean; D272: loose fill, depth x its gradient"),
    }


def _name(path) -> str:
    p = Path(path)
    return str(Path("network/data") / p.name) if p.resolve().parent == DATA_DIR else str(p)


def pack_command(grain: str, out, box) -> list[str]:
    """The dem.pack command of a bed set packed on first use."""
    lx, ly, h = box
    return [sys.executable, "-m", "dem.pack", "--scene", "box", "--size", f"{lx:g}", f"{ly:g}",
            "--height", f"{h:g}", "--grain", grain, "--fill", "rain", "--mass-scale", "100",
            "--stress", *[f"{s:g}" for s in BED_SET_STRESSES_PA], "--out", str(out)]


def pack_bed_set(plan: dict, grain: str, *, quiet: bool = False) -> dict:
    """Pack the grain's bed set with dem.pack into ``plan['bed_dir']`` (a tqdm progress bar over
    its stages: the pour and each load), through a temporary folder; fills ``plan['beds']``.
    Returns the run's record (command, seconds). dem.pack's failure is a CliError."""
    from tqdm import tqdm
    d = Path(plan["bed_dir"])
    d.mkdir(parents=True, exist_ok=True)
    box = set_box(grain)
    tmp = Path(tempfile.mkdtemp(prefix=".bedset-", dir=d))
    cmd = pack_command(grain, tmp / f"{grain}_rain.csv", box)
    env = dict(os.environ, PYTHONUNBUFFERED="1",
               PYTHONPATH=os.pathsep.join([str(_ROOT)] + [p for p in [
                   os.environ.get("PYTHONPATH")] if p]))
    stages = ["rain"] + [f"load {s / 1000:g} kPa" for s in BED_SET_STRESSES_PA if s > 0]
    t0 = time.perf_counter()
    lines: list[str] = []
    proc = None
    try:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, text=True, env=env)
        with tqdm(total=len(stages), desc=f"packing the {grain} bed set", unit="stage",
                  disable=quiet, file=sys.stderr) as bar:
            k, last, prev_step, shown = 0, None, 0, 0.0
            for line in proc.stdout:
                lines.append(line)
                m = re.match(r"\[(\w+)\s*\] step\s+(\d+)\s+t =\s+([0-9.]+) s", line)
                if m is None:
                    continue
                if m[1] == "load" and last == "rain" or m[1] == "load" and last == "load" \
                        and int(m[2]) < prev_step:
                    bar.update(1)
                    k += 1
                last, prev_step = m[1], int(m[2])
                if time.perf_counter() - shown > 1.0:        # at most once a second
                    shown = time.perf_counter()
                    bar.set_postfix_str(f"{stages[min(k, len(stages) - 1)]}: step {m[2]}, "
                                        f"t {m[3]} s")
            code = proc.wait()
            if code == 0:
                bar.update(len(stages) - bar.n)
        if code != 0:
            tail = next((x.strip() for x in reversed(lines) if x.startswith("error:")),
                        lines[-1].strip() if lines else "no message")
            raise CliError(f"dem.pack (the {grain} bed set): {tail}",
                           EXIT_BAD_INPUT if code == EXIT_BAD_INPUT else EXIT_FAILED)
        for p in sorted(tmp.iterdir()):
            os.replace(p, d / p.name)
    except KeyboardInterrupt:
        raise CliError(f"interrupted while packing the {grain} bed set; nothing written to {d}",
                       EXIT_FAILED) from None
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.wait()
        if proc is not None and proc.stdout is not None:
            proc.stdout.close()
        shutil.rmtree(tmp, ignore_errors=True)
    plan["beds"] = _set_in(grain, d)
    if not plan["beds"]:
        raise CliError(f"dem.pack exited 0 but the {grain} bed set in {d} is incomplete",
                       EXIT_FAILED)
    return {"command": " ".join(["python"] + cmd[1:]).replace(str(tmp), str(d)),
            "seconds": time.perf_counter() - t0}
