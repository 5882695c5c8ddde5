"""The grain library: every value sourced or marked not found, every number
physically sensible, the D272 soybean check of the thesis, and one set of grain names."""

import math

import pytest

from dem.grains import GRAIN_FIELDS, GRAINS, Grain, Sourced, grain
from network._grains import D272, D272Constants

#: physically sensible bounds for these crops (kernel densities above water, loose-fill
#: porosities, friction and restitution coefficients, kernel axes from canola to corn)
BOUNDS = {
    "particle_density_kg_m3": (1000.0, 1500.0),
    "bulk_porosity": (0.3, 0.5),
    "friction_pp": (0.1, 1.0),
    "friction_pw": (0.1, 1.0),
    "restitution_pp": (0.1, 0.95),
    "restitution_pw": (0.1, 0.95),
    "axes_mm": (1.0, 15.0),
    "axes_sd_mm": (0.0, 3.0),
    "lateral_pressure_ratio": (0.2, 1.0),
    "internal_friction_deg": (15.0, 50.0),
    "wall_friction_steel": (0.1, 1.0),
    "wall_friction_corrugated": (0.1, 1.0),
    "bulk_unit_weight_kn_m3": (5.0, 10.0),
    "bulk_density_kg_m3": (500.0, 900.0),
    "rolling_friction_pp": (0.001, 0.5),
    "rolling_friction_pw": (0.001, 0.5),
}


@pytest.mark.parametrize("name", sorted(GRAINS))
def test_every_field_sourced_or_marked_not_found(name):
    g = GRAINS[name]
    assert isinstance(g, Grain) and g.name == name
    for field in GRAIN_FIELDS:
        v = getattr(g, field)
        assert isinstance(v, Sourced), field
        if v.value is None:
            assert "not found" in v.source or "no source" in v.note, (name, field)
            assert v.note
        else:
            assert len(v.source) > 20 and v.source != "not found", (name, field)


@pytest.mark.parametrize("name", sorted(GRAINS))
def test_numbers_positive_and_sensible(name):
    g = GRAINS[name]
    for field in GRAIN_FIELDS:
        v = getattr(g, field).value
        if v is None:
            continue
        lo, hi = BOUNDS[field]
        for x in (v if isinstance(v, tuple) else (v,)):
            assert math.isfinite(x) and x > 0 and lo <= x <= hi, (name, field, x)
    if g.axes_mm.value is not None:
        length, width, thickness = g.axes_mm.value
        assert length >= width >= thickness
    for field in ("bulk_porosity", "bulk_unit_weight_kn_m3", "bulk_density_kg_m3"):
        if getattr(g, field).value is not None:
            lo, hi = getattr(g, field).value
            assert lo <= hi, (name, field)


def test_frozen():
    with pytest.raises(Exception):
        GRAINS["soybean"].name = "x"


def test_missing_value_needs_a_note():
    with pytest.raises(ValueError, match="note"):
        Sourced(None, "somewhere")


def test_unknown_grain_lists_the_known_ones():
    with pytest.raises(ValueError) as e:
        grain("oats")
    for name in GRAINS:
        assert name in str(e.value)
    assert grain(" Shelled-Corn ") is GRAINS["shelled_corn"]


def test_soybean_is_the_thesis_bed():
    s = grain("soybean")
    assert s.particle_density_kg_m3.value == 1285.0
    lo, hi = s.bulk_porosity.value
    assert lo <= 0.408 <= hi
    assert s.friction_pp.value == 0.47 and s.friction_pw.value == 0.3


def test_same_grain_names():
    assert set(D272) == set(GRAINS)


@pytest.mark.parametrize("name", sorted(D272))
def test_d272_entries(name):
    c = D272[name]
    assert isinstance(c, D272Constants) and c.edition.startswith(("ASABE D272", "ASAE D272"))
    if c.a_pa_s2_m3 is None or c.b_s_m is None:
        assert c.a_pa_s2_m3 is None and c.b_s_m is None and "not found" in c.note
    else:
        assert c.a_pa_s2_m3 > 0 and c.b_s_m > 0 and "D272" in c.source
    for rng in (c.velocity_range_m_s, c.airflow_range_m3_min_m2):
        if rng is not None:
            assert 0 < rng[0] < rng[1]


def test_d272_soybean_gives_the_thesis_check():
    """Thesis 4.2.3 / Table 4.5: 2.28 Pa over 0.25 m at 0.013 m/s (and 5.18 Pa at 0.027 m/s)."""
    c = D272["soybean"]
    assert (c.a_pa_s2_m3, c.b_s_m) == (1.02e4, 16.0)

    def dp(u, depth):
        return depth * c.a_pa_s2_m3 * u**2 / math.log1p(c.b_s_m * u)

    assert dp(0.013, 0.25) == pytest.approx(2.28, abs=0.005)
    assert dp(0.027, 0.25) == pytest.approx(5.18, abs=0.005)


#: the D272.3 pairs of the secondary source (stored file id 70324629401, a
#: port of the fan-sizing spreadsheet Resistencia_Fluxo_de_Ar.xls), corn's confirmed by a second
#: (id 70970216257)
SECONDARY = {"wheat": (27000.0, 8.77, "Trigo"), "shelled_corn": (20700.0, 30.4, "Milho"),
             "sorghum": (21200.0, 8.06, "Sorgo"), "rough_rice": (25700.0, 13.2, "Arroz")}


@pytest.mark.parametrize("name", sorted(SECONDARY))
def test_d272_secondary_source_grains(name):
    a, b, word = SECONDARY[name]
    c = D272[name]
    assert (c.a_pa_s2_m3, c.b_s_m) == (a, b)
    assert "70324629401" in c.source and "Resistencia_Fluxo_de_Ar.xls" in c.source
    assert word in c.source and f"A: {a:.0f}, B: {b:g}" in c.source      # the quoted row
    assert "secondary source" in c.source and "secondary source" in c.note
    assert c.edition == "ASAE D272.3 (as quoted by a secondary source; edition not stated)"
    assert "not seen" in c.note and "no valid airflow range" in c.note
    assert c.velocity_range_m_s is None and c.airflow_range_m3_min_m2 is None


def test_d272_corn_confirmed_and_its_low_band_not_used():
    c = D272["shelled_corn"]
    assert "70970216257" in c.source and "SHEDD_A, SHEDD_B = 2.07e4, 30.4" in c.source
    assert "A: 9970, B: 8.55" in c.note and "not used" in c.note


def test_d272_rice_is_rough_rice_by_inference():
    assert "inference" in D272["rough_rice"].note and "Arroz" in D272["rough_rice"].note


def test_d272_canola_and_barley_stay_unsourced():
    from network._grains import d272_constants, grains_with_d272
    for name in ("canola", "barley"):
        c = D272[name]
        assert c.a_pa_s2_m3 is None and c.b_s_m is None and "not found" in c.note
        with pytest.raises(ValueError, match=f"no sourced ASABE D272 constants for {name}"):
            d272_constants(name)
    assert "PROVISÓRIOS" in D272["canola"].note and "not used" in D272["canola"].note
    assert grains_with_d272() == ["soybean", "wheat", "shelled_corn", "rough_rice", "sorghum"]
    assert d272_constants("corn") == (20700.0, 30.4) and d272_constants("rice") == (25700.0, 13.2)


def test_d272_soybean_agrees_with_the_empirical_module():
    from network.flow import ASABE_SOYBEAN_A, ASABE_SOYBEAN_B

    assert (ASABE_SOYBEAN_A, ASABE_SOYBEAN_B) == (D272["soybean"].a_pa_s2_m3,
                                                  D272["soybean"].b_s_m)


@pytest.mark.parametrize("name", sorted(GRAINS))
def test_network_bed_properties_agree_with_dem_grains(name):
    """network/_grains.py carries the kernel density and loose-fill porosity the report needs
    (network may not import dem): the same values as dem.grains, read from the same source."""
    from network._grains import BED
    b, g = BED[name], GRAINS[name]
    assert b.particle_density_kg_m3 == g.particle_density_kg_m3.value
    assert b.bulk_porosity == g.bulk_porosity.value
    for mine, theirs in ((b.particle_density_source, g.particle_density_kg_m3.source),
                         (b.bulk_porosity_source, g.bulk_porosity.source)):
        assert mine.split(" (")[0][:40] in theirs, (name, mine, theirs)
    if b.bulk_porosity is not None:
        lo, hi = b.bulk_porosity
        assert b.loose_fill_porosity == pytest.approx(0.5 * (lo + hi), abs=1e-12)
    assert set(BED) == set(D272) == set(GRAINS)


#: EN 1991-4 Table E.1 rows as the transcription (sthanhe/engMan @Silo/constants.xls, sheet
#: 'particles') gives them: gamma_l, gamma_u (kN/m^3), phi_im (deg), K_m, mu_m on walls D1, D2, D3
EN_E1 = {"soybean": ("Soya beans", 7.0, 8.0, 25.0, 0.63, 0.24, 0.38, 0.48),
         "wheat": ("Wheat", 7.5, 9.0, 30.0, 0.54, 0.24, 0.38, 0.57),
         "shelled_corn": ("Maize", 7.0, 8.0, 31.0, 0.53, 0.22, 0.36, 0.53),
         "barley": ("Barley", 7.0, 8.0, 28.0, 0.59, 0.24, 0.33, 0.48)}


@pytest.mark.parametrize("name", sorted(EN_E1))
def test_janssen_inputs_are_the_en_1991_4_table_e1_row(name):
    """K, phi, mu_w (D2, smooth wall; D1 and D3 in the note) and the unit weight of each grain
    that Table E.1 lists are its row; wheat's K, phi and unit weight come from the SGEM 2018 table
    of the same Annex, which agrees with the transcription."""
    row, gl, gu, phi, k, d1, d2, d3 = EN_E1[name]
    g = grain(name)
    assert g.lateral_pressure_ratio.value == k and g.internal_friction_deg.value == phi
    assert g.bulk_unit_weight_kn_m3.value == (gl, gu)
    mu = g.wall_friction_steel
    assert mu.value == d2 and "EN 1991-4" in mu.source and "engMan" in mu.source
    assert f"'{row}' row" in mu.note and f"D1 {d1:g}" in mu.note and f"D3 {d3:g}" in mu.note
    assert "D2 (smooth)" in mu.note and "Not the DEM's friction_pw" in mu.note
    assert mu.value != g.friction_pw.value and mu.source != g.friction_pw.source
    for field in ("lateral_pressure_ratio", "internal_friction_deg", "bulk_unit_weight_kn_m3"):
        assert "EN 1991-4" in getattr(g, field).source and "Jaky" not in getattr(g, field).note


def test_jaky_k_only_where_no_measured_k():
    """K = 1 - sin(phi) (Jaky) exactly where the library holds phi but no measured K, from the
    same source as phi, and the note says so; canola (rapeseed phi 23.91 deg) is the one grain."""
    jaky = {n for n, g in GRAINS.items() if g.lateral_pressure_ratio.value is not None
            and "Jaky" in g.lateral_pressure_ratio.note}
    assert jaky == {"canola"}
    for name in jaky:
        g = GRAINS[name]
        phi = g.internal_friction_deg
        assert g.lateral_pressure_ratio.value == pytest.approx(1 - math.sin(math.radians(phi.value)), abs=1e-15)
        assert g.lateral_pressure_ratio.source == phi.source
        assert f"phi = {phi.value:g} deg" in g.lateral_pressure_ratio.note
    assert GRAINS["canola"].internal_friction_deg.value == 23.91
    assert GRAINS["canola"].lateral_pressure_ratio.value == pytest.approx(0.594699, abs=1e-6)


def test_wall_friction_steel_is_friction_pw_only_where_one_measurement_gives_both():
    """mu_w (Janssen) and friction_pw (DEM contact) are one Sourced number only where a grain on a
    steel sheet is the source of both: rough rice 0.4179, canola 0.301, sorghum 0.32."""
    same = {n for n, g in GRAINS.items() if g.wall_friction_steel.value is not None
            and g.wall_friction_steel.source == g.friction_pw.source}
    assert same == {"rough_rice", "canola", "sorghum"}
    for name in same:
        g = GRAINS[name]
        assert g.wall_friction_steel.value == g.friction_pw.value
        assert "the friction_pw value" in g.wall_friction_steel.note
    assert {n: GRAINS[n].wall_friction_steel.value for n in same} == {
        "rough_rice": 0.4179, "canola": 0.301, "sorghum": 0.32}
    assert all(g.wall_friction_corrugated.value is None for g in GRAINS.values())


def test_measured_bulk_density_is_the_sources_numbers_and_agrees_with_their_porosity():
    """Loose-fill bulk densities as the abstracts give them; where one source gives true density,
    porosity and bulk density (corn: Darfour 2022; soybean: Wandkar 2012 at 7.37 % d.b., true
    density 1250; sorghum: 1257.33 and 1126.72 at the two ends), rho_bulk = rho_true (1 - porosity)
    to the sources' rounding (porosity to 0.01 %: 1e-4 of the bulk density)."""
    assert {n: g.bulk_density_kg_m3.value for n, g in GRAINS.items()} == {
        "soybean": (644.4, 749.1), "wheat": (538.8, 740.0), "shelled_corn": (709.50, 746.00),
        "barley": (623.00, 647.34), "rough_rice": None, "canola": (666.06, 738.8),
        "sorghum": (712.60, 815.40)}
    corn = GRAINS["shelled_corn"]
    lo, hi = corn.bulk_porosity.value
    assert corn.bulk_density_kg_m3.value == pytest.approx(
        (corn.particle_density_kg_m3.value * (1 - hi), corn.particle_density_kg_m3.value * (1 - lo)), rel=1e-4)
    assert GRAINS["soybean"].bulk_density_kg_m3.value[1] == pytest.approx(1250.0 * (1 - 0.4007), rel=1e-4)
    sorghum = GRAINS["sorghum"]
    assert sorghum.bulk_density_kg_m3.value == pytest.approx((1126.72 * (1 - 0.3675), 1257.33 * (1 - 0.3515)),
                                                             rel=1e-4)
    assert sorghum.bulk_porosity.value == (0.3515, 0.3675)


def test_dem_pack_takes_janssen_inputs_from_the_library():
    """dem.pack --depth takes mu_w = wall_friction_steel and the library's K for the five grains
    that have both, and refuses rough rice and sorghum (no K, no phi) with a message naming the
    grain."""
    from dem._pack_pour import _janssen_inputs
    for name in ("soybean", "wheat", "shelled_corn", "barley", "canola"):
        g = GRAINS[name]
        mu, k, src = _janssen_inputs(name)
        assert (mu, k) == (g.wall_friction_steel.value, g.lateral_pressure_ratio.value)
        assert src["wall_friction_source"] == g.wall_friction_steel.source
        assert src["lateral_pressure_ratio_source"] == g.lateral_pressure_ratio.source
    for name in ("rough_rice", "sorghum"):
        with pytest.raises(ValueError, match=f"no lateral pressure ratio K nor angle of internal friction for {name}"):
            _janssen_inputs(name)


def test_rolling_friction_is_the_calibrations_value_or_none_with_a_note():
    """Wheat: INMATEH 78(1) 2026 (0.04 wheat-wheat, 0.111 wheat-steel, the calibration of its
    friction 0.53 / 0.5023); soybean: Boac et al. 2010's single-sphere model (0.05, no wall value);
    every other grain None, with what was searched."""
    w, s = grain("wheat"), grain("soybean")
    assert w.rolling_friction_pp.value == 0.04 and w.rolling_friction_pw.value == 0.111
    assert w.rolling_friction_pp.source == w.friction_pp.source == w.rolling_friction_pw.source
    assert "inmateh-78-73" in w.rolling_friction_pp.source and "wheat-steel" in w.rolling_friction_pw.note
    assert s.rolling_friction_pp.value == 0.05 and "Boac" in s.rolling_friction_pp.source
    assert s.rolling_friction_pw.value is None and "0.05" in s.rolling_friction_pw.note
    for name in ("shelled_corn", "barley", "rough_rice", "canola", "sorghum"):
        for field in ("rolling_friction_pp", "rolling_friction_pw"):
            v = getattr(grain(name), field)
            assert v.value is None and v.source == "not found" and "searched" in v.note, (name, field)
    assert "Processes 9(6):914" in grain("shelled_corn").rolling_friction_pp.note
