"""network.core, the packing format both packages share: every transformation of a Packing
keeps every column (grain ids through unit changes, offsets, subsets and tilings), and a bed
written in cm or mm and read with --units gives the numbers of the bed in metres."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from network import solve
from network.core import Packing, read_packing, write_packing_csv
from network.packing import periodic_copies

DATA = Path(solve.__file__).resolve().parent / "data"
DIMERS = Packing([[0, 0, 0], [0.8, 0, 0], [3, 0, 0], [3.8, 0, 0], [0, 3, 0], [0, 3.8, 0]],
                 [0.5] * 6, grain_id=[4, 4, 9, 9, 2, 2], source="dimers")


def test_scaled_shifted_subset_keep_grain_ids():
    s = DIMERS.scaled(0.01, source="cm")
    np.testing.assert_array_equal(s.centers, DIMERS.centers * 0.01)
    np.testing.assert_array_equal(s.grain_id, DIMERS.grain_id)
    assert (s.source, s.n_grains) == ("cm", 3)
    m = DIMERS.shifted([1, 2, 3])
    np.testing.assert_array_equal(m.centers, DIMERS.centers + [1, 2, 3])
    np.testing.assert_array_equal(m.grain_id, DIMERS.grain_id)
    sub = DIMERS.subset(np.array([0, 1, 4, 5]))
    assert sub.grain_id.tolist() == [4, 4, 2, 2] and sub.n_grains == 2


def test_periodic_copies_number_each_copys_grains_apart():
    p = periodic_copies(DIMERS, 10.0, 2)
    assert p.n == 8 * DIMERS.n and p.n_grains == 8 * DIMERS.n_grains
    first = p.grain_id[:DIMERS.n]
    assert first.tolist() == DIMERS.grain_id.tolist()


@pytest.mark.parametrize("units, factor", [("cm", 100.0), ("mm", 1000.0)])
def test_reading_in_cm_or_mm_keeps_grain_ids(tmp_path, units, factor):
    path = tmp_path / "bed.csv"
    write_packing_csv(DIMERS.scaled(factor), path, digits=17)
    got = read_packing(path, units=units)
    np.testing.assert_array_equal(got.grain_id, DIMERS.grain_id)
    np.testing.assert_allclose(got.centers, DIMERS.centers, rtol=1e-15, atol=1e-15)
    assert got.n_grains == 3


def _solve(path, tmp_path, units):
    out = tmp_path / f"{path.stem}_{units}.json"
    assert solve.main([str(path), "--units", units, "--json", str(out), "--quiet"]) == 0
    return json.loads(out.read_text())


@pytest.mark.slow
@pytest.mark.parametrize("bed", ["wheat_grains", "soybean_grains"])
def test_a_grain_bed_in_cm_or_mm_gives_the_numbers_in_metres(tmp_path, bed):
    """The bundled grain beds (multi-sphere grains) written in m, cm and mm: porosity, k and
    the pressure drop agree to 1e-4, so each sphere still belongs to its grain after the unit
    change (read as separate spheres, the porosity of such a bed is off by a factor of two).
    The rounding of the converted coordinates alone moves k by up to 6e-6 (soybean, mm)."""
    src = read_packing(DATA / f"{bed}.csv")
    assert src.n_grains < src.n
    res = {}
    for units, factor in (("m", 1.0), ("cm", 100.0), ("mm", 1000.0)):
        path = tmp_path / f"{bed}_{units}.csv"          # no companion JSON: the bed's extent
        write_packing_csv(src.scaled(factor), path, digits=17)
        res[units] = _solve(path, tmp_path, units)
    for units in ("cm", "mm"):
        assert res[units]["n_pores"] == res["m"]["n_pores"]
        for key in ("porosity", "permeability_m2", "pressure_drop_pa"):
            assert res[units][key] == pytest.approx(res["m"][key], rel=1e-4), (units, key)
    assert 0.3 < res["m"]["porosity"] < 0.5
