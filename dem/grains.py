r"""The grain library: measured kernel and bed properties of the crops grainflow packs, with sources.

Every number is a :class:`Sourced` value: the value (a float, a ``(low, high)`` range or a
``(length, width, thickness)`` triple), the source it was read from (paper or standard, the
table/abstract, and the page address where it was found), and a note. A value no source gave is
``None`` with a note saying so; nothing here is estimated, interpolated or filled from memory.

Method. Sources were found with full-text search of stored public pages (journal abstracts and
landing pages); the address recorded is the one the search returned. Where a paper reports a
moisture series, the value kept is the low-moisture end (storage-dry grain, the condition of the
ASABE D272 airflow data) and the note gives the series. Where sources disagree the choice and the
reason are in the note and in ``docs/grain-library.md``. Kernel axes are length x width x
thickness in mm; densities kg/m^3; porosity a fraction; friction and restitution dimensionless.
``friction_pp``/``restitution_pp``/``rolling_friction_pp`` are grain-grain contacts, ``*_pw``
grain-wall (the wall material is named in the note). ``rolling_friction_*`` is the dimensionless
coefficient of rolling friction of a DEM calibration (the torque model it belongs to is in
``docs/dem-fill.md``, section Rolling friction). The D272 airflow constants live in ``network/_grains.py``
(DESIGN: network owns the empirical equations), under the same grain names.

Bin loads. The vertical stress at depth z of a round bin of diameter D (Janssen):

.. math:: \sigma_v(z) = \frac{\rho_b g D}{4 \mu_w K}\left(1 - e^{-4 \mu_w K z / D}\right)

takes ``wall_friction_steel`` (mu_w: the bulk sliding on a smooth steel wall, a property of
the bulk against a wall surface) and ``lateral_pressure_ratio`` (K = sigma_h / sigma_v); where
no measured K was found but ``internal_friction_deg`` (phi) was, K is Jaky's 1 - sin(phi) and
the note says so. mu_w is not the DEM's grain-wall contact friction ``friction_pw``: the two
are the same number only where one measurement (a grain sliding on a steel sheet) is the
source of both, and the notes say which. ``bulk_unit_weight_kn_m3`` is EN 1991-4's design
range of the bulk unit weight (rho_b g), ``bulk_density_kg_m3`` a measured loose fill.

>>> grain("soybean").particle_density_kg_m3.value
1285.0
>>> grain("oats")
Traceback (most recent call last):
...
ValueError: unknown grain 'oats'; known grains: barley, canola, rough_rice, shelled_corn, sorghum, soybean, wheat
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Sourced", "Grain", "GRAINS", "grain", "GRAIN_FIELDS"]


@dataclass(frozen=True)
class Sourced:
    """One library value with the source it was read from (``value=None``: not found)."""

    value: float | tuple[float, ...] | None
    source: str
    note: str = ""

    def __post_init__(self):
        if self.value is None and not self.note:
            raise ValueError(f"a missing value needs a note saying so (source {self.source!r})")


#: what was searched for a coefficient of rolling friction (pages corpus, by crop)
_ROLL_SEARCH = ("DEM calibration abstracts of this crop with rolling friction (pages corpus: "
                "'<crop> DEM calibration rolling friction coefficient angle of repose'): none gave a value")


def _missing(what: str, searched: str) -> Sourced:
    return Sourced(None, "not found", f"no source found for {what}; searched: {searched}")


@dataclass(frozen=True)
class Grain:
    """Kernel, bed and contact properties of one crop; every field a :class:`Sourced`."""

    name: str
    axes_mm: Sourced                #: (length, width, thickness), mm
    axes_sd_mm: Sourced             #: standard deviations of the three axes, mm
    particle_density_kg_m3: Sourced  #: true (kernel) density
    bulk_porosity: Sourced          #: measured loose-fill bulk porosity (low, high)
    friction_pp: Sourced            #: grain-grain sliding friction coefficient
    friction_pw: Sourced            #: grain-wall contact friction of the DEM walls (not Janssen's mu_w)
    restitution_pp: Sourced         #: grain-grain coefficient of restitution
    restitution_pw: Sourced         #: grain-wall coefficient of restitution
    #: bulk lateral pressure ratio K = sigma_h / sigma_v of Janssen's equation (module notes);
    #: where no measured K was found but an angle of internal friction was, Jaky's K = 1 - sin(phi)
    lateral_pressure_ratio: Sourced = Sourced(None, "not found", "no source found for a lateral pressure "
                                              "ratio nor an angle of internal friction to take Jaky's K from")
    #: angle of internal friction of the bulk, degrees
    internal_friction_deg: Sourced = Sourced(None, "not found", "no source found for an angle of internal "
                                             "friction; searched: EN 1991-4 Table E.1 (four grains only) and "
                                             "physical-property abstracts of this crop (pages corpus)")
    #: Janssen's wall friction coefficient mu_w of the bulk against a smooth steel wall (module notes)
    wall_friction_steel: Sourced = Sourced(None, "not found", "no source found for a bulk-on-steel wall "
                                           "friction coefficient")
    #: Janssen's mu_w against a corrugated steel wall
    wall_friction_corrugated: Sourced = Sourced(None, "not found", "no source found for a corrugated-wall "
                                                "friction coefficient: EN 1991-4 Table E.1 (as found) "
                                                "tabulates wall categories D1-D3 only, and no ASAE EP433 "
                                                "table of coefficients was readable")
    #: bulk unit weight (lower, upper) of silo design, kN/m^3 (EN 1991-4 gamma_l, gamma_u)
    bulk_unit_weight_kn_m3: Sourced = Sourced(None, "not found", "not in EN 1991-4 Table E.1 (as found): "
                                              "the crop has no row there")
    #: measured loose-fill bulk density (low, high) over the source's moisture series, kg/m^3
    bulk_density_kg_m3: Sourced = Sourced(None, "not found", "the abstracts found for this crop give no "
                                          "bulk density")
    #: grain-grain coefficient of rolling friction of a DEM calibration (mu_r of the rolling torque
    #: mu_r F_n R, docs/dem-fill.md); not found: the DEM runs without rolling friction
    rolling_friction_pp: Sourced = Sourced(None, "not found", "no source found for a grain-grain "
                                           "coefficient of rolling friction; searched: " + _ROLL_SEARCH)
    #: grain-wall coefficient of rolling friction of the same calibration (wall material in the note)
    rolling_friction_pw: Sourced = Sourced(None, "not found", "no source found for a grain-wall "
                                           "coefficient of rolling friction; searched: " + _ROLL_SEARCH)


#: the Sourced fields of :class:`Grain`, in order
GRAIN_FIELDS = ("axes_mm", "axes_sd_mm", "particle_density_kg_m3", "bulk_porosity",
                "friction_pp", "friction_pw", "restitution_pp", "restitution_pw",
                "lateral_pressure_ratio", "internal_friction_deg", "wall_friction_steel",
                "wall_friction_corrugated", "bulk_unit_weight_kn_m3", "bulk_density_kg_m3",
                "rolling_friction_pp", "rolling_friction_pw")

_SD_SEARCH = "the abstracts found report means/ranges only, no standard deviations"
_THESIS = ("thesis Table 3.1 (seed/thesis.txt; PFC parameters reported by Liu et al. 2008a; "
           "density and porosity from Milani et al. 2000)")
_KIBAR = ("Kibar & Ozturk 2008, Physical and mechanical properties of soybean, Int. Agrophys. "
          "22(3):239-244, abstract; http://www.international-agrophysics.org/"
          "Physical-and-mechanical-properties-of-soybean,106500,0,2.html")
_WANDKAR = ("Wandkar, Ukey & Pawar 2012, Determination of physical properties of soybean at "
            "different moisture levels, Agric Eng Int: CIGR Journal 14(2):138-142, abstract; "
            "https://pt.scribd.com/document/241390185/1616-pdf")
_BOAC = ("Boac, Casada, Maghirang & Harner 2010, Material and interaction properties of selected "
         "grains and oilseeds for modeling discrete particles, Trans. ASABE (2010), abstract "
         "(best single-sphere soybean DEM model); https://krex.k-state.edu/signposting/describedby/"
         "84675692-7dc8-46c6-80c9-f3136172661f")
_WHEAT_PROPS = ("Moisture-dependent physical properties of wheat, Int. Agrophys. 2003, 17(4):"
                "207-211 (Univ. of Tehran), abstract; http://www.international-agrophysics.org/"
                "Moisture-dependent-physical-properties-of-wheat,106749,0,2.html")
_WHEAT_DEM = ("Calibration of contact parameters between wheat and key components of grain "
              "leveling robots based on discrete element method, INMATEH 78(1) 2026, "
              "doi:10.35633/inmateh-78-73, abstract (Wan Ken Mai 22 wheat); https://inmateh.eu/"
              "volumes/volume-78--no-1--2026/calibration-of-contact-parameters-between-wheat-and-"
              "key-components-of-grain-leveling-robots-base/")
_WHEAT_RAMAJ = ("Ramaj, Schock, Karaj & Mueller 2022, Influence of self-compaction on the airflow "
                "resistance of aerated wheat bulks, Appl. Sci. 12(17):8909, abstract; "
                "https://ouci.dntb.gov.ua/works/7BABw8B9 (doi:10.3390/app12178909)")
_CORN_QPM = ("physical properties of HQPM 5 quality protein maize vs moisture (9-25 % w.b.), "
             "abstract; https://katalog.lib.cas.cz/KNAV/EdsRecord/edsair,edsair.doi.dedup....."
             "2effc5a48cff87dba17832cb4c893982")
_CORN_DARFOUR = ("Darfour, Ayeh, Odoi, Mills & Odoi 2022, Physical characteristics of maize grain "
                 "as influenced by varietal and moisture differences, Int. J. Food Properties, "
                 "doi:10.1080/10942912.2022.2077756, abstract; "
                 "https://bohrium.dp.tech/paper/arxiv/817363054650982401")
_CORN_DEM = ("Study on the contact parameter calibration of the maize kernel polyhedral discrete "
             "element model, Agriculture (MDPI), Sep 2024, abstract; https://doaj.org/"
             "cookie_consent?continue=%2Farticle%2F60ec5dd5f18a46b5848b620b933fdfde")
_BARLEY_TAV = ("Tavakoli, Tavakoli, Rajabipour, Ahmadi & Gharib-Zahedi 2009, Moisture-dependent "
               "physical properties of barley grains, Int J Agric & Biol Eng 2(4):84-91, abstract; "
               "https://ijabe.org/index.php/ijabe/article/view/161")
_BARLEY_JAST = ("barley varieties Sahra and Valfajr vs moisture 10.12-42.17 % w.b., J. Agric. Sci. "
                "Technol. (Gorgan Univ.), abstract; http://jast.modares.ac.ir/article-23-10966-en.html")
_BARLEY_OE = ("Ozturk & Esen 2008, Physical and mechanical properties of barley, Agricultura "
              "Tropica et Subtropica 41(3), abstract; https://it.scribd.com/document/253876858/Barley")
_RICE = ("Zareiforoush, Komarizadeh & Alizadeh 2009, Effect of moisture content on some physical "
         "properties of paddy grains, Res. J. Appl. Sci. Eng. Technol. 1(3):132-139, abstract "
         "(cultivar Alikazemi); https://studylib.net/doc/13289394/")
_CANOLA = ("Razavi, Yeganehzad et al. 2009, Moisture dependent physical properties of canola "
           "seeds, J. Agric. Sci. Technol. 11(3):309-322, abstract; "
           "https://profdoc.um.ac.ir/paper-abstract-1011501.html")
_SORGHUM = ("Effect of moisture content on physical and aerodynamic properties of sorghum, Journal "
            "of Medical and Bioengineering 2014, abstract (9.06-29.15 % w.b.); https://mdsite.deno."
            "dev/https://www.academia.edu/106744912/Effect%5Fof%5FMoisture%5FContent%5Fon%5F"
            "Physical%5Fand%5FAerodynamic%5FProperties%5Fof%5FSorghum")
_EN1991_WHEAT = ("EN 1991-4:2006 (Eurocode 1, Actions on silos and tanks) Annex E Table E.1, wheat row "
                 "(mean values), as tabulated in Studia Geotechnica et Mechanica 2018, "
                 "doi:10.2478/sgem-2018-0043; https://reference-global.com/article/10.2478/sgem-2018-0043")
_DEM_SEARCH = "DEM calibration abstracts (pages corpus) for this crop gave no value"
_MAIZE_ROLL = ("the polyhedral maize calibration (Agriculture, Sep 2024) has no rolling friction; 'DEM "
               "Parameter Calibration of Maize Seeds and the Effect of Rolling Friction', Processes "
               "9(6):914 (2021, https://mdpi.com/2227-9717/9/6/914) and 'Modeling of Typically Shaped Corn "
               "Seeds and Calibration of the Coefficient of Rolling Friction', Agronomy 13(6):1573 (2023, "
               "https://www.mdpi.com/2073-4395/13/6/1573): the stored abstracts give no value")
_EN_E1 = ("EN 1991-4:2006 (Eurocode 1, Actions on silos and tanks) Annex E Table E.1, mean values and "
          "conversion factors, as transcribed in the 'particles' sheet of @Silo/constants.xls of the sandTES "
          "Engineering Manual software (S. Thanheiser, TU Wien 2023, GPL-3.0, doi:10.5281/zenodo.10207330; "
          "GitHub sthanhe/engMan, commit cf17706); the sheet's columns are those of Table E.1 (gamma_l, "
          "gamma_u kN/m^3, phi_r, phi_im deg, a_phi, K_m, a_K, mu_m for wall categories D1, D2, D3, a_mu, "
          "C_op) and its wheat row equals the Annex E wheat row of the SGEM 2018 table in every value shown")
_RAPESEED = ("Models for predicting frictional properties of rapeseed (authors include Xue Chen), Int. "
             "Agrophys. 2019, 33(1):61-66, abstract; http://www.international-agrophysics.org/"
             "Models-for-predicting-frictional-properties-of-rapeseed,104377,0,2.html")


def _jaky(phi: Sourced, searched: str) -> Sourced:
    """Jaky's lateral pressure ratio K = 1 - sin(phi) from a sourced angle of internal friction."""
    return Sourced(1.0 - math.sin(math.radians(phi.value)), phi.source,
                   f"Jaky's K = 1 - sin(phi) with phi = {phi.value:g} deg (internal_friction_deg): no "
                   f"measured K found; searched: {searched}")


_NO_K = "EN 1991-4 Table E.1 (the crop has no row) and ASAE EP433 (its table was not readable)"
_CANOLA_PHI = Sourced(23.91, _RAPESEED, "rapeseed, direct shear: 23.91-34.99 deg, falling with normal "
                      "stress (25-100 kPa) and rising with moisture (6.58-11.16 % w.b.); the low end kept "
                      "(by the trends stated: dry seed, 100 kPa); stainless-steel friction 0.25-0.50")

GRAINS: dict[str, Grain] = {
    "soybean": Grain(
        "soybean",
        axes_mm=Sourced((7.24, 6.79, 5.78), _KIBAR,
                        "at 8 % moisture; 7.24-8.19 x 6.79-7.12 x 5.78-6.23 mm over 8-16 %; its "
                        "geometric mean 6.57 mm matches the thesis bed (5.5-7.5 mm, mean 6.5). "
                        "Wandkar 2012 gives 6.55 x 5.56 x 4.53 mm at 7.37 % d.b. (smaller beans)"),
        axes_sd_mm=_missing("the axis standard deviations", _SD_SEARCH),
        particle_density_kg_m3=Sourced(1285.0, _THESIS,
                                       "Wandkar 2012: 1250-1111 kg/m^3 (7.37-15.80 % d.b.); "
                                       "Kibar 2008: 983-906 kg/m^3 (rejected: below water, and "
                                       "its 21-23 % porosity is no loose fill)"),
        bulk_porosity=Sourced((0.4007, 0.419), _WANDKAR,
                              "40.07-41.9 % over 7.37-15.80 % d.b.; thesis Table 3.1: 0.408"),
        friction_pp=Sourced(0.47, _THESIS, "direct shear (Liu et al. 2008a); Boac 2010 DEM "
                            "calibration: 0.45"),
        friction_pw=Sourced(0.3, _THESIS, "against Plexiglass; Boac 2010: 0.30 against steel; "
                            "Kibar 2008: galvanized steel 0.164-0.286, wood 0.304-0.441"),
        restitution_pp=Sourced(0.6, _BOAC, "calibrated particle restitution of the best model"),
        restitution_pw=_missing("a soybean-wall restitution",
                                "Boac 2010 abstract gives one particle restitution only"),
        lateral_pressure_ratio=Sourced(0.63, _EN_E1, "'Soya beans' row: K_m 0.63, a_K 1.11"),
        internal_friction_deg=Sourced(25.0, _EN_E1, "'Soya beans' row: phi_im 25, a_phi 1.16 (angle of "
                                      "repose phi_r 29); Kibar 2008 measured 27.37-31.81 deg over 8-16 % "
                                      "moisture"),
        wall_friction_steel=Sourced(0.38, _EN_E1, "'Soya beans' row: mu_m on a D2 (smooth) wall; D1 0.24, "
                                    "D3 0.48, a_mu 1.16. Not the DEM's friction_pw (0.3 against "
                                    "Plexiglass, thesis); Kibar 2008 measured 0.164-0.286 on galvanized "
                                    "steel (single kernels on a sheet)"),
        bulk_unit_weight_kn_m3=Sourced((7.0, 8.0), _EN_E1, "'Soya beans' row: gamma_l 7.0, gamma_u 8.0"),
        bulk_density_kg_m3=Sourced((644.4, 749.1), _WANDKAR, "749.1 at 7.37 % d.b. to 644.4 at 15.80 %; "
                                   "Kibar 2008: 766.12-719.00 over 8-16 %"),
        rolling_friction_pp=Sourced(0.05, _BOAC, "particle coefficient of rolling friction of the best "
                                    "(single-sphere) soybean model, calibrated with its static friction "
                                    "0.45 (soybean-soybean), 0.30 (soybean-steel) and restitution 0.6 "
                                    "against bulk density and angle of repose"),
        rolling_friction_pw=_missing("a soybean-wall coefficient of rolling friction",
                                     "Boac 2010 abstract gives one particle coefficient of rolling "
                                     "friction (0.05), no soybean-steel value"),
    ),
    "wheat": Grain(
        "wheat",
        axes_mm=Sourced((7.08, 3.27, 2.98), _WHEAT_PROPS,
                        "mean of five varieties at 7.4 % d.b."),
        axes_sd_mm=_missing("the axis standard deviations", _SD_SEARCH),
        particle_density_kg_m3=Sourced(1240.0, _WHEAT_PROPS,
                                       "dry end of 1240-847.2 kg/m^3 over 0-22 % d.b. (rewetted "
                                       "wheat; the wet end is below water and not used)"),
        bulk_porosity=Sourced((0.391, 0.413), _WHEAT_RAMAJ,
                              "in-bin pore volume after 1 h at bulk depths 3.4 m and 1.0 m (cv. "
                              "Pionier, 0.123 kg/kg d.b.; 0.370 after 236 h of self-compaction); "
                              "the 2003 abstract gives no porosity value"),
        friction_pp=Sourced(0.53, _WHEAT_DEM, "wheat-wheat static friction; rolling 0.04"),
        friction_pw=Sourced(0.5023, _WHEAT_DEM, "wheat-steel static friction; rolling 0.111; "
                            "the 2003 wheat abstract: 0.279-0.450 over several surfaces"),
        restitution_pp=Sourced(0.52, _WHEAT_DEM, "wheat-wheat"),
        restitution_pw=Sourced(0.47, _WHEAT_DEM, "wheat-steel"),
        lateral_pressure_ratio=Sourced(0.54, _EN1991_WHEAT, "K_m, factor a_K 1.11 (0.49-0.60); the "
                                       "same row: unit weight 7.5-9.0 kN/m^3, wall friction 0.57 "
                                       "against concrete (D3); the Table E.1 transcription of "
                                       "sthanhe/engMan gives the same"),
        internal_friction_deg=Sourced(30.0, _EN1991_WHEAT, "phi_im, factor a_phi 1.12 "
                                      "(26.8-33.6 degrees); angle of repose phi_r 34 (engMan)"),
        wall_friction_steel=Sourced(0.38, _EN_E1, "'Wheat' row: mu_m on a D2 (smooth) wall; D1 0.24, D3 "
                                    "0.57 (= the SGEM 2018 row's concrete value), a_mu 1.16. Not the "
                                    "DEM's friction_pw (0.5023, a calibrated wheat-steel contact)"),
        bulk_unit_weight_kn_m3=Sourced((7.5, 9.0), _EN1991_WHEAT, "gamma lower 7.5, upper 9.0; the same "
                                       "in the engMan transcription"),
        bulk_density_kg_m3=Sourced((538.8, 740.0), _WHEAT_PROPS, "740 at 0 % to 538.8 kg/m^3 at 22 % d.b. "
                                   "(rewetted wheat); 1 - 740/1240 = 0.403, inside Ramaj's in-bin "
                                   "porosity range"),
        rolling_friction_pp=Sourced(0.04, _WHEAT_DEM, "wheat-wheat, calibrated with static friction 0.53 "
                                    "and restitution 0.52 against the angle of repose (simulated 26.83-"
                                    "27.57 deg, no significant difference from the measured); the "
                                    "abstract names neither the DEM software nor the rolling model"),
        rolling_friction_pw=Sourced(0.111, _WHEAT_DEM, "wheat-steel (static friction 0.5023, restitution "
                                    "0.47); wheat-rubber 0.137"),
    ),
    "shelled_corn": Grain(
        "shelled_corn",
        axes_mm=Sourced((9.2476, 7.8684, 3.8572), _CORN_QPM,
                        "at 9 % w.b. (one quality-protein variety); 9.25-10.20 x 7.87-8.26 x "
                        "3.86-4.71 mm over 9-25 % w.b.; the often quoted 12 x 8 x 4.5 mm has "
                        "no source found"),
        axes_sd_mm=_missing("the axis standard deviations", _SD_SEARCH),
        particle_density_kg_m3=Sourced(1250.0, _CORN_DARFOUR,
                                       "five Ghanaian varieties; constant with moisture"),
        bulk_porosity=Sourced((0.4032, 0.4324), _CORN_DARFOUR, "40.32-43.24 %"),
        friction_pp=Sourced(0.182, _CORN_DEM, "maize-maize static friction calibrated for a "
                            "polyhedral kernel model (a sphere or clump model needs its own)"),
        friction_pw=Sourced(0.545, _CORN_DEM, "maize-steel, measured on an inclined plane"),
        restitution_pp=Sourced(0.318, _CORN_DEM, "maize-maize, calibrated"),
        restitution_pw=Sourced(0.5, _CORN_DEM, "maize-steel, measured"),
        lateral_pressure_ratio=Sourced(0.53, _EN_E1, "'Maize' row: K_m 0.53, a_K 1.14"),
        internal_friction_deg=Sourced(31.0, _EN_E1, "'Maize' row: phi_im 31, a_phi 1.14 (angle of repose "
                                      "phi_r 35)"),
        wall_friction_steel=Sourced(0.36, _EN_E1, "'Maize' row: mu_m on a D2 (smooth) wall; D1 0.22, D3 "
                                    "0.53, a_mu 1.24. Not the DEM's friction_pw (0.545, single kernels "
                                    "on steel, inclined plane)"),
        bulk_unit_weight_kn_m3=Sourced((7.0, 8.0), _EN_E1, "'Maize' row: gamma_l 7.0, gamma_u 8.0"),
        bulk_density_kg_m3=Sourced((709.50, 746.00), _CORN_DARFOUR, "five varieties and the moisture "
                                   "series; with the true density 1250: porosity 0.4324-0.4032"),
        rolling_friction_pp=_missing("a maize grain-grain coefficient of rolling friction", _MAIZE_ROLL),
        rolling_friction_pw=_missing("a maize-wall coefficient of rolling friction", _MAIZE_ROLL),
    ),
    "barley": Grain(
        "barley",
        axes_mm=Sourced((8.91, 3.30, 2.58), _BARLEY_TAV,
                        "at 7.34 % d.b.; 8.91-9.64 x 3.30-3.74 x 2.58-2.98 mm to 21.58 % d.b."),
        axes_sd_mm=_missing("the axis standard deviations", _SD_SEARCH),
        particle_density_kg_m3=Sourced(1099.65, _BARLEY_JAST,
                                       "variety Sahra at 10.12 % w.b. (1099.65-1245.72 kg/m^3); "
                                       "Valfajr 1410.82-1230.61; Ozturk & Esen 2008: 984-1014 "
                                       "(rejected: about water, porosity inconsistent)"),
        bulk_porosity=Sourced((0.385, 0.4834), "low: " + _BARLEY_OE + "; high: " + _BARLEY_JAST,
                              "0.385 at 14 % d.b. (Ozturk & Esen); 0.4834 Sahra at 10.12 % w.b. "
                              "(to 0.5074 at 42 % w.b.; Valfajr 0.51-0.59)"),
        friction_pp=_missing("a barley grain-grain DEM friction", _DEM_SEARCH),
        friction_pw=Sourced(0.773, _BARLEY_OE, "galvanized steel, 0.773-0.920 over 10-14 % d.b. "
                            "(concrete 0.877-0.993, wood 0.560-0.713)"),
        restitution_pp=_missing("a barley restitution", _DEM_SEARCH),
        restitution_pw=_missing("a barley-wall restitution", _DEM_SEARCH),
        lateral_pressure_ratio=Sourced(0.59, _EN_E1, "'Barley' row: K_m 0.59, a_K 1.11"),
        internal_friction_deg=Sourced(28.0, _EN_E1, "'Barley' row: phi_im 28, a_phi 1.14 (angle of "
                                      "repose phi_r 31); Ozturk & Esen 2008: 22.50 deg at 14 % d.b."),
        wall_friction_steel=Sourced(0.33, _EN_E1, "'Barley' row: mu_m on a D2 (smooth) wall; D1 0.24, "
                                    "D3 0.48, a_mu 1.16. Not the DEM's friction_pw (0.773, Ozturk & "
                                    "Esen 2008, grain on galvanized steel)"),
        bulk_unit_weight_kn_m3=Sourced((7.0, 8.0), _EN_E1, "'Barley' row: gamma_l 7.0, gamma_u 8.0"),
        bulk_density_kg_m3=Sourced((623.00, 647.34), _BARLEY_OE, "647.34 at 10 % to 623.00 kg/m^3 at "
                                   "14 % d.b.; Sahra (J): 568.10-613.68"),
    ),
    "rough_rice": Grain(
        "rough_rice",
        axes_mm=Sourced((9.83, 2.65, 1.92), _RICE,
                        "cultivar Alikazemi at 8 % d.b. (to 10.05 x 2.76 x 2.01 at 21 %); "
                        "Hashemi 10.20 x 2.31 x 1.85"),
        axes_sd_mm=_missing("the axis standard deviations", _SD_SEARCH),
        particle_density_kg_m3=_missing("a rough-rice true density",
                                        "Ashtiani et al. 2010 and Zareiforoush 2009 abstracts "
                                        "give trends, not values"),
        bulk_porosity=_missing("a rough-rice loose-fill porosity",
                               "abstracts found give trends or one-variety values without the "
                               "fill method"),
        friction_pp=_missing("a rough-rice grain-grain DEM friction", _DEM_SEARCH),
        friction_pw=Sourced(0.4179, _RICE, "galvanized iron sheet, Alikazemi, 0.4179-0.4965 "
                            "over 8-21 % d.b. (glass 0.3168-0.4369, plywood 0.4394-0.5264)"),
        restitution_pp=_missing("a rough-rice restitution", _DEM_SEARCH),
        restitution_pw=_missing("a rough-rice-wall restitution", _DEM_SEARCH),
        internal_friction_deg=_missing("a rough-rice angle of internal friction",
                                       "EN 1991-4 Table E.1 (no rice row); a paddy abstract (FARO 44/57, "
                                       "Nigerian J. Trop. Eng. 2024) gives only 'at least 15.2 deg ... 35 "
                                       "deg also obtained', no value to use"),
        wall_friction_steel=Sourced(0.4179, _RICE, "the friction_pw value: the same measurement (grains "
                                    "on a galvanized iron sheet, Alikazemi at 8 % d.b.) is the source of "
                                    "both"),
    ),
    "canola": Grain(
        "canola",
        axes_mm=Sourced((1.925, 1.475, 1.475), _CANOLA,
                        "length 1.925-2.262 mm and diameter 1.475-1.911 mm over 5.27-23.69 % "
                        "w.b. (four varieties); width = thickness = the reported diameter"),
        axes_sd_mm=_missing("the axis standard deviations", _SD_SEARCH),
        particle_density_kg_m3=_missing("a canola true density",
                                        "Razavi 2009 abstract gives bulk density 666-739 kg/m^3 "
                                        "only"),
        bulk_porosity=_missing("a canola loose-fill porosity",
                               "Razavi 2009 abstract gives no porosity"),
        friction_pp=_missing("a canola grain-grain DEM friction",
                             "Cao et al. 2021 Processes 9:605 (rapeseed DEM) abstract gives no "
                             "values"),
        friction_pw=Sourced(0.301, _CANOLA, "galvanized iron sheet, 0.301-0.419 (rubber "
                            "0.372-0.460, glass 0.253-0.392)"),
        restitution_pp=_missing("a canola restitution", "Cao et al. 2021 abstract gives no values"),
        restitution_pw=_missing("a canola-wall restitution",
                                "Cao et al. 2021 abstract gives no values"),
        internal_friction_deg=_CANOLA_PHI,
        lateral_pressure_ratio=_jaky(_CANOLA_PHI, _NO_K),
        wall_friction_steel=Sourced(0.301, _CANOLA, "the friction_pw value: the same measurement (seeds "
                                    "on a galvanized iron sheet) is the source of both"),
        bulk_density_kg_m3=Sourced((666.06, 738.8), _CANOLA, "lowest (Hyola) and highest (SLM) of four "
                                   "varieties over 5.27-23.69 % w.b."),
    ),
    "sorghum": Grain(
        "sorghum",
        axes_mm=Sourced((4.45, 3.86, 2.49), _SORGHUM,
                        "at 9.06 % w.b.; 4.45-4.65 x 3.86-4.16 x 2.49-2.72 mm to 29.15 %"),
        axes_sd_mm=_missing("the axis standard deviations", _SD_SEARCH),
        particle_density_kg_m3=Sourced(1257.33, _SORGHUM, "1257.33-1126.72 kg/m^3 over the series"),
        bulk_porosity=Sourced((0.3515, 0.3675), _SORGHUM, "35.15-36.75 %"),
        friction_pp=_missing("a sorghum grain-grain DEM friction", _DEM_SEARCH),
        friction_pw=Sourced(0.32, _SORGHUM, "iron, 0.32-0.43 (acrylic 0.25-0.48, zinc 0.21-0.42)"),
        restitution_pp=_missing("a sorghum restitution", _DEM_SEARCH),
        restitution_pw=_missing("a sorghum-wall restitution", _DEM_SEARCH),
        wall_friction_steel=Sourced(0.32, _SORGHUM, "the friction_pw value: the same measurement (grains "
                                    "on an iron sheet; zinc 0.21-0.42) is the source of both"),
        bulk_density_kg_m3=Sourced((712.60, 815.40), _SORGHUM, "815.40 at 9.06 % to 712.60 kg/m^3 at "
                                   "29.15 % w.b."),
    ),
}


def grain(name: str) -> Grain:
    """The library entry of ``name`` (case and ``-``/space insensitive); ValueError lists the known.

    >>> grain("Shelled corn").name
    'shelled_corn'
    """
    key = str(name).strip().lower().replace("-", "_").replace(" ", "_")
    try:
        return GRAINS[key]
    except KeyError:
        raise ValueError(f"unknown grain {name!r}; known grains: "
                         f"{', '.join(sorted(GRAINS))}") from None
