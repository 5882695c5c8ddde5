"""dem.pack --grain --porosity: the procedure lever, network's sample region, the search.

The search logic is tested on a stand-in for pack_grains whose porosity is a known function of
the lever (a DEM packing of hundreds of grains takes minutes); the lever's physical effect is
measured on real packings in docs/report.md.
"""

import numpy as np
import pytest

import dem._clump_pack as cp
from dem import Container
from dem._clump_pack import network_region, pack_grains_to_porosity, procedure_lever
from dem.templates import sphere_template


def test_procedure_lever_ends_and_middle():
    assert procedure_lever(-1.0) == (0.0, 0.0)          # closed box at the fill height
    assert procedure_lever(0.0) == (0.3, 0.0)           # free fall, frictionless
    assert procedure_lever(1.0) == (0.3, 1.0)           # free fall, deposition friction 1
    assert procedure_lever(-0.25) == (0.225, 0.0)
    assert procedure_lever(7.0) == (0.3, 1.0)           # clipped


def test_network_region_is_network_default_region():
    """The same box as network.pores.default_region (1.5 volume-equivalent diameters inside
    the spheres' bounding box), computed without importing network."""
    from network.packing import Packing
    from network.pores import default_region
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 0.05, (400, 3))
    r = np.full(400, 0.002)
    lo, hi = network_region(x, r, np.pi / 6 * 0.004**3)
    reg = default_region(Packing(x, r))
    np.testing.assert_allclose(lo, reg.lo, atol=1e-12)
    np.testing.assert_allclose(hi, reg.hi, atol=1e-12)


def _fake(law, calls):
    """A pack_grains stand-in whose porosity is law(lever) (the lever read back from the
    headroom and friction it is given)."""
    def pack(container, template, *, porosity, deposition_friction, lid_headroom, **kw):
        lam = deposition_friction if deposition_friction > 0 else lid_headroom / 0.3 - 1.0
        calls.append(lam)
        e = law(lam)
        return (None, None, None, None, {"porosity_network_region": e,
                                         "porosity_network_region_error": 1e-3,
                                         "wall_time_s": 1.0})
    return pack


def test_search_reaches_the_target_within_tol(monkeypatch):
    calls = []
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.38 + 0.02 * (lam + 1) ** 1.5, calls))
    box = Container("box", (0.01, 0.01), 0.01)
    out = pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.405, porosity_tol=0.002)
    s = out[4]["porosity_search"]
    assert abs(out[4]["porosity_network_region"] - 0.405) <= 0.002
    assert s["reachable"] == pytest.approx([0.38, 0.38 + 0.02 * 2**1.5])
    assert calls[:2] == [-1.0, 1.0] and len(calls) <= 6
    assert [t["lever"] for t in s["tried"]] == pytest.approx(calls, abs=1e-9)


def test_search_outside_the_reachable_range_names_it(monkeypatch):
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.40 + 0.01 * lam, []))
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(ValueError, match=r"outside what this procedure reaches .*0\.3900-0\.4100"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.43)


def test_search_gives_up_after_max_packings(monkeypatch):
    """A porosity that jumps across the target (packing noise) is not found: RuntimeError with
    the closest bed, never a bed outside the tolerance."""
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.39 if lam < 0.3 else 0.42, []))
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(RuntimeError, match="no packing within 0.005 of porosity 0.405 after 6"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.405)


def test_bad_requests():
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(ValueError, match="porosity must be in"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=1.2)
    with pytest.raises(ValueError, match="max packings >= 2"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.4, max_packings=1)
    with pytest.raises(ValueError, match="deposition friction"):
        cp.pack_grains(box, sphere_template(0.001), deposition_friction=-0.1)


@pytest.mark.slow
def test_grain_bed_not_at_equilibrium_exits_1(tmp_path, capsys):
    """dem.pack --grain marks a bed whose settle stage hit the step limit as it does spheres:
    written with "converged": false, one error line, exit 1 (141 one-sphere grains, 0.8 s)."""
    import json
    from dem.pack import main
    tpl = tmp_path / "one.csv"
    tpl.write_text("x,y,z,r\n0,0,0,1\n")
    out = tmp_path / "bed.csv"
    assert main(["--scene", "box", "--size", "0.01", "0.01", "--height", "0.01", "--grain",
                 str(tpl), "--fill", "grow", "--max-steps", "200", "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: not at equilibrium"), err
    s = json.loads(out.with_suffix(".json").read_text())
    assert s["converged"] is False and s["stages"]["settle"]["steps"] == 200


def test_search_passes_over_a_bed_not_at_equilibrium(monkeypatch):
    """A bed within the tolerance whose settle stage did not converge is not the answer while
    packings remain: the search steps aside (the same lever would give the same bed) to one at
    equilibrium."""
    calls = []
    law = _fake(lambda lam: 0.38 + 0.02 * (lam + 1), calls)

    def pack(*a, **kw):
        out = law(*a, **kw)
        out[4]["stages"] = {"settle": {"converged": abs(calls[-1] - 0.05) > 1e-6}}
        return out
    monkeypatch.setattr(cp, "pack_grains", pack)
    box = Container("box", (0.01, 0.01), 0.01)
    out = pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.401, porosity_tol=0.002)
    assert len(calls) == 4 and out[4]["stages"]["settle"]["converged"]
    assert abs(out[4]["porosity_network_region"] - 0.401) <= 0.002


@pytest.mark.parametrize("target, count_phi", [(0.2, 0.35), (0.9, 0.5), (0.42, 0.42)])
def test_far_targets_count_grains_within_range_and_name_reach(monkeypatch, target, count_phi):
    """A target far outside what grains reach does not set the grain count: 0.2 would overfill
    the bin (N = 0.8 V/V_g: the closed-box end blows up) and 0.9 would leave a bed too thin for
    network's region. N comes from the target clipped to COUNT_POROSITY_RANGE; the ends are
    packed and the reachable range named (ValueError: exit 2). On a real soybean bed
    (0.08 x 0.08 x 0.05 m box) 0.2 ends with the reachable range 0.3211-0.4000."""
    seen = []
    law = _fake(lambda lam: 0.40 + 0.01 * lam, [])

    def pack(container, template, *, porosity, **kw):
        seen.append(porosity)
        return law(container, template, porosity=porosity, **kw)
    monkeypatch.setattr(cp, "pack_grains", pack)
    assert cp.COUNT_POROSITY_RANGE == (0.35, 0.5)
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(ValueError, match=r"outside what this procedure reaches .*0\.3900-0\.4100"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=target)
    assert seen == [count_phi, count_phi]


def test_an_empty_network_region_is_named_not_nan(monkeypatch):
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: float("nan"), []))
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(ValueError, match=r"network's sample region .* is empty .*porosity nan "
                                         r"at lever -1, nan at \+1\): give a larger container"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.9)


def test_pack_cli_unreachable_porosity_exits_2(tmp_path, monkeypatch, capsys):
    """dem.pack --grain --porosity 0.45 beyond what the search's ends reach in a container
    without a recorded range: exit 2 with the reachable range, nothing written."""
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.32 + 0.04 * (lam + 1), []))
    from dem.pack import main
    out = tmp_path / "g.csv"
    assert main(["--scene", "box", "--size", "0.08", "0.08", "--height", "0.05", "--grain",
                 "soybean", "--porosity", "0.45", "--out", str(out), "--quiet"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("[search]")]
    assert len(err) == 1 and err[0].startswith("error: porosity 0.45 is outside"), err
    assert "0.3200-0.4000" in err[0]
    assert not list(tmp_path.iterdir())
