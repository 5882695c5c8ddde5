"""Part 1 of ``python -m network.bench``: every conductance model × Q* policy on one packing.

A 150-sphere periodic packing with the two cheap policies (shape-factor, table-only) and both
models, the default table pointed at a missing file: every row's k is what ``solve_network``
gives directly, the printed lines follow the rows, no policy creates the default table, and with
no fe-only column there is no difference to report.
"""

import json

import pytest

from network import bench
from network.benchmarks import policy_lines
from network.flow import ConductanceOptions, SampleOptions, solve_network
from network.packing import random_packing

N = 150


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bench-policies")
    out = tmp / "policies.json"
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("GRAINFLOW_CACHE_DB", str(tmp / "missing.sqlite"))
        rc = bench.main(["--policy-spheres", str(N), "--policies", "shape-factor", "table-only",
                         "--models", "conduit", "thesis", "--sizes", "--skip-references",
                         "--json", str(out)])
    assert rc == 0
    assert not (tmp / "missing.sqlite").exists()   # copies only, never the default table
    return tmp, json.loads(out.read_text())


def test_rows_and_json(run):
    tmp, report = run
    assert set(report) == {"machine_start", "machine_end", "policies"}
    pol = report["policies"]
    assert pol["n_spheres"] == N and pol["seed"] == 1
    assert pol["table"] == str(tmp / "missing.sqlite")
    assert [(r["conductance_model"], r["policy"]) for r in pol["rows"]] == [
        ("conduit", "shape-factor"), ("conduit", "table-only"),
        ("thesis", "shape-factor"), ("thesis", "table-only")]
    for r in pol["rows"]:
        assert "error" not in r, r
        assert r["seconds"] > 0 and r["conductance_s"] > 0 and r["n_throats"] > 0
        assert "rel_diff_vs_fe_only" not in r   # no fe-only column to compare with
        assert sum(r["sources"].values()) > 0


def test_k_equals_the_pipeline_directly(run, tmp_path):
    _, report = run
    pk = random_packing(N, rng=1, periodic=True, solid_fraction=0.60)
    for r in report["policies"]["rows"]:
        res = solve_network(pk, axis="z", sample=SampleOptions(porosity_points=0),
                            conductance=ConductanceOptions(model=r["conductance_model"],
                                                           policy=r["policy"],
                                                           db=tmp_path / "t.sqlite"))
        assert r["permeability_m2"] == pytest.approx(res.permeability_m2, rel=1e-9)


def test_printed_lines(run):
    _, report = run
    lines = policy_lines(report["policies"])
    assert len(lines) == 4
    assert lines[0].split(":")[0].split() == ["conduit", "shape-factor"]
    assert "vs fe-only" not in "".join(lines)
    err = {"rows": [{"conductance_model": "thesis", "policy": "fe-only", "error": "X: y"}]}
    assert policy_lines(err) == [f"  {'thesis':>8s} {'fe-only':>13s}: X: y"]
