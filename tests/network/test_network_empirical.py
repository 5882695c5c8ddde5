"""Empirical comparisons and the docstring examples of network's own modules."""

import doctest
import importlib

import numpy as np
import pytest

from network.flow import (asabe_d272_gradient, darcy_permeability, ergun_gradient,
                                kozeny_carman_gradient)
from network.pores import region_porosity
from network.pores import Region
from network import Packing


def test_thesis_table_4_5_empirical_values():
    """Thesis 4.2.3 / Table 4.5, 0.25 m bed: Ergun 1.27 Pa and ASABE 2.28 Pa at 0.013 m/s,
    2.90 and 5.18 Pa at 0.027 m/s (d = 6.5 mm, porosity 0.408, air 1.932e-5 Pa s, 1.20 kg/m3)."""
    for v, ergun, asabe in ((0.013, 1.27, 2.28), (0.027, 2.90, 5.18)):
        assert round(0.25 * ergun_gradient(v, porosity=0.408, diameter_m=6.5e-3), 2) == ergun
        assert round(0.25 * asabe_d272_gradient(v), 2) == asabe


def test_kozeny_carman_is_ergun_viscous_term_times_1_2():
    kc = kozeny_carman_gradient(0.01, porosity=0.4, diameter_m=5e-3)
    viscous = ergun_gradient(0.01, porosity=0.4, diameter_m=5e-3, density_kg_m3=0.0)
    np.testing.assert_allclose(kc / viscous, 180 / 150)


def test_darcy_roundtrip():
    k = darcy_permeability(2e-6, 3.0, 0.1, 0.01, viscosity_pa_s=1.8e-5)
    np.testing.assert_allclose(1.8e-5 * 2e-6 / 0.01 / k * 0.1, 3.0)


@pytest.mark.parametrize("fn, kw", [
    (ergun_gradient, dict(porosity=1.2, diameter_m=1e-3)),
    (kozeny_carman_gradient, dict(porosity=0.4, diameter_m=-1.0)),
])
def test_bad_values(fn, kw):
    with pytest.raises(ValueError):
        fn(0.01, **kw)


def test_monte_carlo_porosity_of_one_sphere_in_a_box():
    """One sphere of radius 0.5 centred in a unit box: porosity 1 - pi/6 (within 4 sigma)."""
    pk = Packing(np.array([[0.5, 0.5, 0.5], [5, 5, 5], [6, 5, 5], [5, 6, 5], [5, 5, 6.0]]),
                 np.full(5, 0.5))
    eps, err = region_porosity(pk, Region([0, 0, 0], [1, 1, 1]), 2, method="monte-carlo",
                                n_points=100_000, rng=3)
    assert abs(eps - (1 - np.pi / 6)) < 4 * err
    assert 0.001 < err < 0.002


@pytest.mark.parametrize("mod", ["network.flow._empirical", "network.flow._linear", "network.conductance._thesis",
                                 "network.pores._tessellation"])
def test_docstring_examples(mod):
    res = doctest.testmod(importlib.import_module(mod), optionflags=doctest.ELLIPSIS)
    assert res.failed == 0 and res.attempted > 0
