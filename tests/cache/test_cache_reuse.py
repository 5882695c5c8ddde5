"""Throats exported by network.throatlist and precomputed by cache.precompute are reused exactly
by cache.lookup_qstar and network.solve: one signature, one rounding."""

import json

import numpy as np
import pytest

import network
import throats
from cache import lookup_qstar, precompute as precompute_cli, shape_keys, signature
from network import solve as solve_cli, throatlist as throats_cli


def _no_fe(*a, **kw):
    raise AssertionError("FE must not run: every shape is stored")


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    d = tmp_path_factory.mktemp("reuse")
    bed = d / "bed.csv"
    network.write_packing_csv(network.random_packing(150, rng=3, max_sweeps=300), bed)
    out = d / "throats.csv"
    assert throats_cli.main([str(bed), "--out", str(out), "--quiet"]) == 0
    db = d / "t.sqlite"
    assert precompute_cli.main(["--db", str(db), "--csv", str(out), "--quiet"]) == 0
    return bed, out, db


@pytest.mark.slow
def test_exported_lengths_round_trip_bit_for_bit(scene):
    bed, out, _ = scene
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    tess = network.tessellate(network.read_packing(bed))
    idx = rows[:, 6].astype(int)
    np.testing.assert_array_equal(rows[:, :3], tess.throat_radii[idx])
    np.testing.assert_array_equal(rows[:, 3:6], tess.throat_sides[idx])
    k_csv = shape_keys(signature(rows[:, :3], rows[:, 3:6]))
    k_net = shape_keys(signature(tess.throat_radii[idx], tess.throat_sides[idx]))
    np.testing.assert_array_equal(k_csv, k_net)


@pytest.mark.slow
def test_precomputed_throats_are_exact_hits(scene):
    _, out, db = scene
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    res = lookup_qstar(rows[:, :3], rows[:, 3:6], db=db, policy="table+fe",
                       solver=_no_fe, solver_version=throats.SOLVER_VERSION)
    assert len(rows) > 50
    assert set(res.source) <= {"exact", "closed"}
    assert res.stats["n_fe"] == 0


@pytest.mark.slow
def test_network_solve_thesis_runs_no_fe(scene, tmp_path):
    bed, out, db = scene
    js = tmp_path / "s.json"
    assert solve_cli.main([str(bed), "--policy", "table+fe", "--db", str(db), "--stokes",
                           "--conductance-model", "thesis", "--json", str(js), "--quiet"]) == 0
    q = json.loads(js.read_text())["qstar"]
    n = sum(1 for _ in open(out)) - 1
    assert q["n_fe"] == 0 and q["sources"] == {"exact": n}
