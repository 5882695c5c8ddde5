"""Throat hard cases: every valid triangle of disks gets Q* (possibly 0)
with a status that says which case it was; ordinary throats keep their numbers."""

import csv

import numpy as np
import pytest

import network
import throats
from throats import solve as solve_cli
from throats._mesh import build_geometries

GAP_DELTA = ([2.0, 0.5, 0.5], [2.51, 2.51, 1.2])      # gaps 1-2 and 1-3 equal the closing width
COVERED = ([2.5, 1.0, 1.0], [2.4, 3.0, 2.5])          # disk 1 covers side 12: closed
DEEP_OPEN = ([2.5, 0.3, 0.3], [2.4, 5.0, 4.0])        # disk 1 contains vertex 2, open at vertex 3


def test_gap_equal_to_closing_width_is_solved_and_continuous():
    g = np.array([2.51, 2.51 + 1e-6, 2.51 - 1e-6])
    sol = throats.solve_fem(np.tile(GAP_DELTA[0], (3, 1)), np.c_[g, g, np.full(3, 1.2)])
    assert sol.status.tolist() == ["ok"] * 3, sol.message
    np.testing.assert_allclose(sol.qstar, sol.qstar[1], rtol=1e-3)
    assert sol.qstar[0] == pytest.approx(6.8425e-4, rel=1e-3)


def test_disk_covering_a_side_is_closed_with_zero():
    sol = throats.solve_fem(*COVERED)
    assert (sol.status[0], sol.qstar[0], sol.open_area[0]) == ("closed", 0.0, 0.0)
    assert "cover" in sol.message[0]
    ok, msg = throats.validate_throats(*COVERED)
    assert ok[0] and msg[0] == ""


def test_deep_overlap_with_open_corner_gets_a_positive_qstar():
    sol = throats.solve_fem(*DEEP_OPEN)
    assert sol.status[0] == "ok" and sol.qstar[0] == pytest.approx(0.7697, rel=2e-3)


@pytest.mark.slow
def test_random_deep_overlaps_all_build_a_boundary():
    rng = np.random.default_rng(1)
    s = rng.uniform(0.5, 3, (3000, 3))
    srt = np.sort(s, axis=1)
    s = s[srt[:, 2] < srt[:, 0] + srt[:, 1]]
    r = rng.uniform(0.2, 3, s.shape)
    ok, _ = throats.validate_throats(r, s)
    assert ok.all()                               # every triangle of disks is valid
    rs, ss = throats.canonical_form(r, s)
    assert not [g.error for g in build_geometries(rs, ss) if g.error]


def test_csv_exits_0_when_every_row_has_an_answer(tmp_path):
    src, out = tmp_path / "in.csv", tmp_path / "out.csv"
    with open(src, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["r1", "r2", "r3", "l12", "l13", "l23"])
        for r, s in (GAP_DELTA, COVERED, DEEP_OPEN):
            w.writerow(r + s)
    assert solve_cli.main(["--csv", str(src), "--out", str(out), "--no-progress"]) == 0
    rows = list(csv.DictReader(open(out)))
    assert [x["status"] for x in rows] == ["ok", "closed", "ok"]
    assert all(x["qstar"] != "" for x in rows)


@pytest.mark.slow
def test_ordinary_throats_keep_their_numbers():
    # Q* of the first six of network.sample_throats(500, rng=1) before this change (all 500
    # were compared bit for bit when it was made); rtol 1e-10: the last bits of gmsh's mesh
    # and the sparse solve move with the host CPU (2.5e-12 on an AMD EPYC host)
    r, s = network.sample_throats(500, rng=1)
    sol = throats.solve_fem(r[:6], s[:6])
    np.testing.assert_allclose(sol.qstar, [0.01802273340709571, 0.0024131950863339807,
                                           0.005935162017756895, 0.00922221395079946,
                                           0.007085161350289585, 0.009949641855307953],
                               rtol=1e-10)


@pytest.mark.parametrize("radii, sides", [
    ([1.0, 1.0, 0.01], [2.0, 1.01, 1.01]),          # a fine touching two unit spheres, type d
    ([100.0, 1.0, 1.0], [100.5, 101.2, 2.5]),       # two unit spheres beside a 100x larger one
])
def test_a_fine_is_closed_on_its_own_scale(radii, sides):
    # at a closing width of 0.01 r_bar these lost 8.5 % and 9.8 % of Q* (the fine's passages
    # closed on the large spheres' scale, with an error estimate of 1e-5); now the width scales
    # with the smallest disk below 0.25 r_bar: the same Q* as a 20x narrower width to 1e-4
    a = throats.solve_fem([radii], [sides], rtol=1e-3)
    b = throats.solve_fem([radii], [sides], rtol=1e-5, delta=0.0005)
    assert a.status[0] == "ok" and abs(a.qstar[0] / b.qstar[0] - 1) < 1e-4
    rs, _ = throats.canonical_form([radii], [sides])
    assert throats._solve.closing_width(rs)[0] == pytest.approx(0.01 * rs.min() / 0.25)


def test_solve_fem_takes_any_finite_length_unit():
    # the open area and contact type were computed on the given lengths (their squares overflow
    # from a unit of about 1e155); the CLI worked around it, now solve_fem itself uses r_bar
    ref = throats.solve_fem([[1.0, 0.9, 1.1]], [[2.05, 2.3, 1.95]])
    for scale in (1e-300, 1e300):
        sol = throats.solve_fem([[scale, 0.9 * scale, 1.1 * scale]],
                                [[2.05 * scale, 2.3 * scale, 1.95 * scale]])
        assert sol.qstar[0] == pytest.approx(ref.qstar[0], rel=1e-12)
        assert sol.open_area[0] == pytest.approx(ref.open_area[0], rel=1e-12)
        assert sol.contact_type[0] == ref.contact_type[0] and sol.status[0] == "ok"
