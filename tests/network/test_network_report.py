"""network.report: fan/system intersection, porosity-band arithmetic, bad input, one full run."""

from __future__ import annotations

import json

import numpy as np
import pytest

from network.report.band import band_gradients, fit_log_slope, slope_at
from network.report.system import (bulk_density, curve_range, operating_point, read_fan,
                                   system_rows, velocity_from_airflow)
from network.report import main


def test_operating_point_exact_crossing():
    # system P = 1000 Q^2 sampled at Q = 0, 0.1, 0.2 (piecewise linear: 0, 10, 40 Pa);
    # fan P = 50 - 100 Q: on the segment 0.1-0.2 the system is 10 + 300 (Q - 0.1), so
    # 50 - 100 Q = 300 Q - 20 gives Q = 0.175, P = 32.5 exactly
    q, p = operating_point([0.0, 0.1, 0.2], [0.0, 10.0, 40.0], [0.0, 0.5], [50.0, 0.0])
    assert q == pytest.approx(0.175, rel=1e-12)
    assert p == pytest.approx(32.5, rel=1e-12)


def test_operating_point_at_a_shared_point():
    # the two curves meet exactly at a breakpoint of both
    assert operating_point([0, 1, 2], [0, 1, 4], [0, 1, 2], [2, 1, 0]) == (1.0, 1.0)


@pytest.mark.parametrize("fan_q, fan_p", [
    ([0.0, 0.2], [0.9, 0.1]),          # fan too weak: always below the system
    ([0.3, 0.6], [500.0, 400.0]),      # airflow ranges do not overlap
])
def test_no_operating_point(fan_q, fan_p):
    assert operating_point([0.01, 0.1, 0.2], [1.0, 10.0, 40.0], fan_q, fan_p) is None
    text = curve_range("fan", fan_q, fan_p)
    assert text.startswith("fan: airflow") and "Pa" in text


def test_band_slope_of_a_synthetic_exponential():
    # two families with different prefactors, one slope -11.5: the fit gives it back exactly
    e = np.array([0.38, 0.39, 0.40, 0.41, 0.42] * 2)
    fam = np.repeat([1, 2], 5)
    g = np.where(fam == 1, 3.0, 3.6) * np.exp(-11.5 * e)
    f = fit_log_slope(e, g, fam)
    assert f["slope"] == pytest.approx(-11.5, rel=1e-10)
    assert f["rms_residual"] < 1e-12
    np.testing.assert_allclose(np.exp(f["intercepts"]), [3.0, 3.6], rtol=1e-10)
    np.testing.assert_allclose(band_gradients(10.0, -11.5, (-0.02, 0.02)),
                               10.0 * np.exp([0.23, -0.23]), rtol=1e-12)
    assert slope_at(1e-4, [0.01, 1.0], [-12.0, -10.0]) == -12.0     # held beyond the ends


def test_band_fit_refuses_one_porosity():
    with pytest.raises(ValueError, match="two porosities"):
        fit_log_slope([0.4, 0.4], [1.0, 2.0])


def test_airflow_units_and_system_rows():
    rho_b = bulk_density(1285.0, 0.4)                                  # 771 kg/m^3
    u = velocity_from_airflow(1.0, "m3/min/t", depth_m=2.0, bulk_density_kg_m3=rho_b)
    assert u == pytest.approx(771.0 * 2.0 / 60_000.0, rel=1e-12)
    (row,) = system_rows([u], [100.0], depth_m=2.0, area_m2=3.0, bulk_density_kg_m3=rho_b)
    assert row["airflow_m3_min_t"] == pytest.approx(1.0, rel=1e-12)   # round trip
    assert row["static_pressure_pa"] == pytest.approx(200.0)
    assert row["airflow_m3_s"] == pytest.approx(3.0 * u)


def test_fan_file_bad_rows_are_named(tmp_path):
    f = tmp_path / "fan.csv"
    f.write_text("airflow_m3_s,static_pressure_pa\n0,500\n0.1,-20\n")
    with pytest.raises(ValueError, match="row 3: static_pressure_pa must be finite and >= 0"):
        read_fan(f)
    f.write_text("airflow_m3_s,static_pressure_pa\n0,500\nabc,20\n")
    with pytest.raises(ValueError, match="row 3: airflow_m3_s 'abc' is not a number"):
        read_fan(f)
    f.write_text("airflow_m3_s,static_pressure_pa\n0,2000\n1,1800\n1,1700\n2,1500\n")
    with pytest.raises(ValueError, match="airflow 1 m\\^3/s appears twice"):   # was IndexError
        read_fan(f)
    f.write_text("airflow_m3_s,static_pressure_pa\n0,2000\n1,1800,5\n2,1500\n")
    with pytest.raises(ValueError, match="row 3: 3 values, the header has 2"):
        read_fan(f)


def test_bad_input_exits_2(tmp_path, capsys):
    assert main(["--grain", "oats", "-q"]) == 2
    err = capsys.readouterr().err
    assert "unknown grain 'oats'" in err and "soybean" in err and "wheat" in err
    fan = tmp_path / "fan.csv"
    fan.write_text("airflow_m3_s,static_pressure_pa\n0,500\n-0.1,20\n")
    assert main(["--fan", str(fan), "--floor-area", "1", "-q"]) == 2
    assert "row 3" in capsys.readouterr().err
    # canola: no sourced kernel density (dem.grains / network._grains.BED)
    assert main(["--grain", "canola", "-q"]) == 2
    assert "no sourced kernel density for canola" in capsys.readouterr().err
    assert main(["--grain", "canola", "--particle-density", "1100", "-q"]) == 2
    assert "no bundled packing for canola" in capsys.readouterr().err
    for bad in ("1.5", "-0.1", "nan"):
        assert main(["--porosity", bad, "-q"]) == 2
        assert "--porosity must be in (0, 1)" in capsys.readouterr().err
    assert not list(tmp_path.glob("report_*"))


SOYBEAN_REACH = ("0.3490-0.4114 (the beds dem.pack --porosity made in the 0.05 x 0.05 x 0.05 m "
                 "box, seed 1, network/data/soybean_grains.json; a request within its 0.005 "
                 "tolerance is taken)")


@pytest.mark.parametrize("porosity, where", [("0.45", SOYBEAN_REACH), ("0.3", SOYBEAN_REACH)])
def test_porosity_outside_the_reachable_range_exits_2(tmp_path, capsys, monkeypatch, porosity,
                                                      where):
    """--move-along-band (no packing anew): the bundled soybean bed records what dem.pack
    --porosity reaches (0.3490-0.4114, taken within its 0.005 tolerance,
    network/data/soybean_grains.json): outside it exit 2 before any solve,
    naming the range; the measured top of soybean's loose fill, 0.419, is out of reach too."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "r.json"
    assert main(["--porosity", porosity, "--velocities", "0.01,0.1", "--no-band", "-q",
                 "--move-along-band", "--json", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert (f"porosity {porosity} is outside the range a packing of soybean reaches: {where}"
            in err[0]), err
    assert not out.exists() and not list(tmp_path.glob("report_*"))


def test_a_sphere_packing_moves_at_most_the_band_span(tmp_path, capsys, monkeypatch):
    """A packing without a recorded range (the 3000-sphere scene, own porosity 0.3940 in the
    inset window where its k is measured, 0.3990 over the whole sample): the report moves
    along the band at most 0.02 from the window's, so 0.43 is refused before any solve and
    before anything is written."""
    from network.report.porosity import DATA_DIR
    monkeypatch.chdir(tmp_path)
    assert main(["--packing", str(DATA_DIR / "soybean_default.csv"), "--porosity", "0.43",
                 "--velocities", "0.01,0.1", "--no-band", "-q"]) == 2
    err = capsys.readouterr().err
    assert "porosity 0.43 is outside the range a packing of soybean reaches: 0.3740-0.4140" in err
    assert not list(tmp_path.glob("report_*"))


@pytest.mark.slow
def test_end_to_end_bundled_scene(tmp_path, capsys, monkeypatch):
    """Default: the bundled 495-grain soybean bed (network/data/soybean_grains.csv, own
    porosity 0.4126 by network's Monte Carlo), reported at soybean's measured loose-fill 0.40985
    (middle of 0.4007-0.419, Wandkar 2012) along the computed band slope (about -11.5,
    docs/report.md): dP/L x exp(11.5 x 0.0028) = x 1.03; figures in report_soybean/."""
    monkeypatch.chdir(tmp_path)
    fan = tmp_path / "fan.csv"
    fan.write_text("airflow_m3_s,static_pressure_pa\n0,600\n0.05,500\n0.1,350\n0.15,100\n0.2,0\n")
    out = tmp_path / "r.json"
    code = main(["--grain", "soybean", "--velocities", "0.01,0.05,0.2", "--depth", "1",
                 "--floor-area", "1", "--fan", str(fan), "--json", str(out), "-q"])
    assert code == 0
    r = json.loads(out.read_text())
    for key in ("grain", "porosity", "porosity_source", "fits", "points", "band",
                "system_curve", "operating_point"):
        assert key in r
    assert r["grain"] == "soybean" and r["porosity"] == pytest.approx(0.40985, abs=1e-9)
    assert "loose-fill" in r["porosity_source"] and "Wandkar" in r["porosity_source"]
    assert r["porosity_packing"] == pytest.approx(0.4126, abs=0.002)
    assert r["n_grains"] == 495 and r["n_spheres"] == 2970
    assert "band's computed slope" in r["porosity_move"]
    for p in r["points"]:
        f = p["porosity_shift_factor"]
        assert f == pytest.approx(np.exp(p["band_slope"] * (r["porosity"] - r["porosity_packing"])))
        assert 1.01 < f < 1.06
        assert p["pressure_gradient_pa_per_m"] == pytest.approx(
            f * p["pressure_gradient_packing_pa_per_m"], rel=1e-12)
        assert 0 < p["porosity_shift_ln_stderr"] < 0.01
    assert sorted(x.name for x in (tmp_path / "report_soybean").iterdir()) == [
        "report_band.png", "report_curve.png", "report_system.png"]
    for k in ("permeability_m2", "forchheimer_beta_per_m", "d272_a", "d272_b", "ergun_A"):
        assert k in r["fits"]
    assert len(r["points"]) == 3
    for p in r["points"]:
        assert p["d272_pressure_gradient_pa_per_m"] > 0
        assert p["pressure_gradient_horizontal_pa_per_m"] > 0
        band = p["pressure_gradient_band_pa_per_m"]
        assert list(band) == ["-0.02", "-0.01", "+0.01", "+0.02"]
        assert band["-0.02"] > band["-0.01"] > p["pressure_gradient_pa_per_m"] > band["+0.02"]
    assert -20 < r["band"]["slopes"][0] < -6            # about -11 near 0.40
    op = r["operating_point"]
    assert op["found"] and 0.14 < op["airflow_m3_s"] < 0.2


@pytest.mark.slow
def test_done_when_wheat_from_the_bundled_bed(tmp_path, capsys, monkeypatch):
    """The wheat report, with 2 velocities: `--grain wheat --depth 3 --diameter 6` runs on
    the bundled wheat bed (network/data/wheat_grains.csv, made by dem.pack --porosity 0.402),
    reports for wheat's measured loose-fill 0.402 (middle of 0.391-0.413, Ramaj 2022), with
    the kernel density 1240 kg/m^3 (Int. Agrophys. 2003), and writes its figures."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "w.json"
    assert main(["--grain", "wheat", "--depth", "3", "--diameter", "6", "--velocities",
                 "0.01,0.1", "--json", str(out), "-q"]) == 0
    r = json.loads(out.read_text())
    assert r["grain"] == "wheat" and r["porosity"] == pytest.approx(0.402, abs=1e-12)
    assert "Ramaj" in r["porosity_source"] and r["n_spheres"] == 8 * r["n_grains"]
    assert abs(r["porosity_packing"] - 0.402) < 0.008           # dem.pack's 0.005 + MC noise
    assert r["bulk_density_kg_m3"] == pytest.approx(1240 * (1 - 0.402), rel=1e-12)
    assert r["bin"]["grain_mass_t"] == pytest.approx(
        1240 * 0.598 * np.pi * 9 * 3 / 1000, rel=1e-12)          # 62.9 t in a 6 m x 3 m bin
    # wheat's D272.3 pair from the secondary source (network._grains): 27000 Pa s^2/m^3, 8.77 s/m
    assert (r["d272"]["a_pa_s2_m3"], r["d272"]["b_s_m"]) == (27000.0, 8.77)
    assert "70324629401" in r["d272"]["source"] and "secondary source" in r["d272"]["note"]
    for p in r["points"]:
        u = p["velocity_m_s"]
        assert p["d272_pressure_gradient_pa_per_m"] == pytest.approx(
            27000.0 * u**2 / np.log1p(8.77 * u), rel=1e-12)
    lo, hi = r["porosity_reachable"]
    assert lo < 0.402 < hi
    # the band from wheat's own eight DEM beds (network/data/band_wheat.json), not sphere beds:
    # each point's band is g exp(S de) with S interpolated in ln U between the beds' velocities
    b = r["band"]
    assert b["packer"].startswith("dem.pack") and len(b["beds"]) == 8
    for p in r["points"]:
        S = np.interp(np.log(p["velocity_m_s"]), np.log(b["velocities_m_s"]), b["slopes"])
        band = p["pressure_gradient_band_pa_per_m"]
        assert [band[k] for k in ("-0.02", "-0.01", "+0.01", "+0.02")] == pytest.approx(
            [p["pressure_gradient_pa_per_m"] * np.exp(S * d) for d in (-0.02, -0.01, 0.01, 0.02)],
            rel=1e-9)
    # the figures, and beds/ with the cached solves of wheat's bin bed set (one per bed)
    assert sorted(x.name for x in (tmp_path / "report_wheat").iterdir()) == [
        "beds", "report_band.png", "report_curve.png", "report_system.png"]
    assert len(list((tmp_path / "report_wheat" / "beds" / "bin_solves").glob("*.json"))) == len(
        r["bin_beds"]["beds"]) == 3


@pytest.mark.slow
def test_axis_x_puts_the_horizontal_curve_into_the_system_curve(tmp_path, capsys, monkeypatch):
    """--axis x (cross-flow): the system curve, --airflow and the operating point use the
    horizontal pressure gradient, P = thickness x dP/L(x) at each velocity; the vertical curve
    is still reported."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "x.json"
    assert main(["--grain", "soybean", "--velocities", "0.01,0.1", "--no-band", "--no-figures",
                 "--axis", "X", "--depth", "2", "--floor-area", "3", "--airflow", "0.05", "m/s",
                 "--json", str(out), "--html", str(tmp_path / "x.html"), "-q"]) == 0
    r = json.loads(out.read_text())
    assert r["bin"]["flow_axis"] == "x"
    # the HTML says so too, and the airflow asked (it read as a vertical bin before)
    page = (tmp_path / "x.html").read_text()
    assert "horizontal airflow (x), thickness crossed 2 m, floor 3 m^2" in page
    assert "Airflow asked: " in page and "= 0.05 m/s" in page
    by_u = {p["velocity_m_s"]: p for p in r["points"]}
    assert sorted(by_u) == [0.01, 0.05, 0.1]
    for s in r["system_curve"]:
        p = by_u[s["velocity_m_s"]]
        assert s["static_pressure_pa"] == pytest.approx(
            2.0 * p["pressure_gradient_horizontal_pa_per_m"], rel=1e-12)
        assert s["airflow_m3_s"] == pytest.approx(3.0 * s["velocity_m_s"], rel=1e-12)
        assert p["pressure_gradient_horizontal_pa_per_m"] != p["pressure_gradient_pa_per_m"]
    assert r["airflow"]["static_pressure_pa"] == pytest.approx(
        2.0 * by_u[0.05]["pressure_gradient_horizontal_pa_per_m"], rel=1e-12)
    assert "horizontal airflow (x): thickness crossed 2 m" in capsys.readouterr().out


def test_measured_band_is_the_fit_of_the_grain_beds():
    """measured_band fits ln g = c + S e over the bundled wheat beds (one family): the slope and
    its standard error equal an independent numpy least-squares fit; grains without measured
    beds get None (the report then packs sphere beds)."""
    from network.report.band import GRAIN_BANDS, measured_band
    data = json.loads(GRAIN_BANDS["wheat"].read_text())
    b = measured_band("wheat")
    e = np.array([x["porosity"] for x in data["beds"]])
    for j in range(3):
        y = np.log([x["pressure_gradient_pa_per_m"][j] for x in data["beds"]])
        coef, cov = np.polyfit(e, y, 1, cov=True)
        assert b["slopes"][j] == pytest.approx(coef[0], rel=1e-9)
        assert b["slope_stderrs"][j] == pytest.approx(np.sqrt(cov[0, 0]), rel=1e-6)
    assert [round(x, 2) for x in b["slopes"]] == [-9.71, -9.17, -7.58]       # band_wheat.json's beds
    assert measured_band("soybean") is None and len(data["beds"]) == 8


@pytest.mark.slow
def test_results_outside_the_checked_range_are_warned(tmp_path, capsys, monkeypatch):
    # 3 m/s through 40 m of soybeans: Re_p 1.2e3 and 8.3e5 Pa, beyond the inertial law's
    # checked Re_p 200 and the constant-density air; the warnings name the system curve's drop
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "r.json"
    assert main(["--grain", "soybean", "--velocities", "0.01,3", "--depth", "40", "--no-band",
                 "--no-figures", "--json", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    r = json.loads(out.read_text())
    re_max = max(p["reynolds_particle"] for p in r["points"])
    drop = max(s["static_pressure_pa"] for s in r["system_curve"])
    assert f"warning: Re_p {re_max:.3g} is beyond the 200" in err and re_max > 1000
    assert f"warning: a pressure drop of {drop:.3g} Pa is" in err and drop > 1e5
    assert main(["--grain", "soybean", "--velocities", "0.01,0.1", "--depth", "3", "--no-band",
                 "--no-figures", "-q"]) == 0
    err = capsys.readouterr().err
    assert "beyond the 200" not in err and "of the atmosphere" not in err


#: the bundled wheat report (--depth 3 --diameter 6 --velocities 0.01,0.1 --airflow 0.1
#: m3/min/t): its printed table and key JSON numbers, pinned so that a change of the report's
#: code that is meant to leave its behaviour alone is seen to do so
WHEAT_PINNED_LINES = [
    "Stokes k at the packing's own porosity: vertical 1.3192e-08 m^2, horizontal 1.3535e-08 m^2 "
    "(horizontal/vertical resistance 0.975)",
    "0.003708  0.944      5.346      5.213       11.6      3.582      6.492      5.891      "
    "4.852      4.403",
    "    0.01   2.55      14.67      14.32      32.12      9.957      17.75      16.13      "
    "13.34      12.12",
    "     0.1   25.5      197.4      193.8      428.8        142      233.7      214.8      "
    "181.4      166.8",
    "fits vertical: k 1.3639e-08 m^2, beta 4641 1/m; D272-style a 1.253e+04 Pa s^2/m^3, b 8.87 "
    "s/m; Ergun A 224, B 2.068",
    "airflow 0.1 m^3/(min t) = 0.003708 m/s: 0.1048 m^3/s, static pressure 16.04 Pa",
]
WHEAT_PINNED = {
    "porosity_packing": 0.40002499999999996,
    "porosity_packing_std": 0.00109545652441117,
    "sauter_diameter_m": 0.004100923213830399,
    "k_z": 1.3192295431171851e-08,
    "k_x": 1.3534686639504036e-08,
    "fit_k": 1.3638961060713578e-08,
    "fit_beta": 4641.024366410594,
    "fit_k_x": 1.3988627532586215e-08,
    "g_z": [5.346281395016373, 14.669073847421432, 197.40821199622258],
    "g_x": [5.213107361223869, 14.319873118682493, 193.81440314229414],
    "ergun": [3.581632317414464, 9.956848680058203, 141.9916640299215],
    "band_minus_002": [6.491595276927865, 17.747331852583788, 233.69657622878566],
    "system_pa": [16.03884418504912, 44.0072215422643, 592.2246359886677],
}


@pytest.mark.slow
def test_bundled_wheat_report_numbers_are_pinned(tmp_path, capsys, monkeypatch):
    """The bundled wheat bed's report, printed lines to the last digit and JSON numbers to
    1e-10: a code move that keeps behaviour keeps these (the solve is deterministic)."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "w.json"
    assert main(["--grain", "wheat", "--depth", "3", "--diameter", "6", "--velocities",
                 "0.01,0.1", "--airflow", "0.1", "m3/min/t", "--no-figures", "--json", str(out),
                 "-q"]) == 0
    lines = capsys.readouterr().out.splitlines()
    for want in WHEAT_PINNED_LINES:
        assert want in lines, want
    r = json.loads(out.read_text())
    pts = r["points"]
    got = {
        "porosity_packing": r["porosity_packing"],
        "porosity_packing_std": r["porosity_packing_std"],
        "sauter_diameter_m": r["sauter_diameter_m"],
        "k_z": r["permeability_stokes_m2"]["z"], "k_x": r["permeability_stokes_m2"]["x"],
        "fit_k": r["fits"]["permeability_m2"], "fit_beta": r["fits"]["forchheimer_beta_per_m"],
        "fit_k_x": r["fits_horizontal"]["permeability_m2"],
        "g_z": [p["pressure_gradient_pa_per_m"] for p in pts],
        "g_x": [p["pressure_gradient_horizontal_pa_per_m"] for p in pts],
        "ergun": [p["ergun_pressure_gradient_pa_per_m"] for p in pts],
        "band_minus_002": [p["pressure_gradient_band_pa_per_m"]["-0.02"] for p in pts],
        "system_pa": [s["static_pressure_pa"] for s in r["system_curve"]],
    }
    for key, want in WHEAT_PINNED.items():
        assert got[key] == pytest.approx(want, rel=1e-10, abs=0), key


def test_report_options_are_keyword_only_frozen_and_checked():
    """ReportOptions: keyword-only, frozen, defaults resolved from the grain library (wheat's
    kernel density 1240 kg/m^3), and each impossible value refused naming its field."""
    import dataclasses

    from network.report import ReportOptions
    with pytest.raises(TypeError):
        ReportOptions("wheat")                                # keyword-only
    o = ReportOptions(grain="Wheat", velocities_m_s=[0.01, 0.1])
    assert o.grain == "wheat" and o.velocities_m_s == (0.01, 0.1)
    assert o.particle_density_kg_m3 == 1240.0 and "Agrophys" in o.particle_density_source
    assert o.depth_m == 0.25 and o.axis == "z" and o.band and o.fan is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.depth_m = 3.0
    for kw, msg in [({"depth_m": -1.0}, "depth_m must be a finite number > 0"),
                    ({"velocities_m_s": [0.01, float("nan")]}, "velocities_m_s must be"),
                    ({"porosity": 1.2}, r"porosity must be in \(0, 1\)"),
                    ({"axis": "y"}, "axis must be 'z' or 'x'"),
                    ({"airflow": (1.0, "cfs")}, "airflow unit 'cfs'"),
                    ({"diameter_m": 6.0, "floor_area_m2": 3.0}, "not both"),
                    ({"fan_airflow_m3_s": [0, 1], "fan_static_pressure_pa": [5, 1]},
                     "a fan curve needs the bin"),
                    ({"band_seed": -1}, "band_seed must be an integer >= 0"),
                    ({"grain": "oats"}, "unknown grain 'oats'")]:
        with pytest.raises(ValueError, match=msg):
            ReportOptions(**{"grain": "wheat", **kw})
    with pytest.raises(ValueError, match="no sourced kernel density for canola"):
        ReportOptions(grain="canola")


def test_airflow_units_any_case_per_m3_and_cfm_per_bushel(tmp_path, monkeypatch, capsys):
    """--airflow takes M/S, m3/min/m3 (U = q H / 60) and cfm/bu (1 ft^3/min per US bushel of
    0.03523907 m^3 = 0.3048^3 / 0.03523907 = 0.8035640 m^3/(min m^3)); an unknown unit names
    the accepted ones. The command gets past the unit to the next check (--fan without a bin)."""
    from network.report.system import M3_MIN_M3_PER_CFM_BU, airflow_unit
    assert airflow_unit("M/S") == "m/s" and airflow_unit("M3/MIN/M3") == "m3/min/m3"
    assert M3_MIN_M3_PER_CFM_BU == pytest.approx(0.028316846592 / 0.03523907, rel=1e-12)
    assert velocity_from_airflow(1.2, "m3/min/m3", depth_m=2.5, bulk_density_kg_m3=700.0) \
        == pytest.approx(1.2 * 2.5 / 60.0, rel=1e-12)
    u = velocity_from_airflow(0.1, "CFM/bu", depth_m=3.0, bulk_density_kg_m3=700.0)
    assert u == pytest.approx(0.1 * 0.8035639587537 * 3.0 / 60.0, rel=1e-12)
    # the round trip through the report's per-m^3 column: 60 U / H
    (row,) = system_rows([u], [10.0], depth_m=3.0, area_m2=2.0, bulk_density_kg_m3=700.0)
    assert row["airflow_m3_min_m3"] == pytest.approx(0.1 * M3_MIN_M3_PER_CFM_BU, rel=1e-12)
    monkeypatch.chdir(tmp_path)
    for unit in ("M/S", "m3/min/m3", "cfm/bu"):
        assert main(["--airflow", "0.1", unit, "--fan", "fan.csv", "-q"]) == 2
        assert "--fan needs the bin" in capsys.readouterr().err
    assert main(["--airflow", "0.1", "cfs", "-q"]) == 2
    assert "--airflow unit 'cfs': use one of m/s, m3/min/t, m3/min/m3, cfm/bu" \
        in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_no_band_run_removes_the_earlier_band_figure(tmp_path, capsys):
    """A --no-band run into a folder with an earlier run's report_band.png removes that file
    (the report names it) and nothing else; the curve figure draws D272 only over its stated
    0.01-2 m/s, which the printed report says."""
    (tmp_path / "report_band.png").write_bytes(b"old")
    (tmp_path / "notes.txt").write_text("mine")
    assert main(["--grain", "soybean", "--velocities", "0.005,0.05", "--no-band", "--plot-dir",
                 str(tmp_path), "-q"]) == 0
    out = capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "notes.txt", "report_curve.png", "report_system.png"]
    assert (tmp_path / "notes.txt").read_text() == "mine"
    assert f"removed {tmp_path / 'report_band.png'}" in out
    assert "D272 holds for 0.01-2 m/s (the Hukill-Ives form's stated range" in out


@pytest.mark.parametrize("rows", [
    "0,0\n0.1,50\n0.2,200\n",               # a system curve given as the fan
    "0,0\n50,0.1\n200,0.2\n",               # the same with its columns swapped
])
def test_a_fan_whose_pressure_rises_with_airflow_is_refused(rows, tmp_path, monkeypatch,
                                                            capsys):
    monkeypatch.chdir(tmp_path)
    fan = tmp_path / "fan.csv"
    fan.write_text("airflow_m3_s,static_pressure_pa\n" + rows)
    before = fan.read_bytes()
    out = tmp_path / "r.json"
    assert main(["--fan", str(fan), "--floor-area", "1", "--json", str(out), "-q"]) == 2
    cap = capsys.readouterr()
    err = cap.err.strip().splitlines()
    assert cap.out == "" and len(err) == 1 and err[0].startswith(f"error: --fan {fan}: ")
    assert "rises with airflow" in err[0] and "never falls" in err[0] and "system curve" in err[0]
    assert fan.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["fan.csv"]


def test_a_fan_with_a_stall_hump_or_swapped_looking_columns_is_warned(caplog):
    from network.report.system import check_fan_shape
    with caplog.at_level("WARNING"):
        check_fan_shape([0.0, 0.5, 1.0, 2.0], [400.0, 450.0, 300.0, 0.0])      # a stall hump
    assert len(caplog.records) == 1
    assert "rises with airflow between 0 and 0.5 m^3/s (a stall region?)" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):
        check_fan_shape([50.0, 60.0], [2.0, 1.0])
    assert len(caplog.records) == 1 and "are the columns swapped?" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):
        check_fan_shape([0.0, 0.1, 0.2], [600.0, 350.0, 0.0])                 # a fan: quiet
    assert caplog.records == []


@pytest.mark.slow
def test_unconverged_numbers_are_marked_and_left_out_of_the_fits(tmp_path, capsys,
                                                                  monkeypatch):
    """A solve that stops short at 3 m/s (forced here: the vertical and horizontal points at
    3 m/s report converged False): its row and the airflow line carry a visible mark, the JSON
    says converged: false, the system curve and the fits use the converged points only, the
    Re_p and atmosphere warnings still look at it, and the run exits 1."""
    import dataclasses

    from network.flow import fit_curve
    from network.report import build as report_build
    real = report_build.solve_network

    def stops_short_at_3(*args, **kwargs):
        res = real(*args, **kwargs)
        pts = [dataclasses.replace(pt, converged=False) if u == 3.0 else pt
               for u, pt in zip(res.inertial["velocities_m_s"], res.inertial["points"])]
        return dataclasses.replace(res, inertial=dict(res.inertial, points=pts))

    monkeypatch.setattr(report_build, "solve_network", stops_short_at_3)
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "r.json"
    assert main(["--velocities", "0.01,0.03,0.1", "--airflow", "3", "M/S", "--depth", "40",
                 "--no-band", "--no-figures", "--json", str(out), "-q"]) == 1
    cap = capsys.readouterr()
    r = json.loads(out.read_text())
    bad = [p for p in r["points"] if p["velocity_m_s"] == 3.0]
    assert len(bad) == 1 and bad[0]["converged"] is False
    assert bad[0]["converged_horizontal"] is False
    assert r["airflow"]["converged"] is False
    assert [s["velocity_m_s"] for s in r["system_curve"]] == [0.01, 0.03, 0.1]
    ok = [p for p in r["points"] if p["converged"]]
    want = fit_curve([p["velocity_m_s"] for p in ok],
                     [p["pressure_gradient_pa_per_m"] for p in ok],
                     viscosity_pa_s=r["viscosity_pa_s"], density_kg_m3=r["air_density_kg_m3"],
                     porosity=r["porosity"], diameter_m=r["sauter_diameter_m"])
    assert r["fits"]["permeability_m2"] == pytest.approx(want["permeability_m2"], rel=1e-12)
    rows = [line for line in cap.out.splitlines() if "NOT CONVERGED" in line]
    assert len(rows) == 2 and rows[0].strip().startswith("3 ") \
        and "NOT CONVERGED (z, x): not a result" in rows[0]
    assert rows[1].startswith("airflow ") and "static pressure" in rows[1]
    re_p = bad[0]["reynolds_particle"]
    assert f"warning: Re_p {re_p:.3g} is beyond the 200" in cap.err
    assert "of the atmosphere's" in cap.err
    assert "error: the nonlinear solve did not converge at U = [3.0] m/s" in cap.err
