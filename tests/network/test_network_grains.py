"""Pore networks of multi-sphere grains: grain ids, solid pores,
grain diameters, and one-sphere grains reproducing the sphere results."""

import numpy as np
import pytest

from network import (ConductanceOptions, Packing, SampleOptions, random_packing, solve_network,
                     tessellate)
from network.packing import grain_volumes

#: the closed-form Q* and no porosity estimate: what these tests compare needs neither
SHAPE_FACTOR = dict(sample=SampleOptions(porosity_points=0),
                    conductance=ConductanceOptions(policy="shape-factor"))


def _clumps(n=300, seed=3):
    """Five-sphere grains (a centre sphere and four at 0.45 R, radius 0.55 R, random
    orientation) inside the spheres of a random packing: grains never overlap each other."""
    pk = random_packing(n, rng=seed, solid_fraction=0.55, diameter_range_m=(6e-3, 6e-3))
    big = pk.radii[0]
    rng = np.random.default_rng(seed)
    offs = np.array([[0, 0, 0], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, 0, 1.0]]) * 0.45 * big
    rot = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
    c = (pk.centers[:, None, :] + np.einsum("kj,nij->nki", offs, rot)).reshape(-1, 3)
    return Packing(c, np.full(5 * n, 0.55 * big), grain_id=np.repeat(np.arange(n), 5))


@pytest.mark.slow
def test_one_sphere_grains_reproduce_the_sphere_results():
    pk = random_packing(600, rng=2, solid_fraction=0.57)
    as_grains = Packing(pk.centers, pk.radii, grain_id=np.arange(pk.n)[::-1])
    assert as_grains.grain_diameter == pk.grain_diameter == pk.mean_diameter
    assert as_grains.sauter_diameter == pytest.approx(pk.sauter_diameter, rel=1e-15)
    a = solve_network(pk, **SHAPE_FACTOR)
    b = solve_network(as_grains, **SHAPE_FACTOR)
    assert b.permeability_m2 == pytest.approx(a.permeability_m2, rel=1e-12)
    assert not tessellate(as_grains).solid_pores().any()


def test_solid_pores_lie_inside_one_grain():
    cl = _clumps()
    t = tessellate(cl)
    solid = t.solid_pores()
    assert solid.sum() > 0.02 * t.n_pores
    g = cl.grain_id[t.pore_vertices[solid]]
    assert np.all(g == g[:, :1])
    # no solid pore body reaches the sample: every sample pore has a tetrahedron of pore space
    res = solve_network(cl, **SHAPE_FACTOR)
    assert res.check["ok"] and res.permeability_m2 > 0


def test_grain_volume_of_dimers():
    # two unit spheres one radius apart: 2 V - lens = 8 pi/3 - 5 pi/12
    base = 5.0 * np.arange(400)[:, None] * [1, 0, 0]
    centers = np.concatenate([base, base + [1, 0, 0]])
    v = grain_volumes(centers, np.ones(800), np.tile(np.arange(400), 2))
    assert v.mean() == pytest.approx(8 * np.pi / 3 - 5 * np.pi / 12, rel=3e-3)
    assert v.std() / v.mean() < 0.02            # about 1 % per grain, independent grains


@pytest.mark.slow
def test_porosity_of_clumps_counts_the_union_once():
    from network.pores import Region, region_porosity

    cl = _clumps()
    lo = cl.centers.min(axis=0) + 0.01
    hi = cl.centers.max(axis=0) - 0.01
    eps, sd = region_porosity(cl, Region(lo, hi), 2, n_points=200_000)
    # the union of each 5-sphere grain (0.55 R spheres at 0.45 R) is about half the
    # volume of the sphere it sits in (Monte Carlo of grain_volumes), so the bed is far
    # more porous than the 0.45 of the parent packing; a sum of sphere volumes would
    # count the overlaps several times and give a porosity below that
    v_grain = grain_volumes(cl.centers[:5], cl.radii[:5], np.zeros(5), points=2**16)[0]
    v_sum = 5 * 4 / 3 * np.pi * cl.radii[0] ** 3
    assert v_grain < 0.7 * v_sum
    assert 0.6 < eps < 0.8 and sd < 0.002


@pytest.mark.slow
def test_solve_axis_all_reports_the_tensor_and_the_grain_order(tmp_path, capsys):
    import json

    from network import solve as cli
    from network import write_packing_csv

    cl = _clumps(250, seed=5)
    write_packing_csv(cl, tmp_path / "clumps.csv", digits=10)
    code = cli.main([str(tmp_path / "clumps.csv"), "--axis", "all", "--policy", "shape-factor",
                     "--stokes", "--quiet", "--json", str(tmp_path / "out.json")])
    assert code == 0
    out = json.loads((tmp_path / "out.json").read_text())
    kt = out["permeability_tensor_m2"]
    assert [kt[a] for a in ("xx", "yy", "zz")] == [out["by_axis"][a]["permeability_m2"]
                                                   for a in "xyz"]
    assert out["horizontal_to_vertical_resistance"] == pytest.approx(
        kt["zz"] / (0.5 * (kt["xx"] + kt["yy"])))
    # randomly oriented grains: S near 0 (250 grains: standard error about 0.03)
    assert abs(out["orientation_order"]) < 0.12
    assert "long-axis order S" in capsys.readouterr().out


def test_grain_volumes_do_not_depend_on_the_labels_or_the_row_order():
    # the Monte Carlo shift went to the grains in id order: relabelled grains got other volumes,
    # which moved d32, the sample box and k by up to 5e-4 (the grain audit)
    from network.packing import read_packing

    pk = read_packing("network/data/soybean_grains.csv")
    gid = np.asarray(pk.grain_id)
    v = grain_volumes(pk.centers, pk.radii, gid)
    ids = np.unique(gid)
    new = dict(zip(ids, np.random.default_rng(0).permutation(ids.size) * 7 + 100))
    relabel = np.array([new[g] for g in gid])
    rows = np.random.default_rng(1).permutation(len(gid))
    v2 = grain_volumes(pk.centers[rows], pk.radii[rows], relabel[rows])
    by_new = dict(zip(np.unique(relabel), v2))
    assert np.array_equal(v, np.array([by_new[new[g]] for g in ids]))
