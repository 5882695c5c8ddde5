"""One packing-reader contract for every command: dem's reader (``dem.vibrate``, the
vibration study) reads and refuses the same files as ``network.read_packing``, naming the same
row; ``dem.vibrate`` turns each refusal into one ``error:`` line and exit 2.

dem imports no other project package, so it keeps its own reader; this test is what keeps the
two one contract. (network also refuses fewer than 5 spheres, which it cannot tessellate; dem
can vibrate them.)
"""

import json

import numpy as np
import pytest

import dem
import network
from dem import vibrate

GOOD = "".join(f"{i * 0.01},{(i % 3) * 0.01},{(i % 2) * 0.01},0.004\n" for i in range(8))


def _write(tmp_path, name, text):
    p = tmp_path / name
    (p.write_bytes if isinstance(text, bytes) else p.write_text)(text)
    return p


READ_ALIKE = {
    "header x,y,z,r": "x,y,z,r\n" + GOOD,
    "no header": GOOD,
    "diameter, other order, extra column": "id,d,z,y,x\n" + "".join(
        f"{k},{float(ln.split(',')[3]) * 2},{ln.split(',')[2]},{ln.split(',')[1]},{ln.split(',')[0]}\n"
        for k, ln in enumerate(GOOD.splitlines())),
    "YADE export.text": "# x y z r\n# exported\n" + GOOD.replace(",", "\t"),
    "semicolons": "x;y;z;radius\n" + GOOD.replace(",", ";"),
    "one sphere per grain": "x,y,z,r,grain_id\n" + "".join(
        f"{ln},{k}\n" for k, ln in enumerate(GOOD.splitlines())),
}


@pytest.mark.parametrize("name", sorted(READ_ALIKE))
def test_both_readers_read_the_same_spheres(tmp_path, name):
    p = _write(tmp_path, "bed.csv", READ_ALIKE[name])
    c, r, summary = dem.read_packing(p)
    pk = network.read_packing(p)
    np.testing.assert_array_equal(c, pk.centers)
    np.testing.assert_array_equal(r, pk.radii)
    np.testing.assert_allclose(r, 0.004, rtol=1e-12)
    assert summary is None


def test_npz_read_alike_with_its_summary(tmp_path):
    rows = np.loadtxt(GOOD.splitlines(), delimiter=",")
    p = tmp_path / "bed.npz"
    np.savez(p, centers=rows[:, :3], radii=rows[:, 3])
    (tmp_path / "bed.json").write_text(json.dumps({"container": {"kind": "box", "size_m": [1, 1],
                                                                 "fill_height_m": 1}}))
    c, r, summary = dem.read_packing(p)
    np.testing.assert_array_equal(c, network.read_packing(p).centers)
    assert summary["container"]["kind"] == "box"


BAD = {  # file name, content, the words both messages carry
    "empty": ("bed.csv", "# nothing\n\n", "empty file"),
    "header only": ("bed.csv", "x,y,z,r\n", "no data row after the header"),
    "missing column": ("bed.csv", "x,y,r\n" + GOOD, "row 1: header 'x,y,r' lacks column(s) ['z']"),
    "NaN": ("bed.csv", "x,y,z,r\n" + "\n".join(
        ln.rsplit(",", 1)[0] + ",nan" if k == 2 else ln for k, ln in enumerate(GOOD.splitlines())),
        "row 4: non-finite"),
    "inf centre": ("bed.csv", "x,y,z,r\n" + GOOD + "inf,0,0,0.004\n", "row 10: non-finite"),
    "zero radius": ("bed.csv", "x,y,z,r\n" + GOOD + "1,1,1,0\n", "row 10: radius must be > 0"),
    "duplicate centre": ("bed.csv", "x,y,z,r\n" + GOOD + GOOD.splitlines()[2] + "\n",
                         "row 10: duplicate centre"),
    "not a number": ("bed.csv", "x,y,z,r\n" + GOOD + "1,a,1,0.004\n", "row 10: not a number"),
    "short row": ("bed.csv", "x,y,z,r\n" + GOOD + "1,1,0.004\n", "row 10: expected 4 values"),
    "binary": ("bed.csv", b"\x00\x01\x02binary", "a binary file"),
    "npz not a zip": ("bed.npz", "x,y,z,r\n" + GOOD, ".npz"),
    "npz keys": ("bed.npz", None, "missing array(s) ['radii']"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_both_readers_refuse_the_same_files_naming_the_row(tmp_path, name):
    fname, text, words = BAD[name]
    if text is None:
        p = tmp_path / fname
        np.savez(p, centers=np.zeros((8, 3)))
    else:
        p = _write(tmp_path, fname, text)
    with pytest.raises(ValueError) as e_dem:
        dem.read_packing(p)
    with pytest.raises(ValueError) as e_net:
        network.read_packing(p)
    assert words in str(e_dem.value) and words in str(e_net.value), (e_dem.value, e_net.value)
    assert str(p) in str(e_dem.value)


def test_dem_refuses_multi_sphere_grains_it_cannot_move(tmp_path):
    text = "x,y,z,r,grain_id\n0,0,0,0.004,7\n0.005,0,0,0.004,7\n" + "".join(
        f"{ln},{k}\n" for k, ln in enumerate(GOOD.splitlines()[2:]))
    p = _write(tmp_path, "bed.csv", text)
    with pytest.raises(ValueError, match=r"row 2: grain_id 7 is on 2 spheres: multi-sphere grains"):
        dem.read_packing(p)
    assert network.read_packing(p).n_grains == 7        # network reads them: one solid grain


@pytest.mark.parametrize("case, words", [
    ("NaN", "row 4: non-finite"),
    ("duplicate centre", "row 10: duplicate centre"),
    ("npz keys", "missing array(s) ['radii']"),
    ("missing file", "packing file not found"),
    ("unknown container kind", "container kind must be 'box' or 'cylinder', got 'cone'"),
    ("container without size", "is not a box or cylinder with size_m"),
])
def test_vibrate_bad_packing_exit_2_one_line(tmp_path, capsys, case, words):
    """Before: NaN and duplicate centres ended as an energy blow-up, an .npz as a KeyError
    traceback, an unknown container kind as a traceback."""
    out = tmp_path / "out"
    if case in BAD:
        fname, text, _ = BAD[case]
        p = tmp_path / fname
        np.savez(p, centers=np.zeros((8, 3))) if text is None else p.write_text(text)
    elif case == "missing file":
        p = tmp_path / "nothere.csv"
    else:
        p = _write(tmp_path, "bed.csv", "x,y,z,r\n" + GOOD)
        cont = {"kind": "cone", "size_m": [0.1], "fill_height_m": 0.1}
        if case == "container without size":
            cont = {"kind": "box", "fill_height_m": 0.1}
        (tmp_path / "bed.json").write_text(json.dumps({"container": cont}))
    code = vibrate.main([str(p), "--amplitude", "0.001", "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: ") and words in err[0], err
    assert not out.exists()
