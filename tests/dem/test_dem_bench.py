"""dem.bench: the rate scene and the JSON it writes (benchmarks get tests)."""

import importlib
import json
import math

import numpy as np
import pytest

from dem import Container

bench = importlib.import_module("dem.bench")

#: 2 * 4^3 = 128 spheres: a complete 4 x 4 x 8 simple cubic lattice (lattice_simulation's layout)
N = 128
#: lattice bonds of a 4 x 4 x 8 simple cubic lattice: 3*4*8 (x) + 4*3*8 (y) + 4*4*7 (z)
BONDS = 3 * 4 * 8 + 4 * 3 * 8 + 4 * 4 * 7


@pytest.mark.slow
def test_lattice_scene_is_a_touching_simple_cubic_lattice():
    sim = bench.lattice_simulation(N)
    assert sim.n == N
    np.testing.assert_allclose(sim.radii, 0.00325 * (1 + 1e-4), rtol=1e-15)
    sim.step()
    # radii 1e-4 larger than half the 6.5 mm spacing: every lattice bond touches, no diagonal
    # (6.5 mm * sqrt 2 is far beyond the 0.1 r skin), so pairs = contacts = bonds
    assert len(sim.verlet.pairs) == BONDS
    assert len(sim.contact_fn) == BONDS
    # overlap 2 * 3.25e-7 m at k = 2e6 N/m: F_n = 1.3 N (noise 1e-7 m and gravity move it a little)
    assert np.median(sim.contact_fn) == pytest.approx(2e6 * 6.5e-7, rel=0.5)


@pytest.mark.slow
def test_rate_returns_a_positive_finite_rate_for_the_right_count():
    r = bench.rate(N, steps=10, repeat=2)
    assert r["n"] == N and r["steps"] == 10
    assert r["pairs"] == BONDS and r["contacts"] == BONDS
    assert len(r["seconds"]) == 2 and r["rebuilds"] >= 1
    for key in ("rate_best", "rate_median", "rate_per_cpu_s_best", "ms_per_step_best"):
        assert math.isfinite(r[key]) and r[key] > 0
    # the rate is particle-steps over the best wall time, and ms/step the same time per step
    assert r["rate_best"] == pytest.approx(N * 10 / min(r["seconds"]), rel=1e-12)
    assert r["ms_per_step_best"] == pytest.approx(1e3 * min(r["seconds"]) / 10, rel=1e-12)
    assert r["rate_best"] >= r["rate_median"]


@pytest.mark.slow
def test_bench_json_has_what_it_prints(tmp_path, capsys):
    out = tmp_path / "b.json"
    assert bench.main(["--n", str(N), "64", "--steps", "5", "--repeat", "1", "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "p-steps/s best" in printed and "load average" in printed and str(out) in printed
    data = json.loads(out.read_text())
    assert [row["n"] for row in data["rates"]] == [N, 64]
    for row in data["rates"]:
        # one key per printed column: N, pairs, contacts, ms/step, best, median, per CPU-s, threads
        assert {"n", "pairs", "contacts", "ms_per_step_best", "rate_best", "rate_median",
                "rate_per_cpu_s_best", "steps_by_threads"} <= set(row)
    meta = data["meta"]
    assert {"loadavg_before", "loadavg_after", "cpu_count", "platform", "numpy", "timestamp"} <= set(meta)
    assert len(meta["loadavg_before"]) == 3


def test_lattice_box_holds_the_lattice():
    sim = bench.lattice_simulation(N)
    x = sim.centers
    # the closed box of the scene: 4 x 4 cells wide, 8 high, every sphere inside
    box = Container("box", (4 * 0.0065, 4 * 0.0065), 8 * 0.0065)
    assert np.all(np.abs(x[:, :2]) + sim.radii[:, None] <= np.array(box.size_m) / 2 + 1e-6)
    assert np.all((x[:, 2] - sim.radii >= -1e-6) & (x[:, 2] + sim.radii <= box.fill_height_m + 1e-6))


@pytest.mark.slow
def test_grain_lattice_touches_its_neighbours_once_per_bond():
    # 16 soybeans on a 2 x 2 x 4 lattice of their extent shrunk by 1e-4: 28 grain bonds. The template's
    # four middle spheres (r = c) touch their partners across a z bond, the tip spheres across an x
    # bond and the outer row spheres across a y bond: 8 + 8 + 12 * 4 = 64 sphere contacts; the floor
    # carries the four middle spheres of the 4 bottom grains
    sim = bench.grain_lattice_simulation(16)
    sim.step()
    assert (sim.n_grains, len(sim.radii)) == (16, 96)
    assert len(sim.contact_fn) == 64 and len(sim.last_wall_fn) == 16
    assert len(np.unique(np.sort(sim.touching_grains, axis=1), axis=0)) == 28
    # overlap 1e-4 of the thickness 5.77 mm at kn 2e6 N/m: F_n = 1.15 N
    assert np.median(sim.contact_fn) == pytest.approx(2e6 * 1e-4 * sim.templates[0].extent_m[2], rel=0.01)


@pytest.mark.slow
def test_grain_rate_row_and_json(tmp_path, capsys):
    r = bench.grain_rate(16, steps=4, repeat=2)
    assert (r["grains"], r["n"], r["steps"]) == (16, 96, 4)
    assert r["rate_best"] == pytest.approx(96 * 4 / min(r["seconds"]), rel=1e-12) and r["rate_best"] >= r["rate_median"]
    assert len(r["loadavg"]) == 3
    out = tmp_path / "g.json"
    assert bench.main(["--grains", "16", "--steps", "3", "--repeat", "1", "--json", str(out)]) == 0
    assert "s-steps/s best" in capsys.readouterr().out
    assert [row["grains"] for row in json.loads(out.read_text())["grain_rates"]] == [16]


@pytest.mark.slow
def test_grain_pack_time_runs_dem_pack_for_the_grain_count(tmp_path):
    # 6 soybeans: a cube of side (6 V_g / (1 - 0.40985))^(1/3) = 11.5 mm, packed by the real CLI
    r = bench.grain_pack_time(6, out_dir=str(tmp_path), warm_up=False)
    v_g = bench.library_template("soybean").volume_m3
    assert r["side_m"] == pytest.approx((6 * v_g / (1 - 0.40985)) ** (1 / 3), rel=1e-12)
    assert (r["grains"], r["n_spheres"]) == (6, 36) and r["steps"] >= 6000
    assert 0 < r["pack_wall_time_s"] <= r["wall_s"] and r["cpu_s"] > 0 and len(r["loadavg_before"]) == 3
    assert "--n-grains 6" in r["command"] and (tmp_path / "bed.csv").exists()


@pytest.mark.slow
def test_pour_time_runs_the_wheat_pour_and_its_load(tmp_path):
    r = bench.pour_time(6, stress_pa=2000.0, out_dir=str(tmp_path), warm_up=False)
    assert (r["grains"], r["n_spheres"], r["freeze"], r["stress_pa"]) == (6, 48, True, 2000.0)
    assert "--n-grains 6" in r["command"] and "--stress 2000" in r["command"] and "--mass-scale 100" in r["command"]
    assert 0 < r["pour_cpu_s"] and 0 < r["load_cpu_s"] and r["pour_cpu_s"] + r["load_cpu_s"] <= r["cpu_s"]
    assert r["steps"] == r["fill_steps"] + r["rest_steps"] + r["load_steps"]
    assert 0 < r["active_particle_steps"] <= r["particle_steps"]
