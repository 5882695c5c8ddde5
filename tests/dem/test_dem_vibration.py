"""Vibration checks, resumable runs and the study command (dem.study)."""

import importlib
import json

import numpy as np
import pytest
from scipy.optimize import brentq

from dem import (Container, Material, PackOptions, PlaneWall, RunOptions, Simulation, VibrationOptions,
                 intensity_g, pack_bed, vibrate_bed)

TINY = Container("box", (0.03, 0.02), 0.03)
R = 0.00325
G = 9.81


def _settle(max_steps):
    """The default settling after the vibration (force ratio 1e-3) within ``max_steps`` steps."""
    return RunOptions(tol=1e-3, max_steps=max_steps)


@pytest.fixture(scope="module")
def bed():
    # settled to a force ratio 5e-3 (dem.vibrate's rest check passes: motion 6e-4 radii)
    return pack_bed(TINY, rng=7, options=PackOptions(grow_steps=500, lid_headroom=1.0),
                    run=RunOptions(tol=5e-3, max_steps=20000))


@pytest.mark.slow
def test_sphere_on_a_vibrating_floor_follows_the_analytic_trajectory():
    # A sphere resting on a floor z_w = A sin(wt) at Gamma = A w^2 / g = 1.99 leaves it when the
    # floor's acceleration falls below -g, sin(w t1) = 1/Gamma (rigid-contact limit), then flies
    # on the parabola from the floor's position and velocity at t1 until it meets the floor.
    a, w = 0.0022, 2 * np.pi * 15.0
    mat = Material()
    sim = Simulation([[0, 0, R]], [R], [PlaneWall((0, 0, 0), (0, 0, 1), "floor")], mat, dt_safety=0.5)
    sim.centers[:] = [[0, 0, R - sim.mass[0] * G / mat.kn_pw]]  # static overlap m g / k
    sim.velocities[:] = [[0, 0, a * w]]  # moving with the floor at t = 0
    t1 = np.arcsin(G / (a * w**2)) / w
    z1, v1 = a * np.sin(w * t1) + R, a * w * np.cos(w * t1)
    parabola = lambda t: z1 + v1 * (t - t1) - 0.5 * G * (t - t1) ** 2  # noqa: E731
    t_land = brentq(lambda t: parabola(t) - R - a * np.sin(w * t), t1 + 1e-3, t1 + 1.0)
    ts, zs, touching = [], [], []
    while sim.time_s < t_land + 0.001:
        sim.z_offset_m = a * np.sin(w * sim.time_s)
        sim.wall_vz_m_s = a * w * np.cos(w * sim.time_s)
        sim.step()
        ts.append(sim.time_s)
        zs.append(sim.centers[0, 2])
        touching.append(len(sim.last_wall_fn) > 0)
    ts, zs, touching = map(np.array, (ts, zs, touching))
    off = np.flatnonzero(~touching)[0]
    land = off + np.flatnonzero(touching[off:])[0]
    # measured: takeoff 36 us after t1 (soft contact, k = 3.27e6 N/m), landing 3 us after the
    # analytic time, 4 nm from the parabola in flight (apex 6.0 mm)
    assert ts[off] == pytest.approx(t1, abs=1e-4)
    assert ts[land] == pytest.approx(t_land, abs=2e-5)
    flight = (ts > t1 + 0.002) & (ts < t_land - 0.002)
    assert np.max(np.abs(zs[flight] - parabola(ts[flight]))) < 1e-7


@pytest.mark.slow
def test_bed_at_045_g_moves_with_the_floor_and_leaves_it_at_181_g(bed):
    # relative motion of the mean sphere height against the floor over periods 2-3, sampled
    # 20 times a period: measured 55 um (0.11 A) at 0.45 g (soft contacts, S = 100) and 2.4 mm
    # (1.2 A) at 1.81 g, where the bed takes off each period
    ranges = {}
    for a in (0.0005, 0.002):
        res = vibrate_bed(bed.centers, bed.radii, TINY,
                          vibration=VibrationOptions(freq_hz=15.0, amplitude_m=a, duration_s=0.2,
                                                     record_every_s=1 / 300),
                          run=_settle(100))
        rel = res.motion["bed_z_m"] - res.motion["floor_z_m"]
        sel = (res.times_s > 1 / 15) & (res.times_s <= 0.2)
        ranges[a] = np.ptp(rel[sel]) / a
        # the step: dt = 0.25 sqrt(S m_min / k_n), k_n = 4e6 N/m per grain, so the stiffest contact
        # (grain on wall, 3.27e6 N/m) oscillates with w dt = 0.25 sqrt(3.27/4) = 0.23 < 2 (stable)
        m_min = 1285 * 4 / 3 * np.pi * bed.radii.min() ** 3
        assert res.summary["dt_s"] == pytest.approx(0.25 * np.sqrt(100 * m_min / 4e6), rel=1e-12)
    assert intensity_g(15.0, 0.0005) == pytest.approx(0.4527, abs=1e-4)
    assert ranges[0.0005] < 0.2
    assert ranges[0.002] > 1.0


@pytest.mark.slow
def test_interrupted_vibration_resumes_to_the_same_numbers(bed):
    kw = dict(vibration=VibrationOptions(freq_hz=15.0, amplitude_m=0.002, duration_s=0.04,
                                         record_every_s=1 / 60, snapshot_times_s=[0.03]),
              run=_settle(300))
    ckpts = []
    full = vibrate_bed(bed.centers, bed.radii, TINY, checkpoint=ckpts.append, checkpoint_every_s=0.015, **kw)
    assert len(ckpts) == 2  # at 0.015 s and 0.03 s
    again = vibrate_bed(bed.centers, bed.radii, TINY, resume=ckpts[0], **kw)
    np.testing.assert_array_equal(again.centers, full.centers)
    np.testing.assert_array_equal(again.porosity_spheres, full.porosity_spheres)
    np.testing.assert_array_equal(again.times_s, full.times_s)
    np.testing.assert_array_equal(again.snapshots[0.03], full.snapshots[0.03])


@pytest.mark.slow
def test_vibration_stops_when_the_porosity_is_steady(bed):
    res = vibrate_bed(bed.centers, bed.radii, TINY,
                      vibration=VibrationOptions(freq_hz=15.0, amplitude_m=0.0005, duration_s=1.0,
                                                 record_every_s=1 / 150, steady_window_s=0.2,
                                                 steady_tol=0.01),
                      run=_settle(100))
    assert res.summary["stopped_by"] == "steady"
    assert 0.2 <= res.summary["vibrated_s"] < 1.0


@pytest.mark.slow
def test_study_command_runs_resumes_and_writes_what_it_says(tmp_path, capsys):
    vib_main = importlib.import_module("dem.vibrate").main
    args = ["--study", "thesis", "--scene", "box", "--size", "0.04", "0.03", "--height", "0.04", "--amplitude",
            "0.0005", "0.002", "--duration", "0.03", "--steady-window", "0", "--settle-steps", "200",
            "--no-network", "--quiet", "--out", str(tmp_path)]
    assert vib_main(args) == 0
    study = json.loads((tmp_path / "study.json").read_text())
    assert [round(r["intensity_g"], 2) for r in study["rows"]] == [0.45, 1.81]
    assert study["dt_s"] > 0 and study["stiffness_n_m"]["particle_normal"] == 2.0e6
    for r in study["rows"]:
        assert 0.3 < r["porosity_global_after"] < 0.7 and r["stopped_by"] == "duration"
        assert len(r["porosity_spheres_after"]) == 5  # B1-B5
    assert (tmp_path / "bed.csv").exists() and (tmp_path / "vib_2mm" / "after.csv").exists()
    assert (tmp_path / "porosity_time.png").exists() and (tmp_path / "porosity_intensity.png").exists()
    w = study["wall_time_s"]
    assert all(x > 0 for x in w["vibration"]) and w["bed"] > 0 and w["incomplete"] == []
    assert w["total"] == pytest.approx(w["bed"] + sum(w["vibration"]) + w["network_timed"])
    first = capsys.readouterr().out
    assert "A mm" in first
    # a second run reuses the bed and both results: same table
    assert vib_main(args) == 0
    assert json.loads((tmp_path / "study.json").read_text())["rows"] == study["rows"]
    assert vib_main([*args[:-2], "--out", str(tmp_path), "extra.csv"]) == 2  # --study takes no packing


@pytest.mark.slow
def test_checkpoint_keeps_the_wall_time_of_earlier_runs(tmp_path):
    """A resumed intensity reports its whole wall time: the checkpoint stores earlier runs'
    seconds plus this run's (here 5 s before and 1 s in this run)."""
    import time
    from dem.study import _checkpointer, _load_checkpoint
    path = tmp_path / "checkpoint.npz"
    ck = {"state": {"time_s": np.array(0.5), "steps": np.array(10)}, "snapshots": {},
          "history": {"times_s": [0.0, 0.5]}, "next_record_s": 0.6, "next_checkpoint_s": 1.0}
    _checkpointer(path, 5.0, time.perf_counter() - 1.0)(ck)
    back = _load_checkpoint(path)
    assert back["wall_s"] == pytest.approx(6.0, abs=0.2)
    assert float(back["state"]["time_s"]) == 0.5 and back["history"]["times_s"] == [0.0, 0.5]


@pytest.mark.slow
def test_study_keeps_each_beds_resistance_curve_and_plots_them(tmp_path):
    """The study's network steps include network.curve: its fits and points are kept per bed
    (numbers passed through unchanged) and drawn before/after in resistance_curves.png."""
    pytest.importorskip("matplotlib")
    from dem._plots import plot_study
    from dem.study import NETWORK_STEPS, _network_numbers
    assert NETWORK_STEPS["curve"][0] == "network.curve"
    data = {"permeability_m2": 4e-8, "forchheimer_beta_per_m": 1800.0, "d272_a": 5500.0, "d272_b": 13.0,
            "ergun_A": 171.0, "ergun_B": 1.26,
            "points": [{"velocity_m_s": 0.005, "pressure_gradient_pa_per_m": 2.3},
                       {"velocity_m_s": 0.3, "pressure_gradient_pa_per_m": 342.0}]}
    c = _network_numbers("curve", data)
    assert c["forchheimer_beta_per_m"] == 1800.0 and c["pressure_gradient_pa_per_m"] == [2.3, 342.0]
    after = dict(c, pressure_gradient_pa_per_m=[2.9, 420.0])
    row = {"intensity_g": 1.81, "porosity_global_before": 0.41, "porosity_global_after": 0.39,
           "porosity_interior_after": 0.37, "porosity_spheres_after": [0.36] * 5,
           "network_after": {"curve": after}}
    study = {"bed": {"network": {"curve": c}}, "rows": [row], "series": {}}
    names = [p.name for p in plot_study(study, tmp_path)]
    assert "resistance_curves.png" in names and (tmp_path / "resistance_curves.png").stat().st_size > 1000


@pytest.mark.slow
def test_resume_from_the_studys_npz_checkpoint_is_bit_for_bit(bed, tmp_path):
    """The study's checkpoint file (dem.study._checkpointer -> .npz -> _load_checkpoint) resumes
    to the same centres, records and porosities as a run never stopped, to the last bit."""
    from dem.study import _checkpointer, _load_checkpoint
    kw = dict(vibration=VibrationOptions(freq_hz=15.0, amplitude_m=0.003, duration_s=0.2,
                                         record_every_s=1 / 15),
              run=_settle(300))
    full = vibrate_bed(bed.centers, bed.radii, TINY, **kw)
    path, saved = tmp_path / "checkpoint.npz", []

    def save(ck):
        if not saved:
            _checkpointer(path)(ck)
        saved.append(ck)

    vibrate_bed(bed.centers, bed.radii, TINY, checkpoint=save, checkpoint_every_s=0.1, **kw)
    again = vibrate_bed(bed.centers, bed.radii, TINY, resume=_load_checkpoint(path), **kw)
    np.testing.assert_array_equal(again.centers, full.centers)
    np.testing.assert_array_equal(again.porosity_global, full.porosity_global)
    np.testing.assert_array_equal(again.times_s, full.times_s)


@pytest.mark.slow
def test_vibration_ends_where_the_floor_passes_zero(bed):
    # 0.25 s at 15 Hz is 3.75 periods: the floor stands at -A there, and setting the walls back
    # to 0 would be a 2 mm jump into the bed (3 spheres thrown out). The run goes on to the end
    # of that half period, 0.2667 s, where the floor passes z = 0 within half a step
    res = vibrate_bed(bed.centers, bed.radii, TINY,
                      vibration=VibrationOptions(freq_hz=15.0, amplitude_m=0.002, duration_s=0.25),
                      run=_settle(100))
    s = res.summary
    assert s["vibrated_s"] == pytest.approx(8 / 30, abs=s["dt_s"])
    assert abs(0.002 * np.sin(2 * np.pi * 15.0 * s["vibrated_s"])) < 0.002 * np.pi * 15 * s["dt_s"]
    with pytest.raises(ValueError, match="1e\\+06 Hz is not resolved by the time step"):
        vibrate_bed(bed.centers, bed.radii, TINY,
                    vibration=VibrationOptions(freq_hz=1e6, amplitude_m=1e-9, duration_s=1e-4))
