"""k and porosity of one region: the inset window's porosity beside the window's k.

``permeability_m2`` is measured in the inset window (1.5 grain diameters in from the lateral
faces, 1 from the ends) when the sample is wide enough; ``porosity`` is then that window's
(exact sphere-region volumes), the whole sample's is ``porosity_sample``, and every number built
on the pair (k/d32^2, Ergun, Kozeny-Carman, the fits, the report's porosity) uses the window's.
"""

from __future__ import annotations

import pytest

from network.flow import (SampleOptions, ergun_gradient, inset_window, kozeny_carman_gradient,
                          solve_network)
from network.packing import default_packing_path, read_packing
from network.pores import region_porosity, sample_region


@pytest.fixture(scope="module")
def scene():
    packing = read_packing(default_packing_path())
    region = sample_region(packing, axis="z")
    return packing, region, solve_network(packing, axis="z", sample=SampleOptions(region=region))


def test_the_window_porosity_is_paired_with_the_window_k(scene):
    packing, region, res = scene
    assert res.sample_estimator == "inset"
    win = inset_window(region, 2, packing.grain_diameter)
    assert win is not None
    d = packing.grain_diameter
    assert win.lo == pytest.approx(region.lo + [1.5 * d, 1.5 * d, d], abs=1e-15)
    assert win.hi == pytest.approx(region.hi - [1.5 * d, 1.5 * d, d], abs=1e-15)
    assert res.porosity == region_porosity(packing, win, 2, n_points=200_000)[0]
    assert res.porosity_sample == region_porosity(packing, region, 2, n_points=200_000)[0]
    # the bundled scene: the window is denser than the sample (its walls loosen the edges)
    assert res.porosity == pytest.approx(0.39399, abs=1e-5)
    assert res.porosity_sample == pytest.approx(0.39904, abs=1e-5)
    c = res.comparisons()
    v, d32, mu = res.velocity_m_s, res.sauter_diameter_m, res.viscosity_pa_s
    assert c["ergun"]["pressure_gradient_pa_per_m"] == pytest.approx(float(ergun_gradient(
        v, porosity=res.porosity, diameter_m=d32, viscosity_pa_s=mu, density_kg_m3=1.2)),
        rel=1e-12)
    assert c["kozeny_carman"]["pressure_gradient_pa_per_m"] == pytest.approx(float(
        kozeny_carman_gradient(v, porosity=res.porosity, diameter_m=d32, viscosity_pa_s=mu)),
        rel=1e-12)
    s = res.summary()
    assert s["porosity"] == res.porosity and s["porosity_sample"] == res.porosity_sample


def test_a_sample_too_narrow_for_the_window_keeps_the_sample_pair(scene):
    packing, region, _ = scene
    d = packing.grain_diameter
    c = 0.5 * (region.lo + region.hi)
    small = type(region)(c - [3 * d, 3 * d, 4 * d], c + [3 * d, 3 * d, 4 * d])
    assert inset_window(small, 2, d) is None
    res = solve_network(packing, axis="z", sample=SampleOptions(region=small))
    assert res.sample_estimator == "whole" and res.porosity == res.porosity_sample
