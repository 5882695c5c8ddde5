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
    if g.bulk_porosity.value is not None:
        lo, hi = g.bulk_porosity.value
        assert lo <= hi


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
