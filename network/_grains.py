r"""ASABE D272 (Shedd / Hukill-Ives) airflow-resistance constants by grain: data only.

.. math:: \frac{\Delta P}{L} = \frac{a U^2}{\ln(1 + b U)}

with ΔP/L in Pa/m, U the superficial velocity in m/s, a in Pa·s²/m³ and b in m²·s/m³ (= s/m),
the form and units of ASAE/ASABE D272.3. The values are for a loose fill of clean, relatively dry
grain; D272.3's note (ASAE D272.3 MAR96, section 2, the one part of the standard found in a stored
copy: https://ro.scribd.com/document/458884232/droppressuregrains-pdf) says packing in a bin may
raise the resistance by up to 50 %, and grain in equilibrium with air above 85 % RH takes 80 % of
the pressure drop. Only constants read from a source are here; a grain whose constants were not
found has ``a = b = None`` and a note. Grain names are those of ``dem.grains.GRAINS``.

>>> c = D272["soybean"]
>>> round(0.25 * c.a_pa_s2_m3 * 0.013**2 / __import__("math").log1p(c.b_s_m * 0.013), 2)
2.28
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["D272Constants", "D272", "GRAIN_ALIASES", "d272_constants", "grains_with_d272"]


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

D272: dict[str, D272Constants] = {
    "soybean": D272Constants(
        1.02e4, 16.0, None, None, "ASABE D272.3 (ASABE 2011)",
        "thesis section 4.2.3 (seed/thesis.txt: 'For soybeans, the two constants were found to "
        "be a = 1.02e4 Pa s^2 m^-3 and b = 16.0 m^-1 s'), quoting ASABE Standards D272.3 (2011); "
        "its 2.28 Pa at 0.013 m/s over 0.25 m (Table 4.5) checks them",
        "secondary source (the standard's own table not seen); valid airflow range not found"),
    "wheat": D272Constants(None, None, None, None, "ASABE D272.3", "not found", _NOT_FOUND),
    "shelled_corn": D272Constants(None, None, None, None, "ASABE D272.3", "not found", _NOT_FOUND),
    "barley": D272Constants(None, None, None, None, "ASABE D272.3", "not found", _NOT_FOUND),
    "rough_rice": D272Constants(None, None, None, None, "ASABE D272.3", "not found", _NOT_FOUND),
    "canola": D272Constants(None, None, None, None, "ASABE D272.3", "not found", _NOT_FOUND),
    "sorghum": D272Constants(None, None, None, None, "ASABE D272.3", "not found", _NOT_FOUND),
}


#: Other names people use for the grains of :data:`D272`.
GRAIN_ALIASES = {"soybeans": "soybean", "corn": "shelled_corn", "maize": "shelled_corn",
                 "rice": "rough_rice", "paddy": "rough_rice", "rapeseed": "canola",
                 "milo": "sorghum"}


def grains_with_d272() -> list[str]:
    """The grains whose D272 constants have a source here."""
    return [k for k, v in D272.items() if v.a_pa_s2_m3 is not None]


def d272_constants(name: str) -> tuple[float, float]:
    """(a Pa s²/m³, b s/m) of a grain (names as in :data:`D272` or :data:`GRAIN_ALIASES`).

    ValueError for an unknown grain (listing the known ones) or one whose constants no source
    here gives (saying so).

    >>> d272_constants("soybeans")
    (10200.0, 16.0)
    """
    key = GRAIN_ALIASES.get(str(name).lower(), str(name).lower())
    if key not in D272:
        raise ValueError(f"unknown grain {name!r}; known grains: {', '.join(D272)} (with D272 "
                         f"constants: {', '.join(grains_with_d272())})")
    c = D272[key]
    if c.a_pa_s2_m3 is None:
        raise ValueError(f"no sourced ASABE D272 constants for {key} (docs/grain-library.md); "
                         f"grains with constants: {', '.join(grains_with_d272())}")
    return float(c.a_pa_s2_m3), float(c.b_s_m)
