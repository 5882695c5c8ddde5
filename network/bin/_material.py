r"""The grain bulk's resistance, point by point: k_v(ε), k_h(ε), β(ε) and the porosity field.

Network law (``law="network"``). The porosity band's beds of a grain (``network.report``'s
band on the grain's own DEM beds, ``network/data/band_<grain>.json``: porosity ε_i and the
network's vertical gradient at three velocities) are fitted bed by bed with
``network.flow.fit_curve``'s Forchheimer form, g = μU/k + βρU², and ln k, ln β linearly in ε
over the beds:

.. math:: k_v(\varepsilon) = k_p\,e^{\kappa_1(\varepsilon - \varepsilon_p)}, \qquad
          \beta_v(\varepsilon) = \beta_p\,e^{b_1(\varepsilon - \varepsilon_p)}

(wheat: eight beds, ε 0.373-0.425), the slopes κ_1, b_1 from the beds and the values k_p, β_p
from the Forchheimer fit of the bundled bed's own vertical curve at its porosity ε_p, the bed
``network.report`` moves along its band (``network/data/anisotropy_<grain>.json``, which also
holds the horizontal curve). The horizontal permeability is k_h = a k_v with a = k_x/k_z of
the bundled bed's fits in both directions; β_h follows from the tensor law
(:mod:`network.bin._law`). A grain without band data has no bin law here (``network.report``
packs sphere beds for its band, minutes per run): the bin then needs ``law="d272"``.

D272 law (``law="d272"``): the standard's Shedd constants (``network._grains.D272``) for loose
fill, isotropic, scaled by the network's porosity effect where the grain has band data,
f(ε) = k_v(ε_0)/k_v(ε) with ε_0 the grain's loose-fill porosity (the standard's condition);
without band data the porosity field must be uniform.

Porosity field ε(h), h the depth below the local grain surface (m): uniform, a table (linear
between its rows, held beyond them) or Janssen's vertical stress with a porosity-stress curve
(:func:`janssen_stress`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._grains import BED, D272, G_M_S2, JANSSEN, janssen_stress
from ..core import read_table
from ..report.porosity import requested_porosity
from ._law import ForchheimerLaw, SheddLaw

__all__ = ["ANGLE_OF_REPOSE", "JANSSEN", "Material", "network_material", "d272_material",
           "read_profile", "janssen_stress", "PorosityProfile", "G_M_S2"]

DATA = Path(__file__).resolve().parent.parent / "data"

_EN = ("EN 1991-4:2006 Annex E Table E.1, angle of repose phi_r, as the grain library records it "
       "(dem.grains, the note of internal_friction_deg, with the table's transcription as source)")
_FARM = ("a US farm table of filling angles quoted in a forum thread gives lower values (wheat 25, "
         "soybeans 25, shelled corn 23, barley 28 degrees: "
         "https://community.agriculture.com/t5/Crops/Angle-of-repose/td-p/18193)")
#: angle of repose, degrees, and its source (the peaked top's default cone); copies of the grain
#: library's values (network does not import dem; tests/network/test_network_bin.py checks them)
ANGLE_OF_REPOSE = {
    "soybean": (29.0, f"{_EN}: 'Soya beans' row; {_FARM}"),
    "wheat": (34.0, f"{_EN}: wheat row; {_FARM}"),
    "shelled_corn": (35.0, f"{_EN}: 'Maize' row; {_FARM}"),
    "barley": (31.0, f"{_EN}: 'Barley' row; {_FARM}"),
}



@dataclass(frozen=True)
class PorosityProfile:
    """ε(h) of depth h below the grain surface (m): linear between (depth, porosity) rows,
    held beyond them; ``source`` says where it came from."""

    depth_m: np.ndarray
    porosity: np.ndarray
    source: str

    def __call__(self, depth_m):
        return np.interp(np.maximum(np.asarray(depth_m, dtype=float), 0.0), self.depth_m,
                         self.porosity)

    @classmethod
    def uniform(cls, porosity: float, source: str) -> "PorosityProfile":
        return cls(np.array([0.0, 1.0]), np.array([porosity, porosity]), source)

    @property
    def is_uniform(self) -> bool:
        return bool(np.ptp(self.porosity) == 0)


def read_profile(path, option: str = "--porosity-profile") -> tuple[np.ndarray, np.ndarray]:
    """Two columns of a CSV with a header (depth_m,porosity or stress_pa,porosity): x ascending
    from >= 0, y in (0, 1); read as spreadsheets write it (:func:`network.core.read_table`);
    ValueError naming the option, the file and the row."""
    xs, ys = [], []
    try:
        head, rows = read_table(path, option, what="a porosity profile")
    except ValueError as e:
        if "empty file" not in str(e):
            raise
        raise ValueError(f"{option} {path}: empty file") from None
    want = ("depth_m", "porosity") if option == "--porosity-profile" else ("stress_pa",
                                                                          "porosity")
    if [h.lower() for h in head] != list(want):
        raise ValueError(f"{option} {path}: header must be {','.join(want)}, got "
                         f"{','.join(head)}")
    for i, row in rows:
        if len(row) != 2:
            raise ValueError(f"{option} {path} row {i}: {len(row)} values, the header has 2")
        try:
            x, y = float(row[0]), float(row[1])
        except ValueError:
            raise ValueError(f"{option} {path} row {i}: {row!r} is not two numbers") from None
        if not (math.isfinite(x) and x >= 0):
            raise ValueError(f"{option} {path} row {i}: {want[0]} must be finite and >= 0, "
                             f"got {row[0].strip()}")
        if not (0 < y < 1):
            raise ValueError(f"{option} {path} row {i}: porosity must be in (0, 1), got "
                             f"{row[1].strip()}")
        if xs and x <= xs[-1]:
            raise ValueError(f"{option} {path} row {i}: {want[0]} {x:g} does not increase")
        xs.append(x)
        ys.append(y)
    if len(xs) < 1:
        raise ValueError(f"{option} {path}: no rows")
    if len(xs) == 1:
        xs, ys = [xs[0], xs[0] + 1.0], [ys[0], ys[0]]
    return np.array(xs), np.array(ys)


@dataclass(frozen=True)
class Material:
    """The bin's law: a builder of the per-element law from per-element porosity, the kernel
    density (kg/m³), the porosity profile and what to say about them."""

    law: str
    grain: str
    viscosity_pa_s: float
    density_kg_m3: float
    particle_density_kg_m3: float
    anisotropy: float
    profile: PorosityProfile
    k_coef: tuple | None          # (κ0, κ1) of ln k_v(ε)
    beta_coef: tuple | None       # (b0, b1) of ln β_v(ε)
    d272: tuple | None            # (a, b) Shedd constants
    loose_porosity: float | None
    band_range: tuple | None
    note: str

    def k_v(self, eps):
        """k_v(ε), m²."""
        return np.exp(self.k_coef[0] + self.k_coef[1] * np.asarray(eps, dtype=float))

    def beta_v(self, eps):
        """β_v(ε), 1/m."""
        return np.exp(self.beta_coef[0] + self.beta_coef[1] * np.asarray(eps, dtype=float))

    def element_law(self, eps):
        """The law for per-element porosities ``eps`` (Ne,)."""
        eps = np.asarray(eps, dtype=float)
        if self.law == "network":
            return ForchheimerLaw(self.viscosity_pa_s / self.k_v(eps),
                                  self.beta_v(eps) * self.density_kg_m3, self.anisotropy)
        f = np.ones_like(eps)
        if self.k_coef is not None:
            f = self.k_v(self.loose_porosity) / self.k_v(eps)
        return SheddLaw(f, self.d272[0], self.d272[1], self.anisotropy)

    def gradient_1d(self, velocity_m_s, eps, *, axis="z"):
        """The 1-D law g(U), Pa/m, at porosity ε along z (vertical) or x (horizontal)."""
        law = self.element_law(np.atleast_1d(eps))
        u = np.asarray(velocity_m_s, dtype=float)
        if axis == "z":
            return law.resistance(u)
        a = self.anisotropy                 # horizontal: W = U/√a, G = F(W) = √a g
        return law.resistance(u / np.sqrt(a)) / np.sqrt(a)

    def as_json(self) -> dict:
        out = {"law": self.law, "grain": self.grain, "viscosity_pa_s": self.viscosity_pa_s,
               "air_density_kg_m3": self.density_kg_m3,
               "particle_density_kg_m3": self.particle_density_kg_m3,
               "anisotropy_kh_over_kv": self.anisotropy,
               "porosity_profile": {"depth_m": self.profile.depth_m.tolist(),
                                    "porosity": self.profile.porosity.tolist(),
                                    "source": self.profile.source},
               "note": self.note}
        if self.k_coef is not None:
            out["ln_k_v"] = {"intercept": self.k_coef[0], "slope_per_porosity": self.k_coef[1]}
            out["ln_beta_v"] = {"intercept": self.beta_coef[0],
                                "slope_per_porosity": self.beta_coef[1]}
            out["band_porosity_range"] = (None if self.band_range is None
                                          else list(self.band_range))
        if self.d272 is not None:
            out["d272_a_pa_s2_m3"], out["d272_b_s_m"] = self.d272
        return out


def _forchheimer(u, g, mu, rho):
    m = np.column_stack([mu * u, rho * u**2]) / g[:, None]
    (ik, beta), *_ = np.linalg.lstsq(m, np.ones_like(u), rcond=None)
    return 1.0 / ik, beta


def fit_network_law(*, velocities_m_s, vertical_pa_per_m, horizontal_pa_per_m, porosity,
                    viscosity_pa_s, density_kg_m3, band_velocities_m_s=None, band_beds=None):
    """The network law's constants from a bed's curves and its porosity band.

    Parameters
    ----------
    velocities_m_s, vertical_pa_per_m, horizontal_pa_per_m : (n,) array_like
        The bed's network gradients (Pa/m) in z and x at n >= 2 velocities (m/s).
    porosity : float
        The bed's porosity ε_p.
    viscosity_pa_s, density_kg_m3 : float
        The air of those solves (and of the band's).
    band_velocities_m_s : (m,) array_like, optional
    band_beds : sequence of dict, optional
        Beds with ``porosity`` and ``pressure_gradient_pa_per_m`` (m,); None: no porosity
        dependence (κ_1 = b_1 = 0).

    Returns
    -------
    ((κ0, κ1), (b0, b1), (ε min, ε max) of the band or None, k_h/k_v, note)
    """
    u = np.asarray(velocities_m_s, dtype=float)
    mu, rho = float(viscosity_pa_s), float(density_kg_m3)
    kz, bz = _forchheimer(u, np.asarray(vertical_pa_per_m, float), mu, rho)
    kx, bx = _forchheimer(u, np.asarray(horizontal_pa_per_m, float), mu, rho)
    if not all(np.isfinite(v) and v > 0 for v in (kz, bz, kx, bx)):
        raise ValueError(f"the bed's curves give no positive Forchheimer fit (k {kz:.3g}, "
                         f"{kx:.3g} m^2; beta {bz:.3g}, {bx:.3g} 1/m)")
    k1 = b1 = 0.0
    rng, how = None, "no porosity band: the law holds at the bed's porosity only"
    if band_beds:
        ub = np.asarray(band_velocities_m_s, dtype=float)
        eps, lk, lb = [], [], []
        for bed in band_beds:
            k, beta = _forchheimer(ub, np.array(bed["pressure_gradient_pa_per_m"], float),
                                   mu, rho)
            eps.append(float(bed["porosity"]))
            lk.append(math.log(k))
            lb.append(math.log(beta))
        k1, _ = np.polyfit(eps, lk, 1)
        b1, _ = np.polyfit(eps, lb, 1)
        rng = (min(eps), max(eps))
        how = (f"the slopes of ln k_v and ln beta_v in porosity over the {len(eps)} band beds "
               f"(Forchheimer fit per bed): {k1:.3f}, {b1:.3f}")
    e_p = float(porosity)
    k0, b0 = math.log(kz) - k1 * e_p, math.log(bz) - b1 * e_p
    a = kx / kz
    note = (f"network law: {how}; anchored at the bed's vertical fit (porosity {e_p:.4f}, "
            f"k_v {kz:.4g} m^2, beta_v {bz:.4g} 1/m); k_h/k_v = {a:.4f} from its fits in x and "
            f"z; the tensor law's beta_h/beta_v = {a**-1.5:.4f}, the network's own "
            f"{bx / bz:.4f}")
    return (float(k0), float(k1)), (float(b0), float(b1)), rng, float(a), note


def _band_fit(grain: str):
    """:func:`fit_network_law` of the bundled band and anisotropy files, or None without."""
    path, apath = DATA / f"band_{grain}.json", DATA / f"anisotropy_{grain}.json"
    if not (path.is_file() and apath.is_file()):
        return None
    band, an = json.loads(path.read_text()), json.loads(apath.read_text())
    k, b, rng, a, note = fit_network_law(
        velocities_m_s=an["velocities_m_s"], vertical_pa_per_m=an["vertical_pa_per_m"],
        horizontal_pa_per_m=an["horizontal_pa_per_m"], porosity=an["porosity"],
        viscosity_pa_s=an["viscosity_pa_s"], density_kg_m3=an["density_kg_m3"],
        band_velocities_m_s=band["velocities_m_s"], band_beds=band["beds"])
    return k, b, rng, a, note + f" (network/data/{path.name}, network/data/{apath.name})"


def report_fit(path, grain: str):
    """:func:`fit_network_law` of a ``network.report --json`` file: its bed's curves in z and x
    at the bed's own porosity (the report's horizontal gradients divided by its porosity
    shift factor) and its band's beds. ValueError naming the file and what is missing."""
    try:
        r = json.loads(Path(path).read_text())
        pts = [q for q in r["points"] if q["converged"] and q.get("converged_horizontal", True)]
        u = [q["velocity_m_s"] for q in pts]
        gz = [q["pressure_gradient_packing_pa_per_m"] for q in pts]
        gx = [q["pressure_gradient_horizontal_pa_per_m"] / q["porosity_shift_factor"]
              for q in pts]
        e_p, mu, rho = r["porosity_packing"], r["viscosity_pa_s"], r["air_density_kg_m3"]
        band = r.get("band")
        rgrain = r["grain"]
    except (ValueError, KeyError, TypeError, ZeroDivisionError) as exc:
        raise ValueError(f"--report {path}: not a network.report JSON ({type(exc).__name__}: "
                         f"{exc})") from None
    if rgrain != grain:
        raise ValueError(f"--report {path} is a report of {rgrain}, not of --grain {grain}")
    if len(u) < 2:
        raise ValueError(f"--report {path}: fewer than two converged velocities")
    k, b, rng, a, note = fit_network_law(
        velocities_m_s=u, vertical_pa_per_m=gz, horizontal_pa_per_m=gx, porosity=e_p,
        viscosity_pa_s=mu, density_kg_m3=rho,
        band_velocities_m_s=None if band is None else band["velocities_m_s"],
        band_beds=None if band is None else band["beds"])
    return k, b, rng, a, note + f" (network.report's JSON {path}; its bed {r['packing']})", e_p


def _profile(grain, porosity, profile, compaction, janssen):
    if profile is not None:
        d, e = profile
        return PorosityProfile(d, e, "--porosity-profile (the user's table)")
    if compaction is not None:
        (s, e), (rho_b, diam, mu_w, k_lat) = compaction, janssen
        depth = np.linspace(0.0, 60.0, 601)
        sig = janssen_stress(depth, bulk_density_kg_m3=rho_b, diameter_m=diam,
                             wall_friction=mu_w, lateral_ratio=k_lat)
        return PorosityProfile(depth, np.interp(sig, s, e),
                               f"Janssen (wall friction {mu_w:g}, K {k_lat:g}, bulk density "
                               f"{rho_b:.1f} kg/m^3) with the --compaction curve")
    eps, why = requested_porosity(grain, porosity)
    if eps is None:
        raise ValueError(f"no measured loose-fill porosity for {grain}: give --porosity")
    return PorosityProfile.uniform(eps, "uniform: " + why)


def _density(grain, particle_density):
    if particle_density is not None:
        return float(particle_density)
    rho_p = BED[grain].particle_density_kg_m3
    if rho_p is None:
        raise ValueError(f"no sourced kernel density for {grain}: give --particle-density")
    return float(rho_p)


def network_material(grain: str, *, viscosity_pa_s: float, density_kg_m3: float,
                     porosity=None, profile=None, compaction=None, janssen=None,
                     particle_density=None, report=None) -> Material:
    """The network's law for ``grain``: from the bundled band and curves, or from a
    ``network.report --json`` file (``report``); ValueError saying what to run without either.
    """
    prof = _profile(grain, porosity, profile, compaction, janssen)
    if report is not None:
        kc, bc, rng, a, note, e_p = report_fit(report, grain)
        if rng is None and not (prof.is_uniform and abs(prof.porosity[0] - e_p) < 5e-4):
            raise ValueError(f"--report {report} has no porosity band (--no-band): the law "
                             f"holds at its bed's porosity {e_p:.4f} only; give --porosity "
                             f"{e_p:.4f} or a report with its band")
    else:
        fit = _band_fit(grain)
        if fit is None:
            raise ValueError(
                f"no porosity band of {grain}'s own beds is bundled (network/data/band_"
                f"{grain}.json; bundled: wheat): run python -m network.report --grain {grain} "
                "--json r.json (its band packs sphere beds, minutes) and give --report r.json, "
                "or use --law d272")
        kc, bc, rng, a, note = fit
    loose = requested_porosity(grain, None)[0]
    return Material("network", grain, viscosity_pa_s, density_kg_m3,
                    _density(grain, particle_density), a, prof, kc, bc, None, loose, rng, note)


def d272_material(grain: str, *, viscosity_pa_s: float, density_kg_m3: float, porosity=None,
                  profile=None, compaction=None, janssen=None,
                  particle_density=None) -> Material:
    """D272's Shedd law for ``grain``, isotropic, scaled by the band's porosity effect."""
    c = D272[grain]
    if c.a_pa_s2_m3 is None:
        raise ValueError(f"no sourced ASABE D272 constants for {grain} (network/_grains.py): "
                         "--law d272 cannot be used")
    prof = _profile(grain, porosity, profile, compaction, janssen)
    fit = _band_fit(grain)
    loose = requested_porosity(grain, None)[0]
    if fit is None or loose is None:
        if not prof.is_uniform:
            raise ValueError(f"--law d272 with a porosity field needs {grain}'s porosity band "
                             f"(network/data/band_{grain}.json, not bundled): give a uniform "
                             "porosity")
        return Material("d272", grain, viscosity_pa_s, density_kg_m3,
                        _density(grain, particle_density), 1.0, prof, None, None,
                        (c.a_pa_s2_m3, c.b_s_m), loose, None,
                        "D272 Shedd constants for loose fill, isotropic, at every porosity")
    kc, bc, rng, _, _ = fit
    note = (f"D272 Shedd constants for loose fill (porosity {loose:g}), isotropic, times "
            f"k_v({loose:g})/k_v(porosity) of the network's band (network/data/band_{grain}"
            ".json)")
    return Material("d272", grain, viscosity_pa_s, density_kg_m3,
                    _density(grain, particle_density), 1.0, prof, kc, bc,
                    (c.a_pa_s2_m3, c.b_s_m), loose, rng, note)
