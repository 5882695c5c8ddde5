"""Poured fills and the overburden lid (dem._pour, dem._load, dem.pack --fill/--depth/--stress):
entry speed and drag cap, the default rate, the orientation order, the angle-of-repose fit,
Janssen's stress and its limits, the lid's stress control, the rest check and the bad-input
contract of the command line."""

import json
import math

import numpy as np
import pytest

from dem import Container, FillOptions, Material, janssen_stress, load_bed, pour_grains
from dem._pile import angle_of_repose, orientation_order, porosity_by_depth
from dem._pour import AIR_DENSITY_KG_M3, DRAG_COEFFICIENT, _grown, default_rate, entry_speed, terminal_velocity
from dem._rigid import random_quaternions
from dem.clumps import ClumpSimulation
from dem.pack import main
from dem.templates import library_template, sphere_template

G = 9.81


def test_entry_speed_is_the_fall_from_the_drop_height():
    assert entry_speed(0.3, 4.1e-3, 1240.0) == pytest.approx(math.sqrt(2 * G * 0.3), rel=1e-12)
    assert entry_speed(1.0, 4.1e-3, 1240.0) == pytest.approx(math.sqrt(2 * G), rel=1e-12)


def test_entry_speed_is_capped_at_the_terminal_velocity():
    # Newton's drag: weight = drag at v_t, (pi/6) d^3 (rho_p - rho_a) g = C_D (pi/8) d^2 rho_a v_t^2
    d, rho = 2e-3, 1100.0
    vt = terminal_velocity(d, rho)
    weight = math.pi / 6 * d**3 * (rho - AIR_DENSITY_KG_M3) * G
    drag = DRAG_COEFFICIENT * math.pi / 8 * d**2 * AIR_DENSITY_KG_M3 * vt**2
    assert drag == pytest.approx(weight, rel=1e-12)
    assert math.sqrt(2 * G * 10.0) > vt
    assert entry_speed(10.0, d, rho) == vt


def test_default_rate_raises_the_surface_one_diameter_per_rebound_flight():
    area, d, rho, phi, e, v0 = 0.04**2, 4.1e-3, 1240.0, 0.4, 0.5, 2.0
    rate = default_rate(area, d, rho, phi, e, v0)
    rise = rate / (rho * (1 - phi) * area)          # m/s of bed height
    assert rise * (2 * e * v0 / G) == pytest.approx(d, rel=1e-12)


@pytest.mark.parametrize("kw, match", [
    (dict(method="pile"), "fill must be one of"),
    (dict(drop_height_m=0.0), "drop height 0 m"),
    (dict(drop_height_m=10.5), "drop height 10.5 m"),
    (dict(drop_height_m=float("nan")), "drop height nan"),
    (dict(rate_kg_s=0.0), "rate 0 kg/s"),
    (dict(rate_kg_s=-2.0), "rate -2 kg/s"),
    (dict(spout_diameter_m=-0.01), "spout diameter -0.01 m"),
    (dict(mass_scale=0.5), "mass scale 0.5"),
    (dict(freeze="no"), "freeze must be True or False"),
])
def test_fill_options_refuse_bad_values(kw, match):
    with pytest.raises(ValueError, match=match):
        FillOptions(**kw)


def test_fill_options_are_frozen_and_keyword_only():
    f = FillOptions()
    assert (f.method, f.drop_height_m, f.rate_kg_s, f.mass_scale) == ("rain", 0.3, None, 1.0)
    with pytest.raises(Exception):
        f.method = "spout"
    with pytest.raises(TypeError):
        FillOptions("rain")


def test_orientation_order_limits():
    flat = np.array([[1.0, 0, 0, 0], [np.cos(0.4), 0, 0, np.sin(0.4)]])   # x in the horizontal plane
    assert orientation_order(flat) == pytest.approx(-0.5, abs=1e-12)
    up = np.array([[np.cos(np.pi / 4), 0, -np.sin(np.pi / 4), 0]])         # x rotated onto z
    assert orientation_order(up) == pytest.approx(1.0, abs=1e-12)
    n = 40_000                                      # random: <P2> = 0, standard error sqrt(1/5 / n)
    s = orientation_order(random_quaternions(n, np.random.default_rng(3)))
    assert abs(s) < 5 * math.sqrt(0.2 / n)


def test_angle_of_repose_of_a_cone():
    rng = np.random.default_rng(1)
    xy = rng.uniform(-0.05, 0.05, (20_000, 2))
    r = np.hypot(xy[:, 0], xy[:, 1])
    h = 0.06 - r * math.tan(math.radians(27.0))
    radii = np.full(len(r), 1e-4)
    centers = np.column_stack([xy, h - radii])
    box = Container("box", (0.1, 0.1), 0.06)
    fit = angle_of_repose(centers, radii, box, inner_m=0.01, cell_m=0.004)
    assert fit["angle_deg"] == pytest.approx(27.0, abs=0.5)


def test_porosity_by_depth_lists_ten_layers_from_the_surface_down():
    layers = porosity_by_depth(np.zeros((1, 3)), np.ones(1), (0, 0), (1, 1), 0.2, layers=10,
                               porosity_fn=lambda lo, hi: (float(hi[2]), 0.0))
    assert len(layers) == 10
    assert [l["z_hi_m"] for l in layers] == pytest.approx(np.linspace(0.2, 0.02, 10))
    assert [l["depth_m"] for l in layers] == pytest.approx(np.linspace(0.01, 0.19, 10))


def test_janssen_stress_closed_form_and_limits():
    rho, d, mu, k = 760.0, 6.0, 0.5, 0.54
    kw = dict(bulk_density_kg_m3=rho, diameter_m=d, wall_friction=mu, lateral_ratio=k)
    z = 3.4
    assert janssen_stress(z, **kw) == pytest.approx(rho * G * d / (4 * mu * k) * (1 - math.exp(-4 * mu * k * z / d)),
                                                    rel=1e-12)
    assert janssen_stress(1e-4, **kw) == pytest.approx(rho * G * 1e-4, rel=1e-4)      # z -> 0: the column
    assert janssen_stress(1e3, **kw) == pytest.approx(rho * G * d / (4 * mu * k), rel=1e-12)  # z -> inf
    assert janssen_stress(0.0, **kw) == 0.0
    zs = np.linspace(0, 20, 11)
    assert np.all(np.diff(janssen_stress(zs, **kw)) > 0)
    with pytest.raises(ValueError, match="depth"):
        janssen_stress(-1.0, **kw)


def test_grown_simulation_continues_the_old_grains_unchanged():
    """Adding grains far away changes nothing for the grains already there (state and springs)."""
    t = library_template("soybean")
    walls = Container("box", (0.05, 0.05), 0.05).walls(lid=False)
    rng = np.random.default_rng(2)
    x = np.array([[0.0, 0.0, 0.004], [0.0, 0.0, 0.0105], [0.012, 0.0, 0.004]])
    q = random_quaternions(3, rng)
    a = ClumpSimulation([t], np.zeros(3, int), x, q, np.ones(3), walls, Material(), mass_scale=100.0)
    a.run(max_steps=400)
    b = _grown(a, t, np.array([[0.0, 0.0, 0.2]]), np.zeros((1, 3)), random_quaternions(1, rng))
    a.run(max_steps=300)
    b.run(max_steps=300)
    assert np.max(np.abs(b.X[:3] - a.X)) < 1e-12
    assert np.max(np.abs(b.V[:3] - a.V)) < 1e-9


def _small_pour(**kw):
    t = library_template("soybean")
    box = Container("box", (0.03, 0.03), 0.02)
    args = dict(material=Material(), fill=FillOptions(mass_scale=100.0), n_grains=25, rng=1)
    args.update(kw)
    return pour_grains(box, t, **args), box, t


@pytest.mark.slow
def test_lid_holds_the_target_stress_on_a_small_bed():
    (sim, rec), box, _ = _small_pour()
    assert rec["converged"]
    out = load_bed(sim, box, 4000.0)
    assert out["converged"]
    assert out["lid_stress_pa"] == pytest.approx(4000.0, rel=0.02)
    # the lid carries what it says: its contact forces over the area
    touching = sim._wall_touch[-1].view(bool)
    assert sim._wall_fn[-1][touching].sum() / box.area_m2 == pytest.approx(4000.0, rel=0.1)


def test_pour_enters_every_grain_and_records_the_fill():
    (sim, rec), box, t = _small_pour(n_grains=6, max_steps=200)
    assert sim.n_grains == 6 and rec["batches"] >= 1
    assert rec["entry_speed_m_s"] == pytest.approx(math.sqrt(2 * G * 0.3), rel=1e-12)
    assert rec["fill_time_s"] > 0 and rec["particle_steps"] > 0


def test_rest_check_fails_a_bed_not_at_rest(tmp_path, capsys):
    out = tmp_path / "bed.csv"
    rc = main(["--scene", "box", "--size", "0.02", "0.02", "--height", "0.02", "--grain", "soybean",
               "--n-grains", "4", "--mass-scale", "100", "--max-steps", "1", "--quiet", "--out", str(out)])
    assert rc == 1
    s = json.loads(out.with_suffix(".json").read_text())
    assert s["converged"] is False and s["fill"]["method"] == "rain"
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: not at rest")


@pytest.mark.slow
@pytest.mark.parametrize("extra, named", [
    (["--drop-height", "0"], "--drop-height 0"),
    (["--drop-height", "10.01"], "--drop-height 10.01"),
    (["--rate", "0"], "--rate 0"),
    (["--rate", "-1"], "--rate -1"),
    (["--fill", "spout", "--spout-diameter", "0.5"], "--spout-diameter 0.5"),
    (["--stress", "-1"], "--stress -1"),
    (["--depth", "12", "--bin-diameter", "6", "--bin-height", "10"], "--depth 12"),
    (["--depth", "3", "--bin-diameter", "6", "--stress", "100"], "--stress 100 together with --depth 3"),
    (["--depth", "3"], "--depth 3 needs --bin-diameter"),
    (["--fill", "grow", "--stress", "100"], "--stress needs a poured fill"),
])
def test_bad_fill_and_load_input_exits_2_and_writes_nothing(tmp_path, capsys, extra, named):
    out = tmp_path / "bed.csv"
    rc = main(["--scene", "box", "--grain", "wheat", "--out", str(out), "--quiet"] + extra)
    assert rc == 2
    assert list(tmp_path.iterdir()) == []
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and named in err[0]


@pytest.mark.slow
def test_a_bed_set_loads_each_stress_from_the_same_poured_state(tmp_path):
    """--stress with several values: one pour, each stress loaded from a copy of the poured state,
    so the set's bed at a stress is the bed a single --stress run of the same seed makes."""
    base = ["--scene", "box", "--size", "0.025", "0.025", "--height", "0.02", "--grain", "soybean",
            "--n-grains", "25", "--mass-scale", "100", "--quiet"]
    assert main(base + ["--stress", "0", "4000", "--out", str(tmp_path / "set.csv")]) == 0
    assert main(base + ["--stress", "4000", "--out", str(tmp_path / "one.csv")]) == 0
    one = np.loadtxt(tmp_path / "one.csv", delimiter=",", skiprows=1)
    loaded = np.loadtxt(tmp_path / "set_4kPa.csv", delimiter=",", skiprows=1)
    poured = np.loadtxt(tmp_path / "set_0kPa.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(loaded, one)
    assert not np.array_equal(poured, loaded)
    s0, s4 = (json.loads((tmp_path / f"set_{k}kPa.json").read_text()) for k in (0, 4))
    assert s0["load"]["target_pa"] == 0.0 and s4["load"]["lid_stress_pa"] == pytest.approx(4000.0, rel=0.02)
    np.testing.assert_equal(s4["load"]["porosity_before_load"], s0["porosity_network_region"])
    assert s4["bed_set"]["stresses_pa"] == [0.0, 4000.0]


def test_a_stress_given_twice_is_refused(tmp_path, capsys):
    rc = main(["--scene", "box", "--grain", "wheat", "--stress", "100", "100", "--quiet",
               "--out", str(tmp_path / "b.csv")])
    assert rc == 2 and list(tmp_path.iterdir()) == []
    assert "--stress 100 100: a stress is given twice" in capsys.readouterr().err


def test_sphere_beds_refuse_fill_options(tmp_path, capsys):
    rc = main(["--scene", "box", "--size", "0.04", "0.04", "--height", "0.04", "--fill", "rain",
               "--out", str(tmp_path / "s.csv")])
    assert rc == 2 and "needs --grain" in capsys.readouterr().err


@pytest.mark.slow
def test_rain_of_one_sphere_grains_settles_at_the_poured_random_packing_of_spheres():
    """One-sphere grains (thesis soybean material, real masses) rained into a box settle at the
    porosity of equal spheres poured at random: solid fraction 0.59-0.62 (Scott 1960, Nature
    188:908, 'loose random packing' about 0.60; dense random 0.637), porosity 0.38-0.41, measured
    one diameter from the walls, the floor and the surface."""
    from dem._clump_pack import union_porosity_in_box
    r = 0.00325
    box = Container("box", (0.03, 0.03), 0.03)
    t = sphere_template(r)
    n = int((1 - 0.4) * box.volume_m3 / t.volume_m3)
    sim, rec = pour_grains(box, t, material=Material(radius_min_m=r, radius_max_m=r), n_grains=n, rng=1,
                           max_steps=400_000)
    assert rec["converged"]
    xs = sim.sphere_centers()
    top = float(np.max(xs[:, 2] + sim.radii))
    m = 2 * r
    phi, err = union_porosity_in_box(xs, sim.radii, np.array([-0.015 + m, -0.015 + m, m]),
                                     np.array([0.015 - m, 0.015 - m, top - m]))
    assert 0.38 <= phi <= 0.41, phi


def test_a_dense_spout_stream_is_spread_along_its_fall_not_refused():
    """A spout barely wider than a grain at ten times the default rate: every grain enters
    (the batch slab grows up to 8 times, the mean rate kept)."""
    t = library_template("soybean")
    box = Container("box", (0.04, 0.04), 0.02)
    fill = FillOptions(method="spout", spout_diameter_m=2.2 * t.bounding_radius_m, rate_kg_s=0.1,
                       mass_scale=100.0)
    sim, rec = pour_grains(box, t, material=Material(), fill=fill, n_grains=8, rng=4, max_steps=10)
    assert sim.n_grains == 8 and rec["method"] == "spout"
    assert rec["spout_diameter_m"] == pytest.approx(2.2 * t.bounding_radius_m)


def test_a_container_narrower_than_a_grain_is_refused():
    t = library_template("wheat")
    with pytest.raises(ValueError, match="narrower than a wheat grain"):
        pour_grains(Container("box", (0.006, 0.04), 0.04), t, material=Material(), n_grains=3)
