"""network.report on the bin's beds: Janssen's stress with depth, the set's beds interpolated in
stress, the vertical resistance as layers in series, the solve cache, and what the report does
for a bin it cannot take."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from network.bin._material import JANSSEN, janssen_stress
from network.report import main
from network.report.binbeds import (BED_SET_STRESSES_PA, _TEMPLATE_VOLUME_M3, bed_set_files,
                                    bin_section, bin_velocities, interpolate_in_stress,
                                    layers_in_series, plan_bin_beds, set_box, solve_set)
from network.report.porosity import DATA_DIR

RHO_P = 1240.0


def _fake_set(folder: Path, grain: str, stresses, porosity=0.36):
    """A bed set's files (any CSV; the JSON records the lid stress and the porosity)."""
    folder.mkdir(parents=True, exist_ok=True)
    for s in stresses:
        p = folder / f"{grain}_rain_{s / 1000:g}kPa.csv"
        p.write_text(f"x,y,z,r,grain_id\n0,0,{s:g},0.001,0\n")
        load = {"target_pa": float(s), "lid_stress_pa": float(s)} if s else {"target_pa": 0.0}
        p.with_suffix(".json").write_text(json.dumps(
            {"porosity_network_region": porosity, "load": load, "converged": True,
             "fill": {"method": "rain"}}))
    return bed_set_files(grain, folder)


def _plan(tmp_path, stresses, depth, diameter=6.0, grain="wheat"):
    _fake_set(tmp_path / "data", grain, stresses)
    return plan_bin_beds(grain, depth_m=depth, diameter_m=diameter, depth_given=True,
                         particle_density=RHO_P, bed_dir=tmp_path / "beds",
                         data_dir=tmp_path / "data")


def _solved(plan, gz, gx, eps):
    return [{"stress_pa": s, "path": str(p), "porosity": e, "gradient_z_pa_per_m": list(z),
             "gradient_x_pa_per_m": list(x), "converged": [True] * len(z), "cached": False}
            for (s, p), z, x, e in zip(plan["beds"], gz, gx, eps)]


def test_layers_in_series_integrates_a_gradient_linear_in_depth():
    # g = a + b z: dP = a H + b H^2 / 2, exact under Simpson's rule
    assert layers_in_series(5.0, lambda z: 120.0 + 30.0 * z) == pytest.approx(
        120.0 * 5 + 30.0 * 25 / 2, rel=1e-13)
    # a smooth gradient: exp(z / 2) over 4 m -> 2 (e^2 - 1)
    assert layers_in_series(4.0, lambda z: np.exp(z / 2)) == pytest.approx(
        2 * (math.exp(2) - 1), rel=1e-12)


def test_the_depth_integral_of_a_gradient_linear_in_janssen_stress(tmp_path):
    """Beds whose gradient is linear in stress, g = g0 + c sigma: through the depth
    dP = g0 H + c A (H - (1 - exp(-a H)) / a), A = rho_b g D / (4 mu K), a = 4 mu K / D."""
    H, D = 5.0, 8.0
    plan = _plan(tmp_path, [0.0, 20_000.0, 45_000.0], H, D)
    g0, c = 100.0, 2e-3
    gz = [[g0 + c * s, 10 * (g0 + c * s)] for s, _ in plan["beds"]]
    out = bin_section(plan, _solved(plan, gz, gz, [0.37, 0.365, 0.36]), [0.01, 0.1], None)
    k, mu = JANSSEN["wheat"]
    rho_b = RHO_P * (1 - 0.36)
    a = 4 * mu * k / D
    A = rho_b * 9.80665 / a
    want = g0 * H + c * A * (H - (1 - math.exp(-a * H)) / a)
    assert out["points"][0]["vertical_pressure_drop_pa"] == pytest.approx(want, rel=1e-10)
    assert out["points"][1]["vertical_pressure_drop_pa"] == pytest.approx(10 * want, rel=1e-10)
    assert out["stress_pa"]["bottom"] == pytest.approx(A * (1 - math.exp(-a * H)), rel=1e-12)
    assert out["points"][0]["ratio_to_d272"] is None


def test_at_a_bed_s_own_stress_the_interpolation_is_that_bed_s_solve(tmp_path):
    # the set's middle bed at Janssen's stress at mid-depth: surface and mid are beds' own
    H, D = 6.0, 6.0
    k, mu = JANSSEN["wheat"]
    mid = float(janssen_stress(H / 2, bulk_density_kg_m3=RHO_P * (1 - 0.36), diameter_m=D,
                               wall_friction=mu, lateral_ratio=k))
    plan = _plan(tmp_path, [0.0, mid, 45_000.0], H, D)
    gz, gx = [[11.0, 150.0], [13.0, 170.0], [19.0, 240.0]], [[9.0, 120.0], [10.0, 130.0],
                                                             [14.0, 180.0]]
    out = bin_section(plan, _solved(plan, gz, gx, [0.37, 0.36, 0.35]), [0.01, 0.1],
                      (27000.0, 8.77))
    for j in range(2):
        p = out["points"][j]
        assert p["vertical_gradient_pa_per_m"]["surface"] == gz[0][j]
        assert p["vertical_gradient_pa_per_m"]["mid"] == pytest.approx(gz[1][j], rel=1e-12)
        assert p["horizontal_gradient_pa_per_m"]["mid"] == pytest.approx(gx[1][j], rel=1e-12)
        d272 = 27000.0 * p["velocity_m_s"] ** 2 / math.log1p(8.77 * p["velocity_m_s"]) * H
        assert p["d272_pressure_drop_pa"] == pytest.approx(d272, rel=1e-12)
        assert p["ratio_to_d272"] == pytest.approx(p["vertical_pressure_drop_pa"] / d272)
    assert out["porosity"]["surface"] == 0.37
    assert out["porosity"]["mid"] == pytest.approx(0.36, rel=1e-12)
    assert 0.35 < out["porosity"]["bottom"] < 0.36
    assert interpolate_in_stress([0.0, 1e4, 3e4], [1.0, 2.0, 5.0], [0.0, 1e4, 3e4]).tolist() == [
        1.0, 2.0, 5.0]


def test_bin_velocities_and_interpolation_refuse_a_bad_set():
    assert bin_velocities([0.3, 0.005, 0.04, 0.01, 0.1]) == [0.005, 0.04, 0.3]
    with pytest.raises(ValueError, match="must increase"):
        interpolate_in_stress([0.0, 0.0], [1.0, 2.0], 1.0)


def test_a_depth_beyond_the_set_is_refused_with_the_deepest_it_covers(tmp_path):
    with pytest.raises(ValueError, match=r"--depth 40 m: .* beds cover a depth of at most"):
        _plan(tmp_path, [0.0, 20_000.0, 45_000.0], 40.0, 8.0)
    plan = _plan(tmp_path, [0.0, 20_000.0, 45_000.0], 10.0, 6.0)    # 10 m of a 6 m bin: inside
    assert plan["used"] and plan["source"] == "bundled"


def test_grains_without_janssen_inputs_or_a_bin_get_one_line(tmp_path):
    kw = dict(depth_m=3.0, diameter_m=6.0, depth_given=True, particle_density=1400.0,
              bed_dir=tmp_path)
    for grain in ("rough_rice", "sorghum"):
        p = plan_bin_beds(grain, **kw)
        assert p["used"] is False and "no lateral pressure ratio K" in p["why"]
        assert plan_bin_beds(grain, other="--packing", **kw)["why"] == p["why"]
    p = plan_bin_beds("wheat", other="--packing", **kw)
    assert p["used"] is False and p["why"].startswith("--packing asks for one bed")
    assert plan_bin_beds("wheat", **{**kw, "diameter_m": None}) is None
    assert plan_bin_beds("wheat", **{**kw, "depth_given": False}) is None
    # barley: a template, no bundled set: packed on first use into the cache folder
    p = plan_bin_beds("barley", **kw, data_dir=tmp_path / "none")
    assert p["used"] and p["beds"] is None and p["source"] == "packed"


def test_a_packed_set_in_the_cache_folder_is_reused(tmp_path):
    _fake_set(tmp_path / "beds", "barley", BED_SET_STRESSES_PA)
    p = plan_bin_beds("barley", depth_m=3.0, diameter_m=6.0, depth_given=True,
                      particle_density=1300.0, bed_dir=tmp_path / "beds",
                      data_dir=tmp_path / "none")
    assert p["reused"] and [s for s, _ in p["beds"]] == list(BED_SET_STRESSES_PA)


def test_solves_are_cached_by_file_and_inputs(tmp_path):
    plan = _plan(tmp_path, [0.0, 20_000.0], 3.0)
    calls = []

    def solve(path):
        calls.append(path)
        return {"porosity": 0.36, "gradient_z_pa_per_m": [1.0], "gradient_x_pa_per_m": [1.0],
                "converged": [True]}

    a = solve_set(plan, solve, {"velocities_m_s": [0.01]})
    b = solve_set(plan, solve, {"velocities_m_s": [0.01]})
    assert len(calls) == 2 and not any(x["cached"] for x in a) and all(x["cached"] for x in b)
    solve_set(plan, solve, {"velocities_m_s": [0.02]})              # other inputs: solved
    assert len(calls) == 4
    p0 = plan["beds"][0][1]
    p0.write_text(p0.read_text() + "0,0,1,0.001,1\n")                # another bed: solved
    solve_set(plan, solve, {"velocities_m_s": [0.01]})
    assert len(calls) == 5


@pytest.mark.slow
def test_template_volume_copies_agree_with_dem():
    from dem.templates import resolve_template
    for g, v in _TEMPLATE_VOLUME_M3.items():
        assert resolve_template(g, units="mm").volume_m3 == pytest.approx(v, rel=1e-12)
    lx, ly, h = set_box("barley")
    assert lx == ly == h and 0.02 < lx < 0.05


@pytest.mark.parametrize("argv, named", [
    (["--depth", "-1"], "--depth"),
    (["--depth", "0"], "--depth"),
    (["--depth", "60"], "--depth 60 m"),
])
def test_bad_bin_depth_exits_2(tmp_path, monkeypatch, capsys, argv, named):
    monkeypatch.chdir(tmp_path)
    assert main(["--grain", "soybean", "--diameter", "8", "--no-figures", "-q"] + argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and named in err[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.parametrize("grain", ["corn", "soybean", "wheat"])
def test_the_report_on_a_bin_s_bundled_beds(tmp_path, monkeypatch, capsys, grain):
    """`--grain G --depth 5 --diameter 8` on the bundled bed set: the bin's keys in the JSON
    beside the existing ones, three beds, porosity falling (or equal) with depth, the second
    run read from the solve cache."""
    key = {"corn": "shelled_corn"}.get(grain, grain)
    if not bed_set_files(key):
        pytest.skip(f"no bundled {key} bed set")
    monkeypatch.chdir(tmp_path)
    args = ["--grain", grain, "--depth", "5", "--diameter", "8", "--velocities", "0.01,0.1",
            "--no-band", "--no-figures", "--json", "r.json", "-q"]
    assert main(args) == 0
    r = json.loads((tmp_path / "r.json").read_text())
    assert r["grain"] == key and "points" in r and "system_curve" in r
    bb = r["bin_beds"]
    assert bb["used"] and bb["depth_m"] == 5.0 and bb["diameter_m"] == 8.0
    assert set(bb["stress_pa"]) == set(bb["porosity"]) == {"surface", "mid", "bottom"}
    assert bb["stress_pa"]["surface"] == 0.0 < bb["stress_pa"]["mid"] < bb["stress_pa"]["bottom"]
    assert len(bb["beds"]) == len(bed_set_files(key)) >= 3
    for p in bb["points"]:
        for k in ("vertical_pressure_drop_pa", "vertical_mean_gradient_pa_per_m",
                  "horizontal_mean_gradient_pa_per_m", "horizontal_to_vertical",
                  "d272_pressure_drop_pa", "ratio_to_d272"):
            assert p[k] > 0, k
        g = p["vertical_gradient_pa_per_m"]
        assert min(g.values()) <= p["vertical_mean_gradient_pa_per_m"] <= max(g.values())
    assert not any(b["cached"] for b in bb["beds"])
    # at the surface (stress 0, the poured bed's own) the interpolation is that bed's solve
    for j, p in enumerate(bb["points"]):
        assert p["vertical_gradient_pa_per_m"]["surface"] == bb["beds"][0]["gradient_z_pa_per_m"][j]
        assert p["horizontal_gradient_pa_per_m"]["surface"] == bb["beds"][0]["gradient_x_pa_per_m"][j]
    assert bb["porosity"]["surface"] == bb["beds"][0]["porosity"]
    out = capsys.readouterr().out
    assert "bin's beds (bundled" in out and "layers in series" in out
    assert main(args) == 0
    r2 = json.loads((tmp_path / "r.json").read_text())
    assert all(b["cached"] for b in r2["bin_beds"]["beds"])
    assert r2["bin_beds"]["points"] == bb["points"]


@pytest.mark.slow
def test_a_bed_set_is_packed_on_first_use_with_a_progress_bar(tmp_path, monkeypatch, capsys):
    """pack_bed_set runs dem.pack --stress s1 s2 s3 into the cache folder through a temporary
    folder (a small soybean box here), draws its tqdm bar over the pour and each load on stderr
    and leaves the complete set, which the next plan reuses."""
    import network.report.binbeds as bb
    monkeypatch.setattr(bb, "set_box", lambda grain: (0.025, 0.025, 0.02))
    plan = {"bed_dir": str(tmp_path / "beds"), "beds": None}
    rec = bb.pack_bed_set(plan, "soybean")
    assert [s for s, _ in plan["beds"]] == pytest.approx(list(BED_SET_STRESSES_PA), rel=0.02)
    assert "--stress 0 20000 45000" in rec["command"] and str(tmp_path / "beds") in rec["command"]
    assert sorted(p.name for p in (tmp_path / "beds").iterdir() if p.name.startswith(".")) == []
    err = capsys.readouterr().err
    assert "packing the soybean bed set" in err and "3/3" in err
    assert bb._set_in("soybean", tmp_path / "beds") == plan["beds"]      # found next time


@pytest.mark.parametrize("packed, target", [
    (True, "barley_rain_20kPa.json"), (True, "barley_rain_45kPa.csv"), (True, "barley_rain_0kPa.grains.csv"),
    (False, "barley_rain_20kPa.json"),
])
def test_report_outputs_never_land_on_the_bed_set(tmp_path, monkeypatch, capsys, packed, target):
    """--json onto a file of the bin's bed set (packed already, or the name a set still to pack
    takes): exit 2, one line naming --json and the bed, the set's files unchanged."""
    monkeypatch.chdir(tmp_path)
    beds = tmp_path / "beds"
    if packed:
        _fake_set(beds, "barley", BED_SET_STRESSES_PA)
    else:
        beds.mkdir()
    before = {p.name: p.read_bytes() for p in beds.iterdir()}
    argv = ["--grain", "barley", "--depth", "5", "--diameter", "8", "--bed-dir", str(beds),
            "--no-band", "--no-figures", "-q", "--json", str(beds / target)]
    assert main(argv) == 2
    err = [line for line in capsys.readouterr().err.strip().splitlines()
           if not line.startswith("warning:")]     # the fake set's JSONs hold no container
    assert len(err) == 1 and err[0].startswith(f"error: --json {beds / target}: the same file as a bed of "
                                               "the bin's bed set"), err
    assert {p.name: p.read_bytes() for p in beds.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["beds"]


@pytest.mark.parametrize("grain", ["corn", "barley"])
def test_a_bed_dir_that_is_a_file_is_refused_before_any_work(tmp_path, monkeypatch, capsys, grain):
    """--bed-dir naming a file: exit 2 naming it, whether or not the report would pack there."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "f.csv").write_text("x\n")
    assert main(["--grain", grain, "--depth", "5", "--diameter", "8", "--bed-dir", "f.csv",
                 "--no-band", "--no-figures", "-q", "--json", "r.json"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: --bed-dir f.csv: f.csv exists and is not a folder"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.csv"]
