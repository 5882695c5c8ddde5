"""Inertial network flow, network.curve and network.solve with inertia."""

import dataclasses
import json

import numpy as np
import pytest

from network import curve
from network.conductance import expansion_coefficient
from network.flow import (FlowOptions, SampleOptions, conduit_flow, fit_curve, solve_inertial,
                          solve_network)
from network.packing import default_packing_path, read_packing


@pytest.mark.slow
def test_chain_of_conduits_exact():
    """Two conduits in series, dp = q + 0.5 q^2 each: Q = 1 -> 3 Pa, Q = 100 -> 10200 Pa."""
    pts = solve_inertial(3, [[0, 1], [1, 2]], [1.0, 1.0], np.full((2, 2), 0.5), [0], [2],
                         [100.0, 1.0])
    assert [p.dp_pa for p in pts] == pytest.approx([10200.0, 3.0], rel=1e-9)
    assert all(p.converged and p.iterations <= 30 for p in pts)
    # started from the Stokes solution (p_in 1 Pa: 0.5 m3/s) instead of from rest: the same
    # answer; the start is scaled to the inlet flow, which on two equal conduits in series is
    # already the solution (no Newton step; from rest: five, the first the Stokes solution)
    warm = solve_inertial(3, [[0, 1], [1, 2]], [1.0, 1.0], np.full((2, 2), 0.5), [0], [2],
                          [100.0, 1.0], stokes=(np.array([1.0, 0.5, 0.0]), 0.5))
    assert [p.dp_pa for p in warm] == pytest.approx([10200.0, 3.0], rel=1e-9)
    assert warm[1].iterations == 0 and pts[1].iterations == 5


@pytest.mark.slow
def test_signed_flow_and_loss_coefficients():
    q, w = conduit_flow(np.array([-1.5, 0.0]), np.ones(2), np.array([[9.0, 0.5], [1.0, 1.0]]))
    assert q.tolist() == [-1.0, 0.0] and w.tolist() == [0.5, 1.0]     # reverse uses K[:, 1]
    assert expansion_coefficient(1.0) == 0.0 and expansion_coefficient(0.0) == 1.0


@pytest.fixture(scope="module")
def scene():
    pk = read_packing(default_packing_path())
    return solve_network(pk, sample=SampleOptions(porosity_points=0),
                         flow=FlowOptions(inertia=True, curve_velocities_m_s=[1e-7, 0.027, 0.3]))


@pytest.mark.slow
def test_stokes_limit_mass_balance_and_iterations(scene):
    """U -> 0 gives the Stokes gradient to 1e-6; every pore balances to 1e-10 of Q; <= 30 it."""
    rows = scene.curve_points()
    assert rows[0]["apparent_permeability_m2"] == pytest.approx(scene.permeability_m2, rel=1e-6)
    for u, pt in zip(scene.inertial["velocities_m_s"], scene.inertial["points"]):
        assert pt.converged and pt.iterations <= 30 and pt.residual <= 1e-10
        Q = u * scene.area_m2
        c, q = scene.conns, pt.throat_flow_m3_s
        net = np.bincount(c[:, 0], q, scene.n_pores) - np.bincount(c[:, 1], q, scene.n_pores)
        net[np.concatenate([np.arange(scene.n_pores)[:0]])] = 0
        assert abs(pt.dp_pa) > 0
        fixed = np.zeros(scene.n_pores, bool)
        inl = np.isclose(pt.pressure_pa, pt.dp_pa)
        fixed[inl] = True
        fixed[pt.pressure_pa == 0] = True
        assert np.max(np.abs(net[~fixed])) <= 1e-10 * Q
    # resistance grows with Re; the window law's k/k_app recorded with the nine-row table
    ratio = [scene.permeability_m2 / r["apparent_permeability_m2"] for r in rows]
    assert ratio[0] == pytest.approx(1.0, abs=1e-6) and 1.0 < ratio[2] < ratio[3]
    np.testing.assert_allclose(ratio[2:], [1.1677, 3.1076], rtol=2e-3)


@pytest.mark.slow
def test_parallel_chains_give_the_serial_curve():
    """Two continuation chains in forked processes (workers=2) solve every velocity to the
    same tolerance as one chain: the pressures agree to 1e-9 and every pore balances."""
    pk = read_packing(default_packing_path())
    us = list(np.geomspace(0.005, 0.3, 8))
    flow = FlowOptions(inertia=True, velocity_m_s=us[0], curve_velocities_m_s=us[1:])
    sample = SampleOptions(porosity_points=0)
    one = solve_network(pk, sample=sample, flow=flow)
    two = solve_network(pk, sample=sample, flow=dataclasses.replace(flow, inertial_workers=2))
    p1 = [p.dp_pa for p in one.inertial["points"]]
    p2 = [p.dp_pa for p in two.inertial["points"]]
    assert p2 == pytest.approx(p1, rel=1e-9)
    assert all(p.converged and p.residual <= 1e-10 for p in two.inertial["points"])
    # the chains really are split: 8 velocities in runs of 5 and 3, the sixth starts the
    # second chain from the Stokes pressures, not from the fifth's, so its Newton path differs
    # while the first chain's is the serial one (one chain is deterministic)
    a, b = one.inertial["points"], two.inertial["points"]
    assert [(p.iterations, p.cg_iterations) for p in b[:5]] == \
        [(p.iterations, p.cg_iterations) for p in a[:5]]
    assert (b[5].iterations, b[5].cg_iterations) != (a[5].iterations, a[5].cg_iterations)
    with pytest.raises(ValueError, match="workers"):
        solve_inertial(3, [[0, 1], [1, 2]], [1.0, 1.0], np.zeros(2), [0], [2], [1.0],
                       workers=0)


@pytest.mark.slow
def test_galerkin_preconditioner_is_the_hierarchy_for_its_own_matrix():
    """Recomputing the level operators for the matrix the hierarchy was built on gives the
    same V-cycle (to rounding); for a Jacobian (weights x 0.3 .. 1) CG still converges."""
    import scipy.sparse as sp
    from network.flow import AMGSolver
    rng = np.random.default_rng(3)
    n = 40
    a = sp.diags_array([np.full(n * n - 1, -1.0), np.full(n * n, 4.2),
                        np.full(n * n - 1, -1.0)], offsets=[-1, 0, 1]).tolil()
    for k in range(n * n - n):                                   # 2-D grid Laplacian
        a[k, k + n] = a[k + n, k] = -1.0
    A = sp.csr_array(a)
    amg = AMGSolver(A, smoother="forward-backward")
    r = rng.standard_normal(n * n)
    same = amg.preconditioner(A).matvec(r)
    assert same == pytest.approx(amg.preconditioner().matvec(r), rel=1e-10, abs=1e-12)
    d = sp.diags_array(rng.uniform(0.55, 1.0, n * n))
    J = sp.csr_array(d @ A @ d)
    import scipy.sparse.linalg as spla
    it = [0]
    x, info = spla.cg(J, r, rtol=1e-10, M=amg.preconditioner(J),
                      callback=lambda _: it.__setitem__(0, it[0] + 1))
    assert info == 0 and np.linalg.norm(J @ x - r) <= 1e-9 * np.linalg.norm(r)
    assert it[0] <= 25


@pytest.mark.slow
def test_solve_reports_inertia_and_stokes_gives_the_linear_answer(tmp_path):
    out_i, out_s = tmp_path / "i.json", tmp_path / "s.json"
    from network import solve
    assert solve.main(["-q", "--json", str(out_i)]) == 0
    assert solve.main(["-q", "--stokes", "--json", str(out_s)]) == 0
    i, s = json.loads(out_i.read_text()), json.loads(out_s.read_text())
    # the whole-sample Stokes permeability and the inset one (faces weighted by their area in
    # the window, docs/sample-boundary.md), every throat read in one vertex order
    # (cache/_order.py): 4.2026085e-08 and 4.22839e-08 m2, 1.48496 Pa over 0.25 m
    assert s["permeability_whole_m2"] == pytest.approx(4.2026085e-08, rel=1e-7)
    assert s["permeability_m2"] == pytest.approx(4.22839e-08, rel=1e-5)
    assert s["pressure_drop_pa"] == pytest.approx(1.48496, rel=1e-5)
    assert i["permeability_m2"] == pytest.approx(s["permeability_m2"], rel=1e-9)   # AMG noise
    assert i["pressure_drop_stokes_pa"] == pytest.approx(s["pressure_drop_pa"], rel=1e-9)
    assert i["pressure_drop_pa"] > i["pressure_drop_stokes_pa"]
    assert i["reynolds_particle"] == pytest.approx(5.34, abs=0.01)


@pytest.mark.slow
def test_fit_curve_recovers_forchheimer():
    u = np.geomspace(0.005, 0.3, 12)
    gr = 1.932e-5 * u / 4e-8 + 1000.0 * 1.2 * u**2
    f = fit_curve(u, gr, viscosity_pa_s=1.932e-5, density_kg_m3=1.2, porosity=0.4,
                  diameter_m=0.0066)
    assert f["permeability_m2"] == pytest.approx(4e-8, rel=1e-9)
    assert f["forchheimer_beta_per_m"] == pytest.approx(1000.0, rel=1e-9)
    assert f["forchheimer_residual"] < 1e-12 and f["d272_residual"] < 0.05


@pytest.mark.slow
@pytest.mark.parametrize("argv, match", [
    (["--velocities", "0,0.1"], "0.0"), (["--velocities", "nan"], "nan"),
    (["--velocities", ""], "empty"), (["--density", "0"], "--density"),
    (["--viscosity", "-1"], "--viscosity"), (["--grain", "barley"],
                                                 "grains with constants: soybean, wheat")])
def test_curve_bad_input_exit_2(argv, match, capsys):
    assert curve.main(["-q"] + argv) == 2
    err = capsys.readouterr().err
    assert match in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
@pytest.mark.parametrize("grain", ["wheat", "corn", "shelled_corn", "sorghum", "rice"])
def test_curve_takes_every_grain_with_d272(grain):
    """The grains with D272 constants (network._grains) are --grain choices."""
    from network.flow import GRAINS
    args = curve.build_parser().parse_args(["--grain", grain])
    assert curve._check_options(args)
    assert set(GRAINS) == {"soybean", "wheat", "shelled_corn", "rough_rice", "sorghum"}


@pytest.mark.slow
def test_curve_writes_points_fits_and_plot(tmp_path):
    js, png = tmp_path / "c.json", tmp_path / "c.png"
    assert curve.main(["-q", "--velocities", "0.005,0.05,0.3", "--json", str(js),
                       "--plot", str(png), "--csv", str(tmp_path / "c.csv")]) == 0
    d = json.loads(js.read_text())
    assert [set(p) >= set(curve.KEYS) for p in d["points"]] == [True] * 3
    for k in ("permeability_m2", "forchheimer_beta_per_m", "d272_a", "d272_b", "ergun_A",
              "ergun_B"):
        assert np.isfinite(d[k])
    assert png.stat().st_size > 1000


@pytest.mark.slow
def test_one_velocity_fits_nothing():
    """Every fit has two constants: a single velocity gives None for all of them (it gave a
    minimum-norm 'k' of 0.015 m^2 before), and the curve's result says so the same way."""
    f = fit_curve([0.01], [5.0], viscosity_pa_s=1.932e-5, density_kg_m3=1.2, porosity=0.4,
                  diameter_m=0.0066)
    assert f and all(v is None for v in f.values())
