"""Grain mates in the conduit model (network.conductance._mates): the geometry of the disks
other spheres of a window's grains cut from its sections, sphere packings unchanged, and the
windows they cut on a bed of multi-sphere grains."""

import numpy as np
import pytest

from network import Packing, tessellate
from network.conductance import conduit_conductance
from network.conductance._mates import (grain_mates, mate_radii, window_factors,
                                        window_factors_compiled)
from network.pores import merge_pores
from network.conductance._heights import conduit_heights
from network.packing import read_packing


def test_mate_geometry_in_the_face_frame():
    # face x1 (0,0,0), x2 (2,0,0), x3 (0,2,0), normal +z; a mate of sphere 1's grain at
    # (0.5, 0.4, 0.3), radius 0.5: offset 0.3, disk radius sqrt(0.25 - 0.09) = 0.4 in the
    # face plane, 0.5 at t = 0.3, none beyond t = 0.8
    c = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0.5, 0.4, 0.3], [5, 5, 5.0]])
    pk = Packing(c, [0.6, 0.6, 0.6, 0.5, 0.5], grain_id=[0, 1, 2, 0, 3])
    m = grain_mates(pk, np.array([[0, 1, 2]]), np.array([[0.5, 0.5]]), np.array([[1.0, -1.0]]))
    assert m.rows.tolist() == [0] and m.sphere[0].tolist() == [3]
    np.testing.assert_allclose(m.center[0, 0], [0.5, 0.4], atol=1e-15)
    assert m.offset[0, 0] == pytest.approx(0.3) and m.radius[0, 0] == 0.5
    rho = mate_radii(m, np.array([[0.0, 0.3, -0.5, 0.85]]))[0, 0]
    np.testing.assert_allclose(rho, [0.4, 0.5, 0.0, 0.0], atol=1e-12)
    # a mate of sphere 2's grain at offset 0.6, radius 0.5, spans t in [0.1, 1.1]: outside
    # the window's plane (slab [0, 0]), inside the slab of a half 0.5 high on its side
    pk2 = Packing(np.vstack([c, [1.0, 0.5, 0.6]]), [0.6, 0.6, 0.6, 0.5, 0.5, 0.5],
                  grain_id=[0, 1, 2, 0, 3, 1])
    win = grain_mates(pk2, np.array([[0, 1, 2]]), np.zeros((1, 2)), np.array([[1.0, -1.0]]))
    assert win.sphere[0].tolist() == [3]
    both = grain_mates(pk2, np.array([[0, 1, 2]]), np.array([[0.5, 0.5]]),
                       np.array([[1.0, -1.0]]))
    assert sorted(both.sphere[0].tolist()) == [3, 5]


def _sub_bed(n_grains=40):
    pk = read_packing("network/data/soybean_grains.csv")
    keep = np.isin(pk.grain_id, np.unique(pk.grain_id)[:n_grains])
    return Packing(pk.centers[keep], pk.radii[keep], grain_id=pk.grain_id[keep])


@pytest.mark.parametrize("grains", [False, True])
def test_sphere_packings_are_unchanged(grains):
    # no grain mates: spheres alone, or every sphere its own grain
    rng = np.random.default_rng(3)
    c = rng.random((120, 3)) * 4.0
    pk = Packing(c, np.full(120, 0.45), grain_id=np.arange(120) if grains else None)
    t = tessellate(pk)
    off = conduit_conductance(t, policy="table-only", grain_mates="off")
    for mode in ("window", "all"):
        res = conduit_conductance(t, policy="table-only", grain_mates=mode)
        assert np.array_equal(res.g, off.g)
        key = "n_windows_cut" if mode == "window" else "n_conduits_reached"
        assert res.stats["grain_mates"][key] == 0


def test_grain_mates_lower_only_the_conduits_they_cut():
    t = tessellate(_sub_bed())
    g = {m: conduit_conductance(t, policy="table-only", grain_mates=m) for m in
         ("off", "window")}
    off, win = g["off"].g, g["window"].g
    ok = ~g["off"].internal & (off > 0)
    cut = ok & (win != off)
    # the window loses area, never gains; the taper correction (the slope of y at the first
    # node) can move a conduit the other way by a few per cent (2 of 1619 here)
    assert np.mean(win[ok] <= off[ok]) > 0.995 and np.all(win[ok] <= 1.05 * off[ok])
    assert win[ok].sum() < 0.98 * off[ok].sum()
    assert g["window"].stats["grain_mates"]["n_windows_cut"] == int(np.sum(cut))
    assert 0.1 < cut.sum() / ok.sum() < 0.9
    # the uncut conduits keep their values to the last bit
    assert np.array_equal(win[ok & ~cut], off[ok & ~cut])


def test_the_default_takes_the_mates_out_of_the_windows():
    # conduit_conductance's default is 'window': equal to it to the last bit, and it cuts
    t = tessellate(_sub_bed(20))
    default = conduit_conductance(t, policy="table-only")
    win = conduit_conductance(t, policy="table-only", grain_mates="window")
    assert default.stats["grain_mates"]["mode"] == "window"
    assert default.stats["grain_mates"]["n_windows_cut"] > 0
    assert np.array_equal(default.g, win.g)


def test_compiled_window_loop_equals_the_numpy_path():
    # the window factors by the compiled loop (what conduit_conductance uses) against the
    # numpy path (grain_mates at the face plane, the circle test, throats.section_ratio)
    t = tessellate(_sub_bed())
    idx = np.flatnonzero(~merge_pores(t).internal_throat)
    h, sign = conduit_heights(t, idx, merge_pores(t))
    m = grain_mates(t.packing, t.throat_vertices[idx], 0 * h, sign)
    f_np = np.ones(idx.size)
    f_np[m.rows] = window_factors(m, t.throat_radii[idx][m.rows], t.throat_sides[idx][m.rows])
    f_c = window_factors_compiled(t.packing, t.throat_vertices[idx])
    assert np.sum(f_np < 1) > 100
    np.testing.assert_allclose(f_c, f_np, rtol=1e-11, atol=1e-13)


def test_unknown_mode_is_refused():
    t = tessellate(_sub_bed(10))
    with pytest.raises(ValueError, match="grain_mates"):
        conduit_conductance(t, policy="table-only", grain_mates="yes")


def test_solve_refuses_grain_mates_with_the_thesis_model(capsys):
    from network.solve import main

    assert main(["network/data/soybean_grains.csv", "--grain-mates", "window",
                 "--conductance-model", "thesis", "-q"]) == 2
    err = capsys.readouterr().err
    assert "error: --grain-mates window" in err and "thesis" in err


def test_solve_takes_window_for_the_conduit_model_and_nothing_for_the_thesis_model():
    from network.solve import _check_inputs, build_parser

    args = build_parser().parse_args(["network/data/soybean_grains.csv"])
    assert args.grain_mates is None and args.conductance_model == "conduit"
    thesis = build_parser().parse_args(["network/data/soybean_grains.csv",
                                        "--conductance-model", "thesis"])
    _check_inputs(thesis, ["z"])       # the default asks for no mates of the thesis model
