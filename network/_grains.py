r"""ASABE D272 (Shedd / Hukill-Ives) airflow-resistance constants by grain: data only.

.. math:: \frac{\Delta P}{L} = \frac{a U^2}{\ln(1 + b U)}

with ΔP/L in Pa/m, U the superficial velocity in m/s, a in Pa·s²/m³ and b in m²·s/m³ (= s/m),
the form and units of ASAE/ASABE D272.3. The values are for a loose fill of clean, relatively dry
grain; D272.3's note (ASAE D272.3 MAR96, section 2, the one part of the standard found in a stored
copy: https://ro.scribd.com/document/458884232/droppressuregrains-pdf) says packing in a bin may
raise the resistance by up to 50 %, and grain in equilibrium with air above 85 % RH takes 80 % of
the pressure drop. Soybean's constants are the thesis's; wheat, shelled corn, sorghum and rough
rice come from one secondary source (a fan-sizing program's table, each entry's ``source``),
the standard's own table not seen. Only constants read from a source are here; a grain whose
constants were not found has ``a = b = None`` and a note. Grain names are those of
``dem.grains.GRAINS``.

>>> c = D272["soybean"]
>>> round(0.25 * c.a_pa_s2_m3 * 0.013**2 / __import__("math").log1p(c.b_s_m * 0.013), 2)
2.28
"""

from __future__ import annotations

import json
import math
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["G_M_S2", "JANSSEN", "janssen_stress", "D272Constants", "D272", "GRAIN_ALIASES", "HUKILL_IVES_RANGE_M_S", "d272_constants",
           "d272_line", "d272_velocity_range", "grain_key", "packing_grain", "template_grain",
           "grains_with_d272",
           "BedProperties", "BED"]


log = logging.getLogger(__name__)
#: the bundled packings, ``<grain>_default.csv`` (spheres) and ``<grain>_grains.csv``
_DATA_DIR = Path(__file__).resolve().parent / "data"


@dataclass(frozen=True)
class D272Constants:
    """D272 constants of one grain (``None`` where not found; ``note`` then says so)."""

    a_pa_s2_m3: float | None
    b_s_m: float | None
    #: valid superficial velocity range (low, high), m/s, as the source gives it
    velocity_range_m_s: tuple[float, float] | None
    #: the same range in the standard's m^3/(min m^2), as the source gives it
    airflow_range_m3_min_m2: tuple[float, float] | None
    edition: str
    source: str
    note: str = ""


_NOT_FOUND = ("not found: the D272.3 table of constants was not in any stored copy searched (the "
              "scribd copy of ASAE D272.3 MAR96 shows only its first page); no other source found "
              "quoting this grain's constants")

#: The secondary source of every grain but soybean: a stored public GitHub file that the
#: project's search index names by id only (its repository is not given).
_SRC_A = ("secondary source: stored public GitHub file, search-index id 70324629401, a JavaScript "
          "port of the VBA macros of the spreadsheet Resistencia_Fluxo_de_Ar.xls (silo aeration "
          "fan sizing); its table ('A, B: constantes de Shedd'; 'Perda de carga por metro "
          "(Shedd):  dP/L = A·Q² / ln(1 + B·Q)   [Pa/m, Q em m³/(s·m²)]') names ASAE D272.3 (its "
          "canola comment: 'Conferir com a ASAE D272.3'), and its soybean row 'Soja: ... A: "
          "10200, B: 16' is the thesis's D272.3 soybean pair")
_EDITION_A = "ASAE D272.3 (as quoted by a secondary source; edition not stated)"
_NOTE_A = ("secondary source only: the standard's own table was not seen; the source gives no "
           "valid airflow range and no edition (D272.3 is inferred from its canola comment and "
           "its soybean row)")

D272: dict[str, D272Constants] = {
    "soybean": D272Constants(
        1.02e4, 16.0, None, None, "ASABE D272.3 (ASABE 2011)",
        "thesis section 4.2.3 (seed/thesis.txt: 'For soybeans, the two constants were found to "
        "be a = 1.02e4 Pa s^2 m^-3 and b = 16.0 m^-1 s'), quoting ASABE Standards D272.3 (2011); "
        "its 2.28 Pa at 0.013 m/s over 0.25 m (Table 4.5) checks them",
        "secondary source (the standard's own table not seen); valid airflow range not found"),
    "wheat": D272Constants(
        2.70e4, 8.77, None, None, _EDITION_A,
        _SRC_A + "; wheat row: \"Trigo: { massa: 772, repouso: 30, faixas: [{ ate: Infinity, "
        "A: 27000, B: 8.77 }] }\"", _NOTE_A),
    "shelled_corn": D272Constants(
        2.07e4, 30.4, None, None, _EDITION_A,
        _SRC_A + "; corn row, upper band: \"Milho: ... { ate: Infinity, A: 20700, B: 30.4 }\"; "
        "confirmed by a second stored public GitHub file, search-index id 70970216257 (a "
        "shelled-corn aeration sizing script): '# ASABE D272 Shedd constants for shelled corn: "
        "dP/L = a Q² / ln(1 + b Q), Pa/m, Q in m³/(s m²)' and "
        "'SHEDD_A, SHEDD_B = 2.07e4, 30.4'",
        _NOTE_A + ". The same file splits corn at Q = 0.0203 m/s ('Milho tem duas faixas de "
        "vazão (corte em Q = 0,0203 m³/(s·m²))'): '{ ate: 0.0203, A: 9970, B: 8.55 }' below, "
        "the pair here above; that low band is confirmed by no second source, so it is not "
        "used: the upper band's pair here is applied at every velocity"),
    "barley": D272Constants(None, None, None, None, "ASABE D272.3", "not found", _NOT_FOUND),
    "rough_rice": D272Constants(
        2.57e4, 13.2, None, None, _EDITION_A,
        _SRC_A + "; rice row: \"Arroz: { massa: 570, repouso: 36, faixas: [{ ate: Infinity, "
        "A: 25700, B: 13.2 }] }\"",
        _NOTE_A + ". The source says 'Arroz' (rice) without saying rough or milled; it is taken "
        "as rough rice because D272's grain list has rough rice: an inference, not stated by "
        "the source"),
    "canola": D272Constants(
        None, None, None, None, "ASABE D272.3", "not found",
        "not found: the D272.3 table of constants was not in any stored copy searched (the "
        "scribd copy of ASAE D272.3 MAR96 shows only its first page); the only source found "
        "quoting canola constants (search-index id 70324629401, A 28000, B 12) marks them "
        "provisional: 'A e B: PROVISÓRIOS. Conferir com a ASAE D272.3 / Jayas et al. (1987) "
        "antes de usar em dimensionamento.', so they are not used"),
    "sorghum": D272Constants(
        2.12e4, 8.06, None, None, _EDITION_A,
        _SRC_A + "; sorghum row: \"Sorgo: { massa: 721, repouso: 30, faixas: [{ ate: Infinity, "
        "A: 21200, B: 8.06 }] }\"", _NOTE_A),
}


#: Other names people use for the grains of :data:`D272`.
GRAIN_ALIASES = {"soybeans": "soybean", "corn": "shelled_corn", "maize": "shelled_corn",
                 "rice": "rough_rice", "paddy": "rough_rice", "rapeseed": "canola",
                 "milo": "sorghum"}


#: The velocity range, m/s, over which the Hukill-Ives form of D272 is stated to hold: "a
#: larger range of velocities (0.01-2.0 m s-1)" (thesis section 2.3.2, on Hukill & Ives 1955).
#: The standard's own per-grain ranges are not in any source here (``velocity_range_m_s`` of
#: every grain is None), so this range bounds where a D272 curve is drawn.
HUKILL_IVES_RANGE_M_S = (0.01, 2.0)


def d272_velocity_range(name: str) -> tuple[tuple[float, float], str]:
    """((low, high) m/s, where it comes from) over which a grain's D272 curve is drawn: the
    grain's own range where a source gives one, else :data:`HUKILL_IVES_RANGE_M_S`.

    >>> d272_velocity_range("wheat")[0]
    (0.01, 2.0)
    """
    c = D272[grain_key(name)]
    if c.velocity_range_m_s is not None:
        return tuple(c.velocity_range_m_s), f"{c.edition}'s range for {grain_key(name)}"
    return HUKILL_IVES_RANGE_M_S, ("the Hukill-Ives form's stated range (thesis 2.3.2); the "
                                   "standard's own range for this grain is not sourced here")


def grains_with_d272() -> list[str]:
    """The grains whose D272 constants have a source here."""
    return [k for k, v in D272.items() if v.a_pa_s2_m3 is not None]


def grain_key(name: str) -> str:
    """Library name of a grain: any case, spaces or hyphens for underscores, aliases
    (:data:`GRAIN_ALIASES`) accepted; ValueError listing the known grains.

    >>> grain_key("Shelled corn"), grain_key("soybeans"), grain_key(" rough-rice ")
    ('shelled_corn', 'soybean', 'rough_rice')
    """
    text = "_".join(str(name).strip().lower().replace("-", " ").split())
    key = GRAIN_ALIASES.get(text, text)
    if key not in D272:
        raise ValueError(f"unknown grain {name!r}; known grains: {', '.join(D272)}")
    return key


def d272_constants(name: str) -> tuple[float, float]:
    """(a Pa s²/m³, b s/m) of a grain (names as in :data:`D272` or :data:`GRAIN_ALIASES`).

    ValueError for an unknown grain (listing the known ones) or one whose constants no source
    here gives (saying so).

    >>> d272_constants("soybeans")
    (10200.0, 16.0)
    """
    try:
        key = grain_key(name)
    except ValueError:
        raise ValueError(f"unknown grain {name!r}; known grains: {', '.join(D272)} (with D272 "
                         f"constants: {', '.join(grains_with_d272())})") from None
    c = D272[key]
    if c.a_pa_s2_m3 is None:
        raise ValueError(f"no sourced ASABE D272 constants for {key} (docs/grain-library.md); "
                         f"grains with constants: {', '.join(grains_with_d272())}")
    return float(c.a_pa_s2_m3), float(c.b_s_m)


def d272_line(grain: str | None) -> tuple[tuple[float, float] | None, str]:
    """The ASABE D272 line a bed of ``grain`` is compared with, as every command prints it:
    ((a Pa s²/m³, b s/m), its label) or, for a grain that is unknown (None) or has no sourced
    constants, (None, the sentence saying why there is no line).

    >>> d272_line("soybean")
    ((10200.0, 16.0), 'ASABE D272 (soybeans)')
    >>> d272_line(None)
    (None, "no ASABE D272 line: the bed's grain is unknown (give --grain)")
    """
    if grain is None:
        return None, "no ASABE D272 line: the bed's grain is unknown (give --grain)"
    key = grain_key(grain)
    c = D272[key]
    if c.a_pa_s2_m3 is None:
        return None, f"no ASABE D272 line: no sourced constants for {key}"
    name = "soybeans" if key == "soybean" else key.replace("_", " ")
    return (float(c.a_pa_s2_m3), float(c.b_s_m)), f"ASABE D272 ({name})"


@dataclass(frozen=True)
class BedProperties:
    r"""The kernel density and the measured loose-fill bulk porosity the report needs.

    Copies of ``dem.grains`` (network may not import dem; ``tests/test_grain_library.py``
    checks that the two agree, value and source). ``None``: no source found (see dem.grains).
    Bulk density of a bed: :math:`\rho_b = \rho_p (1 - \varepsilon)`, kg/m^3.
    """

    particle_density_kg_m3: float | None
    particle_density_source: str
    #: measured loose-fill bulk porosity (low, high)
    bulk_porosity: tuple[float, float] | None
    bulk_porosity_source: str

    @property
    def loose_fill_porosity(self) -> float | None:
        """The middle of the measured range (the report's default porosity), or None.

        >>> BED["soybean"].loose_fill_porosity
        0.40985
        """
        if self.bulk_porosity is None:
            return None
        return round(0.5 * (self.bulk_porosity[0] + self.bulk_porosity[1]), 10)


_WANDKAR = "Wandkar, Ukey & Pawar 2012, Determination of physical properties of soybean"
_W03 = "Moisture-dependent physical properties of wheat, Int. Agrophys. 2003"
_RAMAJ = "Ramaj, Schock, Karaj & Mueller 2022, Influence of self-compaction"
_DARFOUR = "Darfour, Ayeh, Odoi, Mills & Odoi 2022, Physical characteristics of maize"
_SORGHUM = "Effect of moisture content on physical and aerodynamic properties of sorghum"
_NONE = "not found (dem.grains)"

BED: dict[str, BedProperties] = {
    "soybean": BedProperties(1285.0, "thesis Table 3.1 (seed/thesis.txt; PFC parameters "
                             "reported by Liu et al. 2008a; density and porosity from Milani",
                             (0.4007, 0.419), _WANDKAR + " (40.07-41.9 % over 7.37-15.80 % d.b.)"),
    "wheat": BedProperties(1240.0, _W03 + " (dry end of 1240-847.2 kg/m^3)", (0.391, 0.413),
                           _RAMAJ + " (in-bin, 1 h after filling, at 3.4 m and 1.0 m)"),
    "shelled_corn": BedProperties(1250.0, _DARFOUR, (0.4032, 0.4324), _DARFOUR),
    "barley": BedProperties(1099.65, "barley varieties Sahra and Valfajr vs moisture 10.12-42.17 "
                            "% w.b., J. Agric. Sci. Technol. (Gorgan Univ.) (Sahra, 10.12 % w.b.)",
                            (0.385, 0.4834), "low: Ozturk & Esen 2008, Physical and mechanical "
                            "properties of barley; high: Sahra, J. Agric. Sci. Technol."),
    "rough_rice": BedProperties(None, _NONE, None, _NONE),
    "canola": BedProperties(None, _NONE, None, _NONE),
    "sorghum": BedProperties(1257.33, _SORGHUM, (0.3515, 0.3675), _SORGHUM),
}


def template_grain(path) -> tuple[str | None, str | None]:
    """(grain, record) of the packing at ``path``: ``record`` is the ``template`` its companion
    JSON (same stem, ``.json``) names, None when there is none; ``grain`` is that record as a
    grain of the library (:func:`network._grains.grain_key`), else the grain a bundled bed is
    of (``network/data/<grain>_default.csv``, ``<grain>_grains.csv``), else None."""
    path = Path(path)
    record = None
    try:
        meta = json.loads(path.with_suffix(".json").read_text())
    except (OSError, ValueError):
        meta = None
    if isinstance(meta, dict) and isinstance(meta.get("template"), str):
        record = meta["template"]
        try:
            return grain_key(record), record
        except ValueError:
            return None, record
    data = _DATA_DIR.resolve()
    stem = path.resolve().stem
    for tail in ("_default", "_grains"):
        if path.resolve().parent == data and stem.endswith(tail) and stem[:-len(tail)] in D272:
            return stem[: -len(tail)], None
    return None, None


def packing_grain(path, given=None, *, default=None, option: str = "--grain") -> str | None:
    """The grain a packing is of, for the comparisons with D272 and the grain's data.

    ``given`` (the ``--grain`` option, None when not given) must agree with the bed's own
    grain (:func:`template_grain`): ValueError naming both when it does not. A bed without a
    template record is taken to be ``given`` (or ``default``) with one logged warning (a
    command's ``warning:`` line); with
    neither, None (the grain is unknown: no D272 line).
    """
    own, record = template_grain(path)
    key = None if given is None else grain_key(given)
    if key is not None and own is not None and key != own:
        raise ValueError(f"{option} {given}: {path} is a bed of {own} (its companion JSON's "
                         f"grain template); give {option} {own}, or a packing of {key}")
    if own is not None:
        return own
    key = key if key is not None else default
    if key is not None:
        what = (f"names the template {record!r}, not a grain of the library" if record
                else "has no grain template record")
        src = f"as {option} says" if given is not None else f"the default {option}"
        log.warning("%s %s: taken to be %s (%s); its D272 line and grain data are %s's", path,
                    what, key, src, key)
    return key


#: standard gravity, m/s²
G_M_S2 = 9.80665

#: Janssen's inputs (lateral pressure ratio K, bulk-on-smooth-steel wall friction mu_w): copies of
#: dem.grains' lateral_pressure_ratio and wall_friction_steel (EN 1991-4:2006 Annex E Table E.1;
#: canola: Jaky's K from its angle of internal friction), checked against it by the tests
JANSSEN = {
    "soybean": (0.63, 0.38),
    "wheat": (0.54, 0.38),
    "shelled_corn": (0.53, 0.36),
    "barley": (0.59, 0.33),
    "canola": (1.0 - math.sin(math.radians(23.91)), 0.301),
}


def janssen_stress(depth_m, *, bulk_density_kg_m3, diameter_m, wall_friction, lateral_ratio):
    r"""Janssen's vertical stress, Pa, at depth h below the surface of a round bin:

    .. math:: \sigma_v(h) = \frac{\rho_b g R_h}{\mu_w K}\big(1 - e^{-\mu_w K h/R_h}\big),
              \qquad R_h = B/4,

    μ_w the grain-wall friction coefficient, K the lateral-to-vertical stress ratio.

    >>> s = janssen_stress(1e-6, bulk_density_kg_m3=750.0, diameter_m=8.0, wall_friction=0.4,
    ...                    lateral_ratio=0.5)
    >>> round(float(s / (750.0 * G_M_S2 * 1e-6)), 6)   # hydrostatic near the surface
    1.0
    """
    rh = diameter_m / 4.0
    c = wall_friction * lateral_ratio / rh
    h = np.asarray(depth_m, dtype=float)
    return bulk_density_kg_m3 * G_M_S2 / c * -np.expm1(-c * h)
