"""Rolling friction (EDEM's standard model, dem._contacts.rolling_moment / rolling_torque): a
sphere rolling on a plane decelerates at -(5/7) mu_r g, on an incline it rolls at
(5/7) g (sin t - mu_r cos t) above tan t = mu_r and stays at rest below, in the sphere engine,
the whole-bed grain step and the active step alike; a multi-sphere grain at rest stays at rest."""

import json

import numpy as np
import pytest

from dem import Material, PlaneWall, Simulation
from dem.clumps import ClumpSimulation
from dem.templates import resolve_template, sphere_template

R_M = 2e-3
G = 9.81
MU_R = 0.1


def _material(mu_r=MU_R):
    return Material(density_kg_m3=1240.0, friction=0.5, wall_friction=0.5, rolling_friction=mu_r,
                    wall_rolling_friction=mu_r, radius_min_m=R_M, radius_max_m=R_M)


def _sphere_on(normal, path, mat):
    """One sphere resting on the plane through the origin with unit ``normal`` (settled 4000 steps)."""
    c = R_M * np.asarray(normal, dtype=float)
    floor = PlaneWall((0, 0, 0), tuple(normal), name="floor")
    if path == "sphere":
        sim = Simulation([c], [R_M], [floor], mat)
    else:
        sim = ClumpSimulation([sphere_template(R_M)], [0], [c], [[1, 0, 0, 0]], [1.0], [floor], mat)
        if path == "active":
            sim.attach_active(lo_m=[-0.05, -0.05, -0.05], hi_m=[0.05, 0.05, 0.05])
    for _ in range(4000):
        sim.step()
    return sim


def _state(sim):
    """(position, velocity, spin) of the one body."""
    if isinstance(sim, ClumpSimulation):
        return sim.X[0].copy(), sim.V[0].copy(), sim.omega()[0]
    return sim.centers[0].copy(), sim.velocities[0].copy(), sim.spins[0].copy()


def _set_rolling(sim, v0):
    """Roll along +x at v0 (spin about +y, v = omega R)."""
    if isinstance(sim, ClumpSimulation):
        sim.V[0] = [v0, 0, 0]
        sim.L[0] = sim._inertia_s[0] * np.array([0.0, v0 / R_M, 0.0])
    else:
        sim.velocities[0] = [v0, 0, 0]
        sim.spins[0] = [0, v0 / R_M, 0]


@pytest.mark.parametrize("path", ["sphere", "grain", "active"])
def test_a_rolling_sphere_decelerates_at_five_sevenths_mu_r_g_and_stops(path):
    # m a = F_t, I a / R = -F_t R - mu_r m g R, I = 2/5 m R^2  =>  a = -(5/7) mu_r g
    sim = _sphere_on((0, 0, 1), path, _material())
    v0 = 0.005
    _set_rolling(sim, v0)
    t, v = [], []
    while True:
        sim.step()
        vx = _state(sim)[1][0]
        if vx < 0.2 * v0:
            break
        t.append(sim.time_s)
        v.append(vx)
    a = np.polyfit(t, v, 1)[0]
    assert a == pytest.approx(-5 / 7 * MU_R * G, rel=0.01)
    for _ in range(2000):       # stops and stays: the torque never reverses the spin
        sim.step()
    x0 = _state(sim)[0]
    for _ in range(3000):
        sim.step()
    x1, v1, w1 = _state(sim)
    assert np.all(np.abs(x1 - x0) < 1e-12) and np.abs(v1).max() < 1e-12 and np.abs(w1).max() < 1e-9


@pytest.mark.parametrize("path", ["sphere", "grain", "active"])
def test_on_an_incline_a_sphere_rolls_only_above_tan_theta_mu_r(path):
    # gravity torque about the contact m g R sin t against mu_r m g cos t R: rolls when tan t > mu_r,
    # then a = (5/7) g (sin t - mu_r cos t) down the slope
    for ratio in (0.5, 2.0):
        theta = np.arctan(ratio * MU_R)
        normal = (-np.sin(theta), 0.0, np.cos(theta))      # the plane z = x tan t, falling towards -x
        sim = _sphere_on(normal, path, _material())
        down = np.array([-np.cos(theta), 0.0, -np.sin(theta)])
        x0 = _state(sim)[0]
        t, s = [], []
        for _ in range(3000):
            sim.step()
            t.append(sim.time_s)
            s.append(_state(sim)[1] @ down)
        if ratio < 1:
            assert np.abs(_state(sim)[0] - x0).max() < 1e-9 and max(np.abs(s)) < 1e-9
        else:
            a = np.polyfit(t[1000:], s[1000:], 1)[0]
            assert a == pytest.approx(5 / 7 * G * (np.sin(theta) - MU_R * np.cos(theta)), rel=0.01)


def test_without_rolling_friction_a_sphere_rolls_on():
    sim = _sphere_on((0, 0, 1), "sphere", _material(0.0))
    _set_rolling(sim, 0.005)
    for _ in range(2000):
        sim.step()
    assert _state(sim)[1][0] == pytest.approx(0.005, rel=1e-6)


@pytest.mark.slow
def test_a_wheat_grain_at_rest_on_a_plane_stays_at_rest():
    t = resolve_template("wheat")
    floor = PlaneWall((0, 0, 0), (0, 0, 1), name="floor")
    mat = Material(density_kg_m3=1240.0, friction=0.53, wall_friction=0.5023, rolling_friction=0.04,
                   wall_rolling_friction=0.111, radius_min_m=float(t.radii.min()), radius_max_m=float(t.radii.max()))
    z = float(np.max(t.radii + np.abs(t.positions[:, 2])))
    sim = ClumpSimulation([t], [0], [[0, 0, z]], [[1, 0, 0, 0]], [1.0], [floor], mat)
    for _ in range(20000):
        sim.step()
    x0 = sim.X[0].copy()
    ke = []
    for _ in range(5000):
        sim.step()
        ke.append(sim.kinetic_energy())
    weight_j = sim.mass[0] * G * 1e-9          # m g times a nanometre
    assert np.abs(sim.X[0] - x0).max() < 1e-9 and max(ke) < weight_j


@pytest.mark.parametrize("field", ["rolling_friction", "wall_rolling_friction"])
@pytest.mark.parametrize("value", [-0.01, float("nan"), float("inf")])
def test_a_negative_or_non_finite_rolling_friction_is_refused(field, value):
    with pytest.raises(ValueError, match=field):
        Material(**{field: value})


def _pour_json(tmp_path, grain, *extra):
    from dem.pack import main
    out = tmp_path / f"{grain}{len(extra)}.csv"
    rc = main(["--scene", "box", "--size", "0.02", "0.02", "--height", "0.02", "--grain", grain, "--n-grains", "3",
               "--mass-scale", "100", "--max-steps", "1", "--quiet", "--out", str(out), *extra])
    assert rc == 1                  # one step: not at rest, written with "converged": false
    return json.loads(out.with_suffix(".json").read_text())


def test_a_pour_records_the_rolling_friction_it_used(tmp_path):
    w = _pour_json(tmp_path, "wheat")
    r = w["rolling_friction"]
    assert r["on"] is True and r["particle"]["value"] == 0.04 and r["wall"]["value"] == 0.111
    assert "inmateh-78-73" in r["particle"]["source"] and "rolling_torque" in r["model"]
    assert w["material"]["rolling_friction"] == 0.04 and w["material"]["wall_rolling_friction"] == 0.111
    off = _pour_json(tmp_path, "wheat", "--no-rolling")["rolling_friction"]
    assert off["on"] is False and off["off_by"] == "--no-rolling"
    assert off["particle"]["value"] == 0.0 and off["particle"]["library_value"] == 0.04
    s = _pour_json(tmp_path, "soybean")["rolling_friction"]       # a grain-grain value only
    assert s["on"] is True and s["particle"]["value"] == 0.05
    assert s["wall"]["value"] == 0.0 and s["wall"]["source"].startswith("none: the library has no value")
    c = _pour_json(tmp_path, "shelled_corn")
    assert c["rolling_friction"]["on"] is False and c["material"]["rolling_friction"] == 0.0
    assert "searched" in c["rolling_friction"]["particle"]["note"]


@pytest.mark.parametrize("extra, named", [
    (["--grain", "wheat", "--fill", "grow"], "--no-rolling needs a poured fill"),
    ([], "--no-rolling needs --grain"),
])
def test_no_rolling_without_a_poured_fill_is_refused(tmp_path, capsys, extra, named):
    from dem.pack import main
    rc = main(["--scene", "box", "--no-rolling", "--out", str(tmp_path / "b.csv"), "--quiet"] + extra)
    assert rc == 2 and list(tmp_path.iterdir()) == []
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0]
