"""Tests for network._conduit: the conduit resistance integral and the conduit conductance.

Closed forms used: a duct of constant section (R = y h); the slowly-varying-tube correction
integrated by scipy.quad for a conical tube (Manton 1971 second-order lubrication, bounded
form, module docstring); open area and wetted length of an equilateral triangle with three
equal non-touching disks; the exact Stokes permeability of a simple cubic array (Zick & Homsy
1982, Table 2) for the end-to-end check.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from network import Packing, tessellate
from network.conductance import conduit_conductance, section_estimate, side_resistance
from network.packing import lattice_packing
from network.validation import lattice_sample_permeability


def test_constant_section_gives_y_times_length():
    # a section function that does not change along h: R = y0 * min(h, r_max), f = 1
    radii = np.array([[0.5, 0.4, 0.45], [0.5, 0.5, 0.5]])
    sides = np.array([[1.0, 1.1, 1.2], [1.0, 1.0, 1.0]])
    y0 = np.array([300.0, 40.0])
    const = lambda rho, s: np.full(rho.shape[0], 1.0 / 300.0) if s[0, 1] > 1.05 else \
        np.full(rho.shape[0], 1 / 40.0)
    R = side_resistance(radii[:1], sides[:1], [0.3], y0[:1], section_q=const)
    assert R[0] == pytest.approx(300.0 * 0.3, rel=1e-12)
    # beyond the largest sphere radius there is no wall: the integral stops at r_max = 0.5
    R9 = side_resistance(radii[1:], sides[1:], [0.9], y0[1:])
    R5 = side_resistance(radii[1:], sides[1:], [0.5], y0[1:])
    assert R9[0] == R5[0] > 0


def test_second_order_correction_on_a_flared_tube():
    # equivalent tube radius a(h) = a0 (1 + kappa h^2) (flat at the window, as by symmetry):
    # y = 8/(pi a^4), s = 4/3 a'^2, R = int y (1 + s/(1+s)) dh. The section function gets
    # disk radii; h is recovered from rho_1 = sqrt(r^2 - h^2).
    r, a0, kappa, H = 1.0, 0.2, 3.0, 0.7
    a = lambda h: a0 * (1 + kappa * h**2)
    def q_of(rho, s):
        h = np.sqrt(np.maximum(r**2 - rho[:, 0] ** 2, 0))
        return np.pi * a(h) ** 4 / 8
    y0 = np.array([8 / (np.pi * a0**4)])
    def integrand(h):
        s = 4 / 3 * (2 * a0 * kappa * h) ** 2
        return 8 / (np.pi * a(h) ** 4) * (1 + s / (1 + s))
    exact = quad(integrand, 0, H)[0]
    got = [side_resistance([[r, r, r]], [[3.0, 3.0, 3.0]], [H], y0, n_sections=n,
                           section_q=q_of)[0] for n in (8, 64)]
    assert got[1] == pytest.approx(exact, rel=2e-3)
    assert got[0] == pytest.approx(exact, rel=3e-2)
    # the correction is real: first order alone is lower by more than 5 %
    first = quad(lambda h: 8 / (np.pi * a(h) ** 4), 0, H)[0]
    assert exact / first > 1.05


def test_closed_window_and_zero_length():
    R = side_resistance([[0.6, 0.6, 0.6]], [[1.0, 1.0, 1.0]], [0.4, ][:1], [np.inf])
    assert np.isinf(R[0])
    R = side_resistance([[0.4, 0.4, 0.4]], [[1.0, 1.0, 1.0]], [0.0], [10.0])
    assert R[0] == 0.0


def test_section_estimate_closed_form_and_symmetry():
    # Happel's cell model: q = A_tri^2 f(phi) / (2 pi), f = -ln phi - 3/2 + 2 phi - phi^2/2;
    # equilateral side 1, three disks rho = 0.3 (apart): phi = (pi/2 rho^2) / (sqrt3/4)
    rho = 0.3
    At = math.sqrt(3) / 4
    phi = math.pi / 2 * rho**2 / At
    f = -math.log(phi) - 1.5 + 2 * phi - phi**2 / 2
    q = section_estimate([[rho] * 3], [[1.0] * 3])[0]
    assert q == pytest.approx(At**2 * f / (2 * math.pi), rel=1e-12)
    # against FE (throats.solve_fem, rtol 1e-3) on the square-array section, legs 1, equal
    # disks: 0.13473, 0.081426, 0.033472 at rho = 0.05, 0.1, 0.2; the dilute cell model is
    # within 0.7, 1.2, 2.8 % of them (the wetted-perimeter A^3/(2 P^2) is 18, 7.1, 3.2 times off)
    fe = np.array([0.13473, 0.081426, 0.033472])
    rr = np.array([0.05, 0.1, 0.2])
    est = section_estimate(np.repeat(rr[:, None], 3, 1), [[1.0, 1.0, math.sqrt(2)]] * 3)
    np.testing.assert_allclose(est / fe, [0.993, 0.988, 0.972], atol=0.002)
    # vertex relabelling: radii (r1,r2,r3)/sides (l12,l13,l23) -> swap 2<->3
    r_ = np.array([[0.3, 0.4, 0.2]]); s_ = np.array([[1.0, 1.2, 0.9]])
    q1 = section_estimate(r_, s_)
    q2 = section_estimate(r_[:, [0, 2, 1]], s_[:, [1, 0, 2]])
    np.testing.assert_allclose(q1, q2, rtol=1e-12)
    assert np.isinf(section_estimate([[0.0, 0.0, 0.0]], [[1.0, 1.0, 1.0]])[0])


def _cheap_qstar(radii, sides):
    return section_estimate(radii, sides) / np.asarray(radii).mean(axis=1) ** 4


@pytest.mark.parametrize("kind", ["sc", "fcc"])
def test_tie_breaking_spread_is_small_with_merging(kind):
    # exact lattice (Qhull splits every cube / octahedral hole its own way) against three
    # jittered copies (sigma = 1e-3 lattice constant): the permeability spread must be a few
    # per cent (measured: SC 0.6 %, FCC 0.1 %; without merging 3.5 % and 5.9 %)
    # (whole-box estimate: this tests the network construction, and the box averages over
    # 4x more cells than the core estimate, whose own jitter noise is about 1 %)
    ks = [lattice_sample_permeability(kind, 0.45, qstar_fn=_cheap_qstar, n_cells=6,
                                      jitter=j, rng=s, estimator="box")[0]
          for j, s in ((0.0, 0), (1e-3, 1), (1e-3, 2), (1e-3, 3))]
    spread = (max(ks) - min(ks)) / np.mean(ks)
    assert spread < 0.02


def _fe_memo():
    throats = pytest.importorskip("throats")
    memo = {}

    def fe(radii, sides):
        radii = np.asarray(radii); sides = np.asarray(sides)
        sc = radii.mean(axis=1, keepdims=True)
        key = np.round(np.hstack([radii, sides]) / sc, 7)
        u, inv = np.unique(key, axis=0, return_inverse=True)
        todo = [i for i, k in enumerate(map(tuple, u)) if k not in memo]
        if todo:
            sol = throats.solve_fem(u[todo, :3], u[todo, 3:], rtol=2e-3)
            memo.update({tuple(u[i]): q for i, q in zip(todo, sol.qstar)})
        return np.array([memo[tuple(x)] for x in u])[inv.ravel()]
    return fe


#: Conduit model (default settings, exact Q* of every section) / exact Stokes permeability,
#: read in the sample core, for every lattice case of the bench: SC against Zick & Homsy (1982)
#: Table 2, BCC/FCC against network._references.computed_lattice_permeability. Pinned so
#: that a change of the model shows up in every case.
LATTICE_CASES = [
    ("sc", 0.3, 1.099), ("sc", 0.45, 1.092), ("sc", np.pi / 6, 1.087),
    ("bcc", 0.3, 0.871), ("bcc", 0.4, 0.902), ("bcc", 0.5, 0.933), ("bcc", 0.6, 0.969),
    ("bcc", 0.66, 0.989),
    ("fcc", 0.3, 1.020), ("fcc", 0.45, 0.990), ("fcc", 0.55, 0.979), ("fcc", 0.65, 0.994),
    ("fcc", 0.72, 0.997),
]


def _exact_lattice_k(kind, phi, r):
    from network.validation import computed_lattice_permeability, lattice_permeability
    if kind == "sc":
        return lattice_permeability("sc", phi, r)
    return computed_lattice_permeability(kind, phi)


@pytest.mark.slow
def test_every_lattice_case_against_exact_stokes():
    # target: within 10 % from phi = 0.3 to touching. Met in 12 of 13 cases; BCC at
    # phi = 0.3 is 12.9 % low (a known miss, analysed in network._conduit: no per-section
    # correction brings SC and BCC at phi = 0.3 within 10 % together). Asserted as measured,
    # not hidden: if a model change moves it, this test says so.
    fe = _fe_memo()
    got = {}
    for kind, phi, expected in LATTICE_CASES:
        k, r = lattice_sample_permeability(kind, phi, qstar_fn=fe)
        got[(kind, phi)] = ratio = k / _exact_lattice_k(kind, phi, r)
        assert ratio == pytest.approx(expected, abs=0.005), (kind, phi)
    within = [c for c, v in got.items() if abs(v - 1) < 0.10]
    assert len(within) == 12
    assert ("bcc", 0.3) not in within


@pytest.mark.parametrize("phi", [0.45, np.pi / 6])
def test_thesis_model_is_about_half_of_zick_homsy(phi):
    # the thesis model (L = 2 rbar) with the same exact Q*: about half the exact value
    fe = _fe_memo()
    kt, r = lattice_sample_permeability("sc", phi, model="thesis", qstar_fn=fe)
    assert 0.45 < kt / _exact_lattice_k("sc", phi, r) < 0.55


def test_bad_arguments():
    c, r = lattice_packing("sc", 0.3, n_cells=2, lattice_constant_m=1.0)
    tess = tessellate(Packing(c, r))
    with pytest.raises(ValueError, match="sections"):
        conduit_conductance(tess, sections="bogus", qstar_fn=_cheap_qstar)
    with pytest.raises(ValueError, match="viscosity"):
        conduit_conductance(tess, viscosity_pa_s=-1, qstar_fn=_cheap_qstar)
    with pytest.raises(ValueError, match="n_sections"):
        side_resistance([[0.4] * 3], [[1.0] * 3], [0.3], [1.0], n_sections=1)


@pytest.mark.parametrize("kind, phi, box", [("bcc", 0.5, 0.860), ("fcc", 0.55, 0.857)])
def test_bcc_fcc_box_estimate_and_thesis_model(kind, phi, box):
    # BCC/FCC have no literature table here; network._references.computed_lattice_permeability
    # (Taylor-Hood FE in the symmetry cell, checked on SC against Zick & Homsy) is the
    # reference. The whole-box value is 7-14 % below the core value (0.860, 0.857 of exact at
    # 7 cells, against 0.933, 0.979 in the core) only through the sample's boundary layer,
    # which falls as 1/H. The thesis model is 0.34 of exact here.
    fe = _fe_memo()
    k_ref = _exact_lattice_k(kind, phi, None)
    kb, _ = lattice_sample_permeability(kind, phi, qstar_fn=fe, estimator="box")
    assert kb / k_ref == pytest.approx(box, abs=0.01)
    kt, _ = lattice_sample_permeability(kind, phi, model="thesis", qstar_fn=fe)
    assert kt / k_ref < 0.36


#: Conduit model (table Q*, the shipped g1 grid) / the LBM Stokes drag law of van der Hoef,
#: Beetstra & Kuipers (2005), J. Fluid Mech. 528:233, in the sample core: periodic random
#: packings of 800 monodisperse spheres (seed 1), copied 3x3x3.
RANDOM_CASES = [(0.36, 1.054), (0.40, 1.014), (0.45, 1.043)]


@pytest.mark.slow
@pytest.mark.parametrize("porosity, expected", RANDOM_CASES)
def test_random_packings_against_lbm_drag_law(porosity, expected):
    # target: within 10 % of the LBM law for random packings of porosity 0.36-0.45;
    # the thesis model is about a third of it (measured 0.30-0.33)
    from network.validation import random_sample_permeability
    from network.validation import beetstra_permeability
    k_ref = beetstra_permeability(1.0 - porosity, 1.0)
    k = random_sample_permeability(porosity)
    assert k / k_ref == pytest.approx(expected, abs=0.01)
    assert abs(k / k_ref - 1) < 0.10
    if porosity == 0.40:
        kt = random_sample_permeability(porosity, model="thesis")
        assert 0.25 < kt / k_ref < 0.40


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["bcc", "fcc"])
def test_core_estimator_does_not_depend_on_sample_size(kind):
    # a periodic array has one permeability; the core estimate must not drift with the sample
    # size (measured with FE Q*: BCC 0.9308 -> 0.9334, FCC 0.9791 -> 0.9795 from 6 to 11 cells)
    # while the whole-box estimate rises with size through its 1/H boundary layer
    # (BCC 0.837 -> 0.896, FCC 0.817 -> 0.918)
    core = [lattice_sample_permeability(kind, 0.5, qstar_fn=_cheap_qstar, n_cells=n)[0]
            for n in (6, 9)]
    box = [lattice_sample_permeability(kind, 0.5, qstar_fn=_cheap_qstar, n_cells=n,
                                       estimator="box")[0] for n in (6, 9)]
    assert core[1] / core[0] == pytest.approx(1.0, abs=0.005)
    assert box[1] / box[0] > 1.04
    assert box[1] < core[1]
