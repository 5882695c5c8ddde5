"""read_packing: formats and the messages for bad input."""

import numpy as np
import pytest

from network import Packing, read_packing, write_packing_csv

RNG = np.random.default_rng(7)
C = RNG.random((12, 3))
R = 0.05 + 0.01 * RNG.random(12)


def test_csv_roundtrip(tmp_path):
    p = tmp_path / "a.csv"
    write_packing_csv(Packing(C, R), p, digits=17)
    pk = read_packing(p)
    np.testing.assert_array_equal(pk.centers, C)
    np.testing.assert_array_equal(pk.radii, R)


def test_csv_column_order_and_extra_columns(tmp_path):
    p = tmp_path / "b.csv"
    lines = ["id,r,z,y,x"] + [f"{i},{float(R[i])!r},{float(C[i,2])!r},{float(C[i,1])!r},{float(C[i,0])!r}" for i in range(12)]
    p.write_text("\n".join(lines) + "\n")
    pk = read_packing(p)
    np.testing.assert_array_equal(pk.centers, C)
    np.testing.assert_array_equal(pk.radii, R)


def test_npz(tmp_path):
    p = tmp_path / "c.npz"
    np.savez(p, centers=C, radii=R)
    pk = read_packing(p)
    np.testing.assert_array_equal(pk.centers, C)


def test_lammps_dump(tmp_path):
    p = tmp_path / "dump.liggghts"
    rows = "\n".join(f"{i + 1} 1 {float(C[i,0])!r} {float(C[i,1])!r} {float(C[i,2])!r} 0 0 0 {float(R[i])!r}" for i in range(12))
    snap = ("ITEM: TIMESTEP\n{t}\nITEM: NUMBER OF ATOMS\n12\nITEM: BOX BOUNDS ff ff ff\n"
            "0 1\n0 1\n0 1\nITEM: ATOMS id type x y z vx vy vz radius\n")
    # two snapshots: the last one is read
    first = rows.replace(" 1 0.", " 1 9.", 1)
    p.write_text(snap.format(t=0) + first + "\n" + snap.format(t=100) + rows + "\n")
    pk = read_packing(p)
    np.testing.assert_array_equal(pk.centers, C)
    np.testing.assert_array_equal(pk.radii, R)


@pytest.mark.parametrize("bad, match", [
    ("x,y,z,r\n" + "0,0,0,1\n" * 0 + "".join(f"{i},0,0,1\n" for i in range(5)) + "5,0,nan,1\n",
     "row 7: non-finite"),
    ("x,y,z,r\n" + "".join(f"{i},0,0,1\n" for i in range(5)) + "5,0,0,-1\n", "row 7: radius must be > 0"),
    ("x,y,z,r\n" + "".join(f"{i},0,0,1\n" for i in range(5)) + "2,0,0,1\n", "row 7: duplicate centre"),
    ("x,y,z,r\n" + "".join(f"{i},0,0,1\n" for i in range(5)) + "5,0,abc,1\n", "row 7: not a number"),
    ("x,y,z,r\n" + "".join(f"{i},0,0,1\n" for i in range(5)) + "5,0,1\n", "row 7: expected 4 values"),
    ("x,y,z,r\n0,0,0,1\n1,0,0,1\n", "too few spheres"),
    ("a,b,c\n1,2,3\n", "lacks column"),
    # blank and comment lines among the rows: the file's line numbers still
    ("# yade\nx,y,z,r\n\n" + "".join(f"{i},0,0,1\n# c\n" for i in range(5)) + "5,0,0,-1\n",
     "row 14: radius must be > 0"),
    ("x y z r\n" + "".join(f"{i} 0 0 1  # inline\n" for i in range(5)) + "\n\n5 0 nan 1\n",
     "row 9: non-finite"),
    ("x,y,z,r\n\n# only a comment\n", "no data row after the header"),
])
def test_bad_csv_messages(tmp_path, bad, match):
    p = tmp_path / "bad.csv"
    p.write_text(bad)
    with pytest.raises(ValueError, match=match):
        read_packing(p)


def test_missing_file():
    with pytest.raises(FileNotFoundError):
        read_packing("/nonexistent/packing.csv")


def test_packing_shape_checks():
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        Packing(np.zeros((4, 2)), np.ones(4))
    with pytest.raises(ValueError, match="radii must have shape"):
        Packing(np.zeros((4, 3)), np.ones(3))


def _rows(sep):
    return [sep.join(repr(float(v)) for v in (*C[i], R[i])) for i in range(12)]


@pytest.mark.parametrize("sep", [" ", "\t", ";", "  \t "])
def test_whitespace_tab_and_semicolon_files(tmp_path, sep):
    p = tmp_path / "a.txt"
    p.write_text("\n".join(_rows(sep)) + "\n")
    pk = read_packing(p)
    np.testing.assert_array_equal(pk.centers, C)
    np.testing.assert_array_equal(pk.radii, R)


def test_yade_export_text(tmp_path):
    # YADE's yade.export.text writes '#format x_y_z_r' and rows "x y z r" separated by spaces
    p = tmp_path / "yade.txt"
    p.write_text("#format x_y_z_r\n" + "\n".join(_rows(" ")) + "\n")
    np.testing.assert_array_equal(read_packing(p).radii, R)


def test_diameter_header_is_halved_and_units_scale_to_metres(tmp_path):
    p = tmp_path / "d.tsv"
    lines = ["id\tdiameter\tx\ty\tz"] + [
        f"{i}\t{2 * float(R[i])!r}\t{float(C[i, 0])!r}\t{float(C[i, 1])!r}\t{float(C[i, 2])!r}"
        for i in range(12)]
    p.write_text("\n".join(lines) + "\n")
    np.testing.assert_allclose(read_packing(p).radii, R, rtol=1e-15)
    mm = read_packing(p, units="mm")
    np.testing.assert_allclose(mm.radii, R * 1e-3, rtol=1e-15)
    np.testing.assert_allclose(mm.centers, C * 1e-3, rtol=1e-15)
    with pytest.raises(ValueError, match="unknown length unit 'in'"):
        read_packing(p, units="in")


def test_scale_warning_suggests_units():
    from network.packing import scale_warning

    assert scale_warning(Packing(C * 1e-3, np.full(12, 3e-3))) is None        # 6 mm grains
    msg = scale_warning(Packing(C, np.full(12, 3.0)))                          # 6 mm in "m"
    assert "6 m is outside 0.5-50 mm" in msg and "--units mm" in msg


@pytest.mark.parametrize("content, match", [
    (b"garbage", "not a .npz \\(zip\\) archive"),
])
def test_bad_npz_names_the_formats(tmp_path, content, match):
    p = tmp_path / "x.npz"
    p.write_bytes(content)
    with pytest.raises(ValueError, match=match) as e:
        read_packing(p)
    assert "formats read" in str(e.value)


def test_binary_file_is_refused(tmp_path):
    p = tmp_path / "x.dat"
    p.write_bytes(b"\x00\x01\x02abc")
    with pytest.raises(ValueError, match="binary file, not a packing"):
        read_packing(p)


def _dimers():
    """Five two-sphere grains (radius 0.5, centres 0.6 apart), grains 3 apart."""
    base = np.array([[0, 0, 0], [3, 0, 0], [0, 3, 0], [0, 0, 3], [3, 3, 3.0]])
    c = np.concatenate([base, base + [0.6, 0, 0]])
    return c, np.full(10, 0.5), np.tile(np.arange(5), 2)


def test_grain_id_roundtrip_csv_and_npz(tmp_path):
    c, r, g = _dimers()
    pk = Packing(c, r, grain_id=g)
    write_packing_csv(pk, tmp_path / "g.csv", digits=17)
    assert (tmp_path / "g.csv").read_text().splitlines()[0] == "x,y,z,r,grain_id"
    back = read_packing(tmp_path / "g.csv")
    np.testing.assert_array_equal(back.grain_id, g)
    assert back.n_grains == 5 and back.n == 10
    np.savez(tmp_path / "g.npz", centers=c, radii=r, grain_id=g)
    np.testing.assert_array_equal(read_packing(tmp_path / "g.npz").grain_id, g)
    # a four-column file (no grain ids) reads as one grain per sphere
    write_packing_csv(Packing(c, r), tmp_path / "s.csv")
    assert read_packing(tmp_path / "s.csv").grain_id is None


def test_grain_id_on_spheres_apart_is_refused_naming_it(tmp_path):
    c, r, g = _dimers()
    g = g.copy()
    g[7] = 4                                  # grain 4 now also owns a sphere of grain 2
    p = tmp_path / "bad.csv"
    p.write_text("x,y,z,r,grain_id\n" + "\n".join(
        f"{c[i, 0]},{c[i, 1]},{c[i, 2]},{r[i]},{g[i]}" for i in range(10)) + "\n")
    with pytest.raises(ValueError, match=r"grain_id 4 is on spheres that do not overlap into one "
                                         r"body \(row 6 and row 9 are apart\)"):
        read_packing(p)
    p.write_text(p.read_text().replace(",4\n", ",4.5\n", 1))
    with pytest.raises(ValueError, match="grain_id must be a whole number"):
        read_packing(p)
