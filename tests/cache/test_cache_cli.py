"""cache.lookup and throats.solve CSV output: one meaning of each column."""

import pytest
import csv

import numpy as np

import network
import throats
from cache import lookup as lookup_cli
from throats import solve as solve_cli


def _write(path, r, s):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["r1", "r2", "r3", "l12", "l13", "l23"])
        w.writerows(np.c_[r, s].tolist())


def _read(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.mark.slow
def test_open_area_and_qstar_mean_the_same_in_both_commands(tmp_path):
    r, s = network.sample_throats(8, rng=4)                 # metres
    src = tmp_path / "in.csv"
    _write(src, r, s)
    a, b = tmp_path / "lookup.csv", tmp_path / "solve.csv"
    assert lookup_cli.main(["--db", str(tmp_path / "t.sqlite"), "--csv", str(src), "--out", str(a),
                            "--policy", "shape-factor", "--quiet"]) == 0
    assert solve_cli.main(["--csv", str(src), "--out", str(b), "--method", "shape-factor"]) == 0
    la, sb = _read(a), _read(b)
    area_a = np.array([float(x["open_area"]) for x in la])
    area_b = np.array([float(x["open_area"]) for x in sb])
    np.testing.assert_allclose(area_a, throats.open_area(r, s), rtol=1e-12)   # m², input units
    np.testing.assert_allclose(area_a, area_b, rtol=1e-12)
    assert np.all((area_a > 1e-7) & (area_a < 1e-4))         # mm-sized windows, in m²
    np.testing.assert_allclose([float(x["qstar"]) for x in la],
                               [float(x["qstar"]) for x in sb], rtol=1e-12)


def test_help_states_each_default(capsys):
    for main, text in ((lookup_cli.main, "default table+fe"), (solve_cli.main, "default: finite")):
        try:
            main(["--help"])
        except SystemExit as exc:
            assert exc.code == 0
        assert text in " ".join(capsys.readouterr().out.split())
