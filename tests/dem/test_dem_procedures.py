"""Packing procedures of dem.pack (rect-bin target interior porosity 0.408 ± 0.01).

The full rect-bin is measured by ``python -m dem.pack --scene rect-bin`` (numbers in
docs/dem-packing.md); here a 0.06 × 0.02 m slab with rect-bin's thickness (about three
grains) checks that the 'sediment' procedure does what it says, with short stages.
"""

import numpy as np
import pytest

from dem import SCENE_DEFAULTS, Container, PackOptions, RunOptions, pack_bed

SLAB = Container("box", (0.06, 0.02), 0.06)
SHORT = dict(rng=3, run=RunOptions(tol=1e-2, max_steps=4000))
SED = dict(options=PackOptions(procedure="sediment", grow_steps=1000, lid_headroom=0.3, sediment_steps=1500,
                               tap_freq_hz=60.0, tap_amplitude_m=1.5e-4, tap_duration_s=0.05, tap_settle_steps=1000),
           **SHORT)


@pytest.fixture(scope="module")
def slabs():
    return pack_bed(SLAB, **SED), pack_bed(SLAB, options=PackOptions(procedure="lid", grow_steps=1000,
                                                                     lid_headroom=0.2), **SHORT)


@pytest.mark.slow
def test_sediment_is_denser_than_frictional_lid_with_sane_contacts(slabs):
    sed, lid = slabs
    s, sl = sed.summary, lid.summary
    assert s["n_spheres"] == sl["n_spheres"] == 296  # Eq. 3.10 for 0.06 x 0.02 x 0.06 m
    # measured (seed 3, these short stages): sediment 0.439, lid 0.467 (friction 0.47 locks a loose
    # structure in a bin three grains thick); a packing stage that keeps friction on loses the gap
    assert s["porosity_global_surface"] < sl["porosity_global_surface"] - 0.015
    assert s["porosity_global_surface"] == pytest.approx(0.439, abs=0.01)
    # contacts stay physical: overlaps below 1 % of a radius, nobody outside the bin
    assert s["max_overlap_fraction"] < 0.01 and s["mean_overlap_fraction"] < 0.002
    assert np.all(np.abs(sed.centers[:, 0]) + sed.radii <= 0.03 + 1e-4)
    assert np.all(np.abs(sed.centers[:, 1]) + sed.radii <= 0.01 + 1e-4)
    assert np.all(sed.centers[:, 2] - sed.radii >= -1e-4)


@pytest.mark.slow
def test_sediment_restores_friction_and_taps_whole_periods(slabs):
    s = slabs[0].summary
    assert s["procedure"] == "sediment"
    assert s["final_friction"] == {"particle": 0.47, "wall": 0.3}  # Table 3.1 values back for the last settle
    tap = s["stages"]["tap"]
    assert tap["cycles"] == 3  # round(0.05 s x 60 Hz)
    assert tap["duration_s"] == pytest.approx(3 / 60.0, abs=2 * s["dt_s"])
    assert tap["intensity_g"] == pytest.approx(1.5e-4 * (2 * np.pi * 60) ** 2 / 9.81, rel=1e-12)
    assert list(s["stages"]) == ["expand", "sediment", "tap", "tap_settle", "settle"]


@pytest.mark.slow
def test_procedure_arguments_are_checked():
    with pytest.raises(ValueError, match="procedure must be one of"):
        PackOptions(procedure="appendix-z")
    with pytest.raises(ValueError, match="lid_headroom > 0"):
        PackOptions(procedure="sediment", lid_headroom=0.0)
    assert SCENE_DEFAULTS["rect-bin"]["procedure"] == "sediment"
