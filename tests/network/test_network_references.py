"""Tests for network._references: published tables, series and drag-law conversions.

Sources: Zick & Homsy (1982) J. Fluid Mech. 115:13, Table 2 (simple cubic drag K);
Sangani & Acrivos (1982) Int. J. Multiphase Flow 8:343 (dilute SC series);
van der Hoef, Beetstra & Kuipers (2005) J. Fluid Mech. 528:233 (LBM Stokes drag of random
packings); Kozeny-Carman; Ergun.
"""

import math

import numpy as np
import pytest

from network.validation import (
    ZICK_HOMSY_SC,
    beetstra_permeability,
    beetstra_stokes_drag,
    drag_to_permeability,
    ergun_viscous_permeability,
    kozeny_carman_permeability,
    lattice_permeability,
    sangani_acrivos_sc_drag,
    zick_homsy_sc_drag,
)


def test_zick_homsy_table_values_reproduced():
    # Table 2 of Zick & Homsy (1982), simple cubic: phi -> K
    table = {0.027: 2.008, 0.064: 2.810, 0.125: 4.292, 0.216: 7.442, 0.343: 15.4,
             0.45: 28.1, 0.5236: 42.1}
    for phi, k in table.items():
        assert zick_homsy_sc_drag(phi) == pytest.approx(k, rel=1e-12)


def test_zick_homsy_interpolation_is_monotone_and_bracketed():
    phi = np.linspace(0.01, math.pi / 6, 400)
    K = zick_homsy_sc_drag(phi)
    assert np.all(np.diff(K) > 0)
    # between 0.343 and 0.45 the value lies between the two table entries
    assert 15.4 < zick_homsy_sc_drag(0.4) < 28.1


@pytest.mark.parametrize("phi, k_zh, rel", [(0.027, 2.008, 1e-3), (0.064, 2.810, 1e-3),
                                            (0.125, 4.292, 1e-3), (0.216, 7.442, 1e-2)])
def test_sangani_acrivos_series_matches_zick_homsy_when_dilute(phi, k_zh, rel):
    # two independent sources agree: the dilute series and the boundary-integral table
    assert sangani_acrivos_sc_drag(phi) == pytest.approx(k_zh, rel=rel)


def test_sangani_acrivos_series_fails_when_dense():
    # the series is not for dense arrays: 23 % low at touching (why the table is used there)
    assert sangani_acrivos_sc_drag(0.5236) / 42.1 < 0.8


def test_drag_to_permeability_isolated_sphere_limit():
    # K = 1 (Stokes drag 6 pi mu a U on every sphere): k = mu U / (n F) = 2 a^2 / (9 phi)
    a, phi = 2e-3, 0.01
    n = phi / (4 / 3 * math.pi * a**3)
    assert drag_to_permeability(1.0, phi, a) == pytest.approx(1 / (n * 6 * math.pi * a), rel=1e-12)


def test_sc_touching_permeability():
    # a = 1: k = 2 / (9 * 0.5236 * 42.1) (pi/6 used for phi)
    assert lattice_permeability("sc", math.pi / 6, 1.0) == pytest.approx(
        2 / (9 * (math.pi / 6) * 42.1), rel=1e-9)


@pytest.mark.parametrize("kind", ["bcc", "fcc"])
def test_missing_tables_are_reported_not_invented(kind):
    with pytest.raises(NotImplementedError, match="not found"):
        lattice_permeability(kind, 0.5, 1.0)


def test_beetstra_limits():
    # phi -> 0: F -> 1 (isolated-sphere Stokes drag, F normalised by 3 pi mu d U)
    assert beetstra_stokes_drag(1e-10) == pytest.approx(1.0, abs=1e-4)
    # the dense term is Kozeny-Carman: with F = 10 phi/(1-phi)^2 alone, k equals KC exactly
    phi = np.array([0.55, 0.6, 0.64])
    eps = 1 - phi
    F_kc = 10 * phi / eps**2
    k_kc = eps * 1.0 / (18 * phi * F_kc)
    np.testing.assert_allclose(k_kc, kozeny_carman_permeability(eps, 1.0), rtol=1e-12)
    # the full law: the (1-phi)^2 (1 + 1.5 sqrt(phi)) term adds 1.3-3 % to the drag there
    ratio = kozeny_carman_permeability(eps, 1.0) / beetstra_permeability(phi, 1.0)
    assert np.all((ratio > 1.005) & (ratio < 1.05))


def test_ergun_in_beetstra_normalisation():
    # Ergun's viscous term written as F = 150 phi / (18 (1-phi)^2) (waLBerla
    # DragForceCorrelations.h uses this normalisation) must convert to d^2 eps^3/(150 (1-eps)^2)
    phi = 0.6
    F = 150 * phi / (18 * (1 - phi) ** 2)
    k = (1 - phi) / (18 * phi * F)
    assert k == pytest.approx(ergun_viscous_permeability(1 - phi, 1.0), rel=1e-12)


def test_grain_bed_numbers():
    # porosity 0.40, d = 6.5 mm (soybean-like): KC k = d^2 0.4^3/(180 0.6^2) = 4.17e-8 m^2;
    # the LBM law is below KC by F_KC/F = 37.5 / (37.5 + 0.16 (1 + 1.5 sqrt 0.6)) = 0.99086
    d = 6.5e-3
    assert kozeny_carman_permeability(0.4, d) == pytest.approx(4.1728e-8, rel=1e-4)
    ratio = beetstra_permeability(0.6, d) / kozeny_carman_permeability(0.4, d)
    assert ratio == pytest.approx(37.5 / (37.5 + 0.16 * (1 + 1.5 * math.sqrt(0.6))), rel=1e-12)
    assert ratio == pytest.approx(0.99086, abs=1e-5)


def test_bad_input():
    with pytest.raises(ValueError, match="solid_fraction"):
        zick_homsy_sc_drag(0.6)
    with pytest.raises(ValueError, match="solid_fraction"):
        beetstra_stokes_drag(-0.1)
    with pytest.raises(ValueError, match="porosity"):
        kozeny_carman_permeability(1.2, 1.0)
    with pytest.raises(ValueError, match="unknown lattice"):
        lattice_permeability("hcp", 0.3, 1.0)
