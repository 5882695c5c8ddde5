"""Inertial validation (issue 14 item 5): the drag laws and the network against them.

Drag laws: Beetstra, van der Hoef & Kuipers (2007) as in OpenFOAM's ``dragModels::Beetstra``;
Hill, Koch & Ladd (2001) dense random-array fit as in MFiX's ``KOCH_HILL`` (Benyahia et al.
2006 coefficients). Network numbers recorded on Finney's packing (cube of 16 radii at its
centre, solid fraction 0.638) at the commit that added this file; tables in
``docs/inertial-flow.md``.
"""

from pathlib import Path

import numpy as np
import pytest

from network.conductance import expansion_coefficient
from network.flow import conduit_flow
from network.validation import (FINNEY_PATH, bed_inertial_case, beetstra_drag,
                                beetstra_stokes_drag, drag_ratio, finney_inertial_case,
                                hill_koch_ladd_drag)


def test_beetstra_stokes_limit_is_the_stokes_law_of_references():
    phi = np.array([0.3, 0.5, 0.6, 0.64])
    np.testing.assert_allclose(beetstra_drag(phi, 0.0), beetstra_stokes_drag(phi), rtol=1e-12)
    np.testing.assert_allclose(beetstra_drag(phi, 1e-9), beetstra_stokes_drag(phi), rtol=1e-6)


def test_beetstra_value_by_hand():
    # phi 0.6, Re 10: F0 = 37.5 + 0.16 (1 + 1.5 sqrt 0.6); F1 by the formula, term by term
    phi, re = 0.6, 10.0
    f0 = 10 * phi / 0.16 + 0.16 * (1 + 1.5 * np.sqrt(phi))
    f1 = (0.413 * re / (24 * 0.16) * (1 / 0.4 + 3 * 0.6 * 0.4 + 8.4 * re**-0.343)
          / (1 + 10**1.8 * re**(-(1 + 2.4) / 2)))
    assert float(beetstra_drag(phi, re)) == pytest.approx(f0 + f1, rel=1e-12)


def test_hill_koch_ladd_is_continuous_at_its_switch_and_quadratic_below():
    phi = 0.6
    f1 = 0.11 + 5.1e-4 * np.exp(11.6 * phi)
    f3 = 0.0673 + 0.212 * phi + 0.0232 / 0.4**5
    re_switch = 2 * f3 / f1                       # Re_a = Re / 2
    lo, hi = hill_koch_ladd_drag(phi, [re_switch * (1 - 1e-9), re_switch * (1 + 1e-9)])
    assert lo == pytest.approx(hi, rel=1e-8)
    f0 = float(hill_koch_ladd_drag(phi, 0.0))
    assert f0 == pytest.approx(10 * phi / 0.4**3)
    excess = hill_koch_ladd_drag(phi, [1.0, 2.0]) - f0
    assert excess[1] / excess[0] == pytest.approx(4.0)      # F1 Re^2: Mei-Auriault onset


def test_drag_ratio_and_bad_input():
    assert float(drag_ratio("beetstra", 0.6, 0.0)) == 1.0
    assert float(drag_ratio("hill_koch_ladd", 0.6, 0.0)) == 1.0
    with pytest.raises(ValueError, match="law must be one of"):
        drag_ratio("ergun", 0.6, 1.0)
    with pytest.raises(ValueError, match="solid_fraction"):
        beetstra_drag(1.2, 1.0)
    with pytest.raises(ValueError, match="reynolds"):
        beetstra_drag(0.6, -1.0)
    with pytest.raises(ValueError, match=">= 0.4"):
        hill_koch_ladd_drag(0.3, 1.0)


def test_onset_law_conduit_flow():
    # dp = q/g + K q|q| X/(Xc + X), X = K g |q|: exact inverse, slope, Re^2 onset
    g, K, xc = np.ones(4), np.full(4, 0.5), 1.0
    dp = np.array([1e-4, 0.1, -1.5, 100.0])
    q, w = conduit_flow(dp, g, K, crossover=xc)
    x = K * g * np.abs(q)
    np.testing.assert_allclose(q / g + K * q * np.abs(q) * x / (xc + x), dp, rtol=1e-12)
    q2, _ = conduit_flow(dp + 1e-7, g, K, crossover=xc)
    np.testing.assert_allclose((q2 - q) / 1e-7, w, rtol=1e-5)
    # low flow: the excess over the viscous drop is (K g q)^2 / Xc of it (Re^2 per conduit)
    excess = (dp[0] - q[0] / g[0]) / (q[0] / g[0])
    assert excess == pytest.approx((K[0] * g[0] * q[0]) ** 2 / xc, rel=1e-3)


def test_expansion_loss_with_the_laminar_profile():
    # momentum + energy balance: K = alpha - 2 beta s + (2 beta - alpha) s^2; Poiseuille tube
    # alpha = 2, beta = 4/3: K(0) = 2 (twice Borda-Carnot), K(1) = 0, K(0.5) = 5/6
    s = np.array([0.0, 0.5, 1.0])
    np.testing.assert_allclose(expansion_coefficient(s, profile="laminar"), [2, 5 / 6, 0],
                               atol=1e-12)
    np.testing.assert_allclose(expansion_coefficient(s), (1 - s) ** 2, atol=1e-12)
    with pytest.raises(ValueError, match="profile must be one of"):
        expansion_coefficient(s, profile="turbulent")


@pytest.mark.skipif(not FINNEY_PATH.exists(), reason="Finney data not available")
def test_finney_against_the_drag_laws_at_three_reynolds_numbers():
    case = finney_inertial_case([2.0, 10.0, 50.0])
    assert case.converged and np.all(case.iterations <= 30)
    assert case.solid_fraction == pytest.approx(0.638, abs=0.005)
    # network k/k_app recorded at this file's commit (quadratic per-conduit law)
    np.testing.assert_allclose(case.k_ratio, [1.0165, 1.0807, 1.3808], rtol=2e-3)
    err = case.error["beetstra"]
    assert abs(err[0]) < 0.02 and abs(err[1]) < 0.02           # issue target, Re_p <= 10
    # known miss (docs/inertial-flow.md): at Re_p 50 the network is ~19 % below Beetstra
    assert err[2] == pytest.approx(-0.189, abs=0.01)
    np.testing.assert_allclose(case.error["hill_koch_ladd"], [0.0094, -0.0571, -0.2021],
                               atol=0.003)


@pytest.mark.skipif(not FINNEY_PATH.exists(), reason="Finney data not available")
def test_finney_onset_law_at_three_reynolds_numbers():
    # laminar expansion profile + Re^2 onset with X_c = 1 (docs/inertial-flow.md): the excess
    # grows like Re^2 at small Re; values recorded at the commit that added this test
    case = finney_inertial_case([1.0, 2.0, 10.0], crossover=1.0, profile="laminar")
    assert case.converged
    excess = case.k_ratio - 1.0
    assert excess[1] / excess[0] == pytest.approx(4.0, rel=0.15)
    np.testing.assert_allclose(case.error["beetstra"], [0.0002, 0.0001, -0.0388], atol=0.002)


BUNDLED = Path(__file__).resolve().parents[1] / "network" / "data" / "soybean_default.csv"


def test_bed_case_cuts_the_interior_box_and_solves_both_axes():
    # the bundled scene (walls, 5.5-7.5 mm): the box 2.5 d32 inside the walls and floor, 3 d32
    # below the surface (the lowest column top); the default law's k/k_app recorded at the
    # commit that added this test (session 17), vertical and horizontal
    from network.flow import DEFAULT_INERTIAL_LAW, INERTIAL_LAWS

    law = INERTIAL_LAWS[DEFAULT_INERTIAL_LAW]
    z = bed_inertial_case(BUNDLED, [1.0, 5.0, 10.0], axis=2, **law)
    x = bed_inertial_case(BUNDLED, [1.0, 5.0, 10.0], axis=0, **law)
    assert z.converged and x.converged and z.solid_fraction == x.solid_fraction
    # exact sphere-region volumes; a Monte Carlo of 2e6 points testing every sphere near each
    # point: 0.6016-0.6022 (testing only the nearest centre, as before session 18, misses the
    # big spheres' points nearer a small sphere's centre: 0.5954-0.5961)
    assert z.solid_fraction == pytest.approx(0.60178, abs=5e-5)
    np.testing.assert_allclose(z.k_ratio, [1.00350, 1.05742, 1.15011], rtol=3e-4)
    np.testing.assert_allclose(x.k_ratio, [1.00358, 1.05740, 1.14825], rtol=3e-4)
    # as the random packings: a few % above Beetstra at Re_p 5-10
    assert np.all(np.diff(z.error["beetstra"]) > 0) and 0.02 < z.error["beetstra"][2] < 0.08


def test_bed_case_refuses_margins_that_leave_no_box():
    with pytest.raises(ValueError, match="no sample box"):
        bed_inertial_case(BUNDLED, [1.0], margin=6.0)


def _mc_script():
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "docs" / "scripts" / "mc_ensemble.py"
    spec = importlib.util.spec_from_file_location("mc_ensemble", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _mc_pair(n, phi, seed, equilibrate):
    """(script module, box side, grown centres, their MC configuration, sweeps) of the
    periodic random packing (n unit spheres, phi, seed), as ``mc_ensemble.py`` makes them."""
    mc = _mc_script()
    side, x0 = mc.grown_configuration(n, phi, seed)
    x1, sweeps = mc.monte_carlo(x0, side, equilibrate=equilibrate, seed=seed,
                                log=lambda *_: None)
    return mc, side, x0, x1, sweeps


def test_monte_carlo_configuration_is_overlap_free_at_diameter_one_and_opens_contacts():
    # docs/scripts/mc_ensemble.py (the packing-ensemble study of docs/inertial-flow.md): from
    # a grown periodic packing (overlaps up to ~1 %), hard-sphere moves reach diameter 1 with
    # no pair closer than 1, fewer pairs near contact, and the same result for the same seed
    mc, side, x0, x1, sweeps = _mc_pair(100, 0.55, 3, 300)
    assert np.sqrt(mc._min_dist2(x0, side)) < 1.0 <= np.sqrt(mc._min_dist2(x1, side))
    assert x1.min() >= 0.0 and x1.max() < side and sweeps > 300
    assert mc._gaps(x1, side)[0] < 0.7 * mc._gaps(x0, side)[0]     # 4.66 -> 2.76 per sphere
    x2, _ = mc.monte_carlo(x0, side, equilibrate=300, seed=3, log=lambda *_: None)
    assert np.array_equal(x1, x2)


#: Resolved flow (lattice-Boltzmann, D 24, CPU, session 17; docs/data/lbm_mc100_reference.json)
#: of the 100-sphere packing phi 0.55 seed 1 and of its hard-sphere Monte Carlo configuration
LBM100 = {"grown": ([4.8963, 9.7288], [1.0492, 1.1290]),
          "mc": ([4.9628, 10.0149], [1.0350, 1.0968])}
#: the network's k/k_app on the same two configurations, recorded when the test was added
NETWORK100 = {"grown": [1.0622, 1.1573], "mc": [1.0421, 1.1197]}


def test_beetstra_holds_on_its_own_kind_of_packing_and_the_network_follows_the_lbm():
    # issue 14 item 5 (docs/inertial-flow.md, "the packing ensemble"): Beetstra's law was fitted
    # on Monte Carlo hard-sphere configurations; on one the resolved flow follows it within
    # 0.8 % and the network is within 2 % of both; on the contact-rich grown packing the
    # resolved flow itself is 3.2 % above the law at Re_p 10
    from network.flow import DEFAULT_INERTIAL_LAW, INERTIAL_LAWS

    mc, side, x0, x1, _ = _mc_pair(100, 0.55, 1, 8000)
    law = INERTIAL_LAWS[DEFAULT_INERTIAL_LAW]
    for name, x in (("grown", x0), ("mc", x1)):
        re, lbm = (np.array(v) for v in LBM100[name])
        ratio, beet_err, _, converged = mc.network_ratio(x, side, 0.55, law, reynolds=re)
        lbm_vs_beet = lbm / np.asarray(drag_ratio("beetstra", 0.55, re)) - 1.0
        np.testing.assert_allclose(ratio, NETWORK100[name], rtol=3e-4)
        assert converged and np.all(np.abs(ratio / lbm - 1.0) < 0.026)
        if name == "mc":
            assert np.all(np.abs(lbm_vs_beet) < 0.008) and np.all(np.abs(beet_err) < 0.02)
        else:
            assert lbm_vs_beet[1] > 0.03 and beet_err[1] > 0.05


#: Resolved flow (lattice-Boltzmann, D 40, H200, session 18; docs/data/lbm_mc800_reference.json)
#: of the 800-sphere phi 0.55 seed 1 packing's Monte Carlo configuration (2 000 sweeps at d = 1)
LBM800_MC = ([4.9431, 9.9378, 20.2394, 51.5422], [1.0391, 1.1053, 1.2535, 1.6804])
#: the network's k/k_app on that configuration, recorded when the test was added
NETWORK800_MC = [1.0437, 1.1218, 1.2962, 1.8117]        # 1.2960, 1.8111 before session 21's
#                                                          lookup order (cache/_order.py)


def test_network_on_an_800_sphere_monte_carlo_configuration_against_its_resolved_flow():
    # issue 14 item 5: on a Beetstra-type configuration of 800 spheres the resolved flow is
    # within 1.2 % of the law at Re_p <= 10 and the network within 1.6 % of the resolved flow;
    # at Re_p 50 the network is 7.8 % above it (the known overshoot on contact-poor packings,
    # docs/inertial-flow.md "Session 18"; 2.7 % on the grown packing of the same seed)
    from network.flow import DEFAULT_INERTIAL_LAW, INERTIAL_LAWS

    mc, side, _, x1, sweeps = _mc_pair(800, 0.55, 1, 2000)
    assert sweeps == 3068 and abs(mc._gaps(x1, side)[0] - 1.1975) < 1e-9
    re, lbm = (np.array(v) for v in LBM800_MC)
    ratio, _, _, converged = mc.network_ratio(x1, side, 0.55, INERTIAL_LAWS[DEFAULT_INERTIAL_LAW],
                                              reynolds=re)
    np.testing.assert_allclose(ratio, NETWORK800_MC, rtol=3e-4)
    lbm_vs_beet = lbm / np.asarray(drag_ratio("beetstra", 0.55, re)) - 1.0
    assert converged and np.all(np.abs(lbm_vs_beet[:2]) < 0.013)
    assert np.all(np.abs(ratio[:2] / lbm[:2] - 1.0) < 0.016)
    assert 0.06 < ratio[3] / lbm[3] - 1.0 < 0.08
