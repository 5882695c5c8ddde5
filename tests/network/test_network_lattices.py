"""Tests for network._lattices: sphere counts, solid fractions, touching limits (closed forms)."""

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from network.packing import (
    LATTICES,
    SPHERES_PER_CELL,
    TOUCHING_FRACTION,
    lattice_packing,
    lattice_radius,
)


@pytest.mark.parametrize("kind", LATTICES)
@pytest.mark.parametrize("phi", [0.1, 0.3, 0.5])
def test_solid_fraction_of_box_matches_request(kind, phi):
    # m spheres of volume 4/3 pi r^3 per cell of volume a^3 (exact by construction)
    a, n = 2e-3, 3
    c, r = lattice_packing(kind, phi, n_cells=n, lattice_constant_m=a)
    assert c.shape == (SPHERES_PER_CELL[kind] * n**3, 3)
    vol = np.sum(4.0 / 3.0 * np.pi * r**3)
    assert vol / (n * a) ** 3 == pytest.approx(phi, rel=1e-12)
    assert np.all(c >= 0) and np.all(c < n * a)


@pytest.mark.parametrize(
    "kind, closed_form, nn",
    [("sc", math.pi / 6, 1.0), ("bcc", math.sqrt(3) * math.pi / 8, math.sqrt(3) / 2),
     ("fcc", math.sqrt(2) * math.pi / 6, 1 / math.sqrt(2))],
)
def test_touching_fraction_closed_forms(kind, closed_form, nn):
    assert TOUCHING_FRACTION[kind] == pytest.approx(closed_form, rel=1e-15)
    a = 1.5e-3
    c, r = lattice_packing(kind, TOUCHING_FRACTION[kind], n_cells=3, lattice_constant_m=a)
    d, _ = cKDTree(c).query(c, k=2)
    # nearest-neighbour distance a*nn equals the diameter at touching
    np.testing.assert_allclose(d[:, 1], nn * a, rtol=1e-12)
    np.testing.assert_allclose(2 * r, nn * a, rtol=1e-12)


def test_coordination_numbers():
    # touching SC/BCC/FCC: 6, 8, 12 contacts for an interior sphere
    for kind, z in (("sc", 6), ("bcc", 8), ("fcc", 12)):
        c, r = lattice_packing(kind, TOUCHING_FRACTION[kind], n_cells=4, lattice_constant_m=1.0)
        tree = cKDTree(c)
        centre = np.argmin(np.linalg.norm(c - 2.0, axis=1))
        nb = tree.query_ball_point(c[centre], 2 * r[0] * (1 + 1e-9))
        assert len(nb) - 1 == z


def test_far_faces_and_origin():
    c, _ = lattice_packing("bcc", 0.3, n_cells=2, include_far_faces=True,
                           lattice_constant_m=1.0, origin_m=(1, 2, 3))
    assert c.shape == (27 + 8, 3)
    np.testing.assert_allclose(c.min(0), [1, 2, 3])
    np.testing.assert_allclose(c.max(0), [3, 4, 5])
    # mirror symmetry about the box centre
    mirrored = 2 * np.array([2.0, 3.0, 4.0]) - c
    d, _ = cKDTree(c).query(mirrored)
    assert d.max() < 1e-12


def test_jitter_is_seeded_and_sized():
    c0, _ = lattice_packing("fcc", 0.4, n_cells=4, lattice_constant_m=1.0)
    c1, _ = lattice_packing("fcc", 0.4, n_cells=4, lattice_constant_m=1.0, jitter=1e-3, rng=7)
    c2, _ = lattice_packing("fcc", 0.4, n_cells=4, lattice_constant_m=1.0, jitter=1e-3,
                            rng=np.random.default_rng(7))
    np.testing.assert_array_equal(c1, c2)
    dev = (c1 - c0).ravel()
    assert dev.std() == pytest.approx(1e-3, rel=0.1)  # 768 samples: std within ~3 %


def test_radius_units_and_bad_input():
    assert lattice_radius("sc", math.pi / 6, lattice_constant_m=4.0) == pytest.approx(2.0)
    with pytest.raises(ValueError, match="touching"):
        lattice_radius("sc", 0.6)
    with pytest.raises(ValueError, match="unknown lattice"):
        lattice_radius("hcp", 0.3)
    with pytest.raises(ValueError, match="n_cells"):
        lattice_packing("sc", 0.3, n_cells=0)
    with pytest.raises(ValueError, match="jitter"):
        lattice_packing("sc", 0.3, jitter=-1.0)
    with pytest.raises(TypeError):
        lattice_radius(3, 0.3)


def test_core_estimator_arguments():
    from network.flow import core_permeability
    from network.validation import lattice_sample_permeability
    with pytest.raises(ValueError, match="estimator"):
        lattice_sample_permeability("sc", 0.3, estimator="bogus")
    # SC with 6 cells: the core (one lattice constant in from each face) holds one pore plane
    with pytest.raises(ValueError, match="two distinct pore positions"):
        lattice_sample_permeability("sc", 0.3, n_cells=6, qstar_fn=lambda r, s: np.ones(len(r)))

    class _S:  # a chain of 4 pores along x, spacing 0.8/3, in the region [0, 1]^3
        axis = 0
        region = type("R", (), {"lo": np.zeros(3), "hi": np.ones(3)})()
        pore_xyz = np.column_stack([0.1 + np.arange(4) * 0.8 / 3, np.full(4, 0.5),
                                    np.full(4, 0.5)])
        conns = np.array([[0, 1], [1, 2], [2, 3]])
    g, p = np.ones(3), np.array([3.0, 2.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="margin_m"):
        core_permeability(_S(), g, p, margin_m=0.0)
    with pytest.raises(ValueError, match="no core"):
        core_permeability(_S(), g, p, margin_m=0.6)
    # unit flow through every plane, gradient 1/(0.8/3) from the two core pores, core
    # 0.6 x 0.6: k = mu Q / (A G) = 1 / (0.36 * 3.75) (Darcy's law, exact for this chain)
    k = core_permeability(_S(), g, p, margin_m=0.2)
    assert k == pytest.approx(1.0 / (0.36 * 3.75), rel=1e-12)
