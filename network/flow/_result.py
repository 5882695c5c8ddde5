"""The result of the flow stage along one axis, and the summary of several axes."""

from __future__ import annotations

import dataclasses

import numpy as np

from .._air import RHO_AIR_KG_M3
from .._grains import D272
from ._empirical import asabe_d272_gradient, ergun_gradient, kozeny_carman_gradient
from ._fits import fit_curve

__all__ = ["FlowResult", "combined_summary"]


@dataclasses.dataclass(frozen=True)
class FlowResult:
    """Network-model result along one axis (all SI). See :meth:`summary` for the JSON keys.

    Per-pore arrays (``pressure_pa`` in Pa for the flow-imposed problem, ``pore_xyz`` in m) are
    indexed like ``pore_ids``; per-throat arrays (``throat_flow_m3_s``, ``throat_conductance``,
    ``conns`` in local pore indices) like ``throat_ids`` (tessellation throats). When
    tetrahedra were joined into pore bodies, ``pore_groups`` (Np,) gives every tetrahedron's
    body and ``pore_ids`` are body ids; otherwise it is None and ``pore_ids`` are tetrahedra.
    """

    axis: str
    conductance_model: str
    policy: str
    viscosity_pa_s: float
    velocity_m_s: float
    depth_m: float
    region_lo: tuple
    region_hi: tuple
    region_radius: float | None
    n_pores: int
    n_throats: int
    n_inlet: int
    n_outlet: int
    n_dropped: int
    length_m: float
    area_m2: float
    flow_m3_s: float
    permeability_m2: float
    mean_diameter_m: float
    sauter_diameter_m: float
    #: porosity of the region ``permeability_m2`` is measured in (the inset window when
    #: ``sample_estimator`` is 'inset', else the sample) and its error: the pair (k, porosity)
    #: that k/d², Ergun, Kozeny-Carman and the fits use
    porosity: float
    porosity_std: float
    solver: dict
    check: dict
    qstar_stats: dict
    timings_s: dict
    pressure_pa: np.ndarray = dataclasses.field(repr=False)
    throat_flow_m3_s: np.ndarray = dataclasses.field(repr=False)
    throat_conductance: np.ndarray = dataclasses.field(repr=False)
    pore_ids: np.ndarray = dataclasses.field(repr=False)
    throat_ids: np.ndarray = dataclasses.field(repr=False)
    conns: np.ndarray = dataclasses.field(repr=False)
    pore_xyz: np.ndarray = dataclasses.field(repr=False)
    pore_groups: np.ndarray | None = dataclasses.field(default=None, repr=False)
    #: k of the sample's core, ``core_margin_m`` in from every face (None: cylinder sample
    #: or a core too small), m²; see :func:`network.flow.core_permeability`.
    permeability_core_m2: float | None = None
    core_margin_m: float | None = None
    #: mu Q H / (A dP) over the whole sample, m² (= permeability_m2 when ``sample_estimator``
    #: is 'whole'; see ``docs/sample-boundary.md``).
    permeability_whole_m2: float | None = None
    #: 'inset': permeability_m2 from the window inside the lateral boundary layer; 'whole'.
    sample_estimator: str = "whole"
    #: Window Q* of each sample throat (mean-radius units; NaN inside a merged pore body; None
    #: with a custom conductance function), indexed like ``throat_ids``.
    throat_qstar: np.ndarray | None = dataclasses.field(default=None, repr=False)
    #: Nonlinear (inertial) solves when asked (:func:`network.flow.solve_network` with
    #: ``inertia=True``): ``density_kg_m3``, ``velocities_m_s`` (the first is
    #: ``velocity_m_s``) and their :class:`network.flow.InertialPoint` ``points``.
    inertial: dict | None = dataclasses.field(default=None, repr=False)
    #: porosity of the whole sample box and its error (= ``porosity`` without an inset window)
    porosity_sample: float | None = None
    porosity_sample_std: float | None = None
    #: The grain the bed is of (a key of :data:`network._grains.D272`), for the D272
    #: comparison; None: unknown, no D272 line.
    grain: str | None = None

    def reynolds_particle(self, velocity_m_s: float, density_kg_m3: float) -> float:
        """Re_p = ρ U d32 / μ (DESIGN.md), dimensionless."""
        return density_kg_m3 * velocity_m_s * self.sauter_diameter_m / self.viscosity_pa_s

    def curve_points(self) -> list[dict]:
        """The inertial points as JSON-ready dicts, ascending velocity."""
        if self.inertial is None:
            return []
        rho = self.inertial["density_kg_m3"]
        rows = []
        for u, pt in zip(self.inertial["velocities_m_s"], self.inertial["points"]):
            grad = self._inertial_gradient(pt)
            rows.append({"velocity_m_s": float(u),
                         "reynolds_particle": self.reynolds_particle(u, rho),
                         "pressure_gradient_pa_per_m": float(grad),
                         "apparent_permeability_m2": float(self.viscosity_pa_s * u / grad),
                         "converged": bool(pt.converged), "newton_iterations": pt.iterations,
                         "cg_iterations": pt.cg_iterations, "residual": pt.residual,
                         "seconds": pt.seconds})
        return sorted(rows, key=lambda r: r["velocity_m_s"])

    def curve_fits(self) -> dict:
        """Darcy-Forchheimer, D272 and Ergun fits (:func:`network.flow.fit_curve`) over the
        converged inertial points, with this sample's porosity and d32; all None with fewer
        than two velocities, {} without inertial points."""
        ok = [p for p in self.curve_points() if p["converged"]]
        if not ok:
            return {}
        return fit_curve([p["velocity_m_s"] for p in ok],
                         [p["pressure_gradient_pa_per_m"] for p in ok],
                         viscosity_pa_s=self.viscosity_pa_s,
                         density_kg_m3=self.inertial["density_kg_m3"], porosity=self.porosity,
                         diameter_m=self.sauter_diameter_m)

    @property
    def k_over_d2(self) -> float:
        """k / d32² (Sauter mean diameter), dimensionless."""
        return self.permeability_m2 / self.sauter_diameter_m**2

    @property
    def pressure_gradient_pa_per_m(self) -> float:
        return self.viscosity_pa_s * self.velocity_m_s / self.permeability_m2

    @property
    def pressure_drop_pa(self) -> float:
        return self.pressure_gradient_pa_per_m * self.depth_m

    def comparisons(self) -> dict:
        """Empirical pressure gradients (Pa/m) and drops over ``depth_m`` (Pa) at the same v:
        Ergun, Kozeny-Carman and, where ``grain`` has sourced constants, ASABE D272 (else
        ``asabe_d272`` is None)."""
        v, e, d = self.velocity_m_s, self.porosity, self.sauter_diameter_m
        out = {}
        for name, grad in (
            ("ergun", ergun_gradient(v, porosity=e, diameter_m=d, viscosity_pa_s=self.viscosity_pa_s,
                                     density_kg_m3=RHO_AIR_KG_M3)),
            ("kozeny_carman", kozeny_carman_gradient(v, porosity=e, diameter_m=d,
                                                     viscosity_pa_s=self.viscosity_pa_s)),
        ):
            out[name] = {"pressure_gradient_pa_per_m": float(grad),
                         "pressure_drop_pa": float(grad * self.depth_m)}
        c = D272.get(self.grain) if self.grain is not None else None
        out["asabe_d272"] = None
        if c is not None and c.a_pa_s2_m3 is not None:
            grad = asabe_d272_gradient(v, a=c.a_pa_s2_m3, b=c.b_s_m)
            out["asabe_d272"] = {"grain": self.grain, "pressure_gradient_pa_per_m": float(grad),
                                 "pressure_drop_pa": float(grad * self.depth_m)}
        return out

    def summary(self) -> dict:
        """Every scalar as a JSON-ready dict, one key per number with its unit in the name."""
        return {
            "axis": self.axis,
            "conductance_model": self.conductance_model,
            "policy": self.policy,
            "permeability_m2": self.permeability_m2,
            "sample_estimator": self.sample_estimator,
            "permeability_whole_m2": self.permeability_whole_m2,
            "permeability_note": (
                "inset: Darcy's law in the window 1.5 grain diameters in from the lateral faces "
                "and 1 from the ends, free of the layer the cut lateral conduits leave (the "
                "whole-sample value, permeability_whole_m2, is low by about 1/width); whole: "
                "mu Q H / (A dP), for samples too narrow for the window (docs/sample-boundary.md)"),
            "permeability_core_m2": self.permeability_core_m2,
            "permeability_core_note": (
                "Darcy's law in the sample's core, core_margin_m in from every face, free of "
                "the sample's boundary layer (cut conduits on the lateral faces, inlet/outlet "
                "pores that are not a plane), which lowers permeability_m2 by a term falling "
                "as 1/H; null for cylindrical samples or a core narrower than 5 mean "
                "diameters"),
            "core_margin_m": self.core_margin_m,
            "k_over_d2": self.k_over_d2,
            "k_over_d2_note": "d = Sauter mean diameter d32 = 2 sum(r^3)/sum(r^2) (also used in "
                              "Ergun and Kozeny-Carman)",
            "pressure_gradient_pa_per_m": self.pressure_gradient_pa_per_m,
            "pressure_drop_pa": self.pressure_drop_pa,
            "velocity_m_s": self.velocity_m_s,
            "depth_m": self.depth_m,
            "viscosity_pa_s": self.viscosity_pa_s,
            "flow_m3_s": self.flow_m3_s,
            "flow_m3_s_note": "total flow for 1 Pa across the sample",
            "porosity": self.porosity,
            "porosity_std": self.porosity_std,
            "porosity_sample": self.porosity_sample,
            "porosity_sample_std": self.porosity_sample_std,
            "porosity_note": (
                "porosity is that of the region permeability_m2 is measured in (the inset "
                "window with sample_estimator 'inset', else the sample), the pair k/d32^2, "
                "Ergun, Kozeny-Carman and the fits use; porosity_sample is the whole sample's"),
            "mean_diameter_m": self.mean_diameter_m,
            "sauter_diameter_m": self.sauter_diameter_m,
            "n_pores": self.n_pores,
            "n_throats": self.n_throats,
            "n_inlet_pores": self.n_inlet,
            "n_outlet_pores": self.n_outlet,
            "n_dropped_pores": self.n_dropped,
            "sample_length_m": self.length_m,
            "sample_area_m2": self.area_m2,
            "sample_lo_m": list(self.region_lo),
            "sample_hi_m": list(self.region_hi),
            "sample_radius_m": self.region_radius,
            "solver": self.solver,
            "mass_balance": self.check,
            "qstar": self.qstar_stats,
            "comparisons": self.comparisons(),
            "seconds": self.timings_s,
        } | self._inertial_summary()

    def _inertial_gradient(self, point) -> float:
        r"""Pressure gradient of an inertial point, Pa/m: :math:`\Delta p / H` of the whole
        sample times :math:`k_\mathrm{whole}/k` (the ratio k_app/k is taken from the whole
        sample, whose lateral boundary layer lowers both alike; k from ``sample_estimator``).
        """
        whole = self.permeability_whole_m2 or self.permeability_m2
        return point.dp_pa / self.length_m * whole / self.permeability_m2

    def _inertial_summary(self) -> dict:
        """Inertial value at ``velocity_m_s`` with the Stokes values beside it."""
        if self.inertial is None:
            return {}
        pt = self.inertial["points"][0]
        grad = self._inertial_gradient(pt)
        return {"pressure_gradient_pa_per_m": grad,
                "pressure_drop_pa": grad * self.depth_m,
                "pressure_gradient_stokes_pa_per_m": self.pressure_gradient_pa_per_m,
                "pressure_drop_stokes_pa": self.pressure_drop_pa,
                "reynolds_particle": self.reynolds_particle(self.velocity_m_s,
                                                            self.inertial["density_kg_m3"]),
                "density_kg_m3": self.inertial["density_kg_m3"],
                "inertial_law": self.inertial.get("law"),
                "inertial_solver": {"converged": pt.converged, "newton_iterations": pt.iterations,
                                    "cg_iterations": pt.cg_iterations, "residual": pt.residual,
                                    "seconds": pt.seconds}}


def combined_summary(results, *, seconds: dict | None = None, packing=None) -> dict:
    r"""JSON-ready summary of one or several :class:`FlowResult` (one per axis).

    One axis: its :meth:`FlowResult.summary`. Several: the arithmetic mean of the directional
    permeabilities, :math:`\bar k = \tfrac13 \sum_a k_a`, the gradient :math:`\mu v/\bar k`
    (Pa/m) and drop over the depth (Pa) it gives (Stokes, said in ``pressure_gradient_note``; with
    inertia each axis has its own under ``by_axis``), the anisotropy :math:`k_a/\bar k`, and every
    axis's own summary under ``by_axis``. ``seconds`` is merged into the ``seconds`` entry.
    With the three axes, the diagonal of the permeability tensor ``permeability_tensor_m2``
    (k_xx, k_yy, k_zz, m²) and ``horizontal_to_vertical_resistance`` =
    :math:`k_{zz} / \tfrac12(k_{xx} + k_{yy})` (resistance is 1/k; z is vertical); with a
    ``packing`` of multi-sphere grains, ``orientation_order``: :math:`S` of the grains' long
    axes against the vertical (:meth:`network.packing.Packing.orientation_order`).
    """
    results = list(results)
    if not results:
        raise ValueError("no results to summarise")
    if len(results) == 1:
        out = results[0].summary()
        out["seconds"] = dict(out["seconds"], **(seconds or {}))
        return out
    by = {r.axis: r.summary() for r in results}
    first = results[0]
    k = float(np.mean([r.permeability_m2 for r in results]))
    grad = first.viscosity_pa_s * first.velocity_m_s / k
    out = {
        "axis": "all",
        "conductance_model": first.conductance_model,
        "policy": first.policy,
        "permeability_m2": k,
        "permeability_note": "arithmetic mean of the three directional permeabilities",
        "k_over_d2": k / first.sauter_diameter_m**2,
        "pressure_gradient_pa_per_m": grad,
        "pressure_drop_pa": grad * first.depth_m,
        "pressure_gradient_note": "Stokes, mu v / the mean k" + (
            "; each axis's value with inertia is under by_axis"
            if any("pressure_gradient_stokes_pa_per_m" in b for b in by.values()) else ""),
        "porosity": first.porosity,
        "porosity_std": first.porosity_std,
        "porosity_sample": first.porosity_sample,
        "n_pores": max(r.n_pores for r in results),
        "n_throats": max(r.n_throats for r in results),
        "anisotropy": {r.axis: float(r.permeability_m2 / k) for r in results},
        "comparisons": by[first.axis]["comparisons"],
        "by_axis": by,
        "seconds": dict(seconds or {}),
    }
    ks = {r.axis: float(r.permeability_m2) for r in results}
    if set(ks) == {"x", "y", "z"}:
        out["permeability_tensor_m2"] = {"xx": ks["x"], "yy": ks["y"], "zz": ks["z"]}
        out["horizontal_to_vertical_resistance"] = ks["z"] / (0.5 * (ks["x"] + ks["y"]))
    if packing is not None and packing.grain_id is not None and packing.n_grains < packing.n:
        out["orientation_order"] = packing.orientation_order(axis=2)
        out["orientation_order_note"] = ("S = <3 cos^2(theta) - 1>/2 of the grains' long axes "
                                         "against z: 1 all vertical, -0.5 all horizontal, 0 "
                                         "random")
    return out
