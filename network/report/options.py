"""The typed options of a report (:class:`ReportOptions`), what :func:`build_report` takes.

The command (:mod:`network.report.cli`) turns its arguments into one :class:`ReportOptions`
after checking them (its messages name the options); a library caller builds one directly and
gets a ValueError naming the field for a value that cannot work.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .._air import MU_AIR_PA_S, RHO_AIR_KG_M3
from .._grains import BED, grain_key
from ..core import check_physical_porosity
from ..curve import DEFAULT_VELOCITIES, parse_velocities
from ..flow import DEFAULT_DEPTH_M
from .system import AIRFLOW_UNITS, check_fan_shape

__all__ = ["ReportOptions", "grain_key"]


def _positive(name: str, value, *, optional: bool = True) -> None:
    if value is None and optional:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")


@dataclass(frozen=True, kw_only=True)
class ReportOptions:
    """Everything a report is computed from, besides the packing itself.

    Parameters
    ----------
    grain : str
        Crop, a key of :data:`network._grains.D272` (aliases such as ``"corn"`` accepted and
        stored as the key). Required.
    velocities_m_s : tuple of float
        Superficial velocities solved, m/s, each > 0; default the command's ``0.005:0.3:12``.
    porosity : float or None
        Porosity ε the report is for, in (0, 1); None (default): the packing's own.
    porosity_source : str
        Why that porosity, the first words of the JSON's ``porosity_source``.
    reachable : dict or None
        The range a packing of the grain reaches, a record ``{"range": (low, high), "tol": t,
        "source": s}`` (:func:`network.report.porosity.reach_record`); None (default): within
        ``MAX_SHIFT`` of the packing's own.
    particle_density_kg_m3 : float or None
        Kernel density ρ_p, kg/m³, > 0, for the bulk density ρ_p (1 - ε); None (default): the
        grain library's (ValueError where it has none).
    particle_density_source : str or None
        Where ρ_p comes from; None (default): the library's source, or ``"given"``.
    depth_m : float
        Grain the air crosses, m, > 0 (default ``DEFAULT_DEPTH_M``, 0.25 m).
    axis : {"z", "x"}
        The bin's airflow for the system curve, the airflow and the fan (default ``"z"``).
    diameter_m, floor_area_m2 : float or None
        Round bin diameter, m, or floor area, m²; at most one; neither: 1 m² (default).
    airflow : (float, str) or None
        An airflow to report, (value > 0, unit of ``AIRFLOW_UNITS``); default None.
    fan_airflow_m3_s, fan_static_pressure_pa : tuple of float or None
        A fan curve (same length, ≥ 2 points, airflow ascending), needs the bin's diameter or
        floor area; default None. ``fan_file`` names its file in the JSON.
    band : bool
        Compute (or read) the porosity band (default True); without it the porosity is the
        packing's own.
    sphere_band : bool
        Band on sphere beds even where the grain's DEM beds are bundled (default False).
    band_seed : int
        First seed of the band's sphere packings, ≥ 0 (default 1).
    viscosity_pa_s, density_kg_m3 : float
        Air, Pa s and kg/m³, > 0 (defaults the thesis air's, 1.932e-5 and 1.20).
    sample_box_m : tuple of 6 float or None
        Sample box (xmin, xmax, ymin, ymax, zmin, zmax), m; None (default): the interior box.
    margin_m : float or None
        Wall margin of the default box, m, ≥ 0; None (default): 1.5 mean diameters.
    bed_label : str
        Which bed, the first words of ``porosity_source`` (default ``"the user's packing"``).
    bed_record : dict or None
        The JSON's ``bed`` entry; None (default): a user's packing at the given path.
    bin_beds : dict or None
        The bin's beds (:func:`network.report.binbeds.plan_bin_beds`, its beds packed): the
        report adds the resistance through the bin's whole depth (``bin_beds``); a plan with
        ``used`` False is reported as its one line; None (default): no bin section.
    """

    grain: str
    velocities_m_s: tuple = field(default_factory=lambda: tuple(
        parse_velocities(DEFAULT_VELOCITIES)))
    porosity: float | None = None
    porosity_source: str = "the packing's own"
    reachable: dict | None = None
    particle_density_kg_m3: float | None = None
    particle_density_source: str | None = None
    depth_m: float = DEFAULT_DEPTH_M
    axis: str = "z"
    diameter_m: float | None = None
    floor_area_m2: float | None = None
    airflow: tuple | None = None
    fan_airflow_m3_s: tuple | None = None
    fan_static_pressure_pa: tuple | None = None
    fan_file: str | None = None
    band: bool = True
    sphere_band: bool = False
    band_seed: int = 1
    viscosity_pa_s: float = MU_AIR_PA_S
    density_kg_m3: float = RHO_AIR_KG_M3
    sample_box_m: tuple | None = None
    margin_m: float | None = None
    bed_label: str = "the user's packing"
    bed_record: dict | None = None
    bin_beds: dict | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "grain", grain_key(self.grain))
        us = tuple(float(u) for u in self.velocities_m_s)
        if not us:
            raise ValueError("velocities_m_s must hold at least one velocity")
        for u in us:
            _positive("velocities_m_s", u)
        set_(self, "velocities_m_s", us)
        if self.porosity is not None and not (
                isinstance(self.porosity, (int, float)) and 0 < self.porosity < 1):
            raise ValueError(f"porosity must be in (0, 1), got {self.porosity!r}")
        if self.porosity is not None:
            check_physical_porosity(self.porosity, "porosity")
        if self.reachable is not None:
            try:
                lo, hi = (float(v) for v in self.reachable["range"])
                tol = float(self.reachable.get("tol", 0.0))
            except (TypeError, ValueError, KeyError):
                raise ValueError("reachable must be a record {'range': (low, high), 'tol': t, "
                                 f"'source': s}}, got {self.reachable!r}") from None
            if not (0 <= lo <= hi <= 1 and 0 <= tol < 1):
                raise ValueError(f"reachable range must lie within [0, 1], got {self.reachable!r}")
            set_(self, "reachable", {**self.reachable, "range": (lo, hi), "tol": tol,
                                     "source": str(self.reachable.get("source", "given"))})
        for name in ("particle_density_kg_m3", "diameter_m", "floor_area_m2", "depth_m",
                     "viscosity_pa_s", "density_kg_m3"):
            _positive(name, getattr(self, name),
                      optional=name in ("particle_density_kg_m3", "diameter_m", "floor_area_m2"))
        if self.particle_density_kg_m3 is None:
            bed = BED[self.grain]
            if bed.particle_density_kg_m3 is None:
                raise ValueError(f"no sourced kernel density for {self.grain} "
                                 "(docs/grain-library.md): give particle_density_kg_m3")
            set_(self, "particle_density_kg_m3", bed.particle_density_kg_m3)
            if self.particle_density_source is None:
                set_(self, "particle_density_source", bed.particle_density_source)
        elif self.particle_density_source is None:
            set_(self, "particle_density_source", "given")
        if self.axis not in ("z", "x"):
            raise ValueError(f"axis must be 'z' or 'x', got {self.axis!r}")
        if self.diameter_m is not None and self.floor_area_m2 is not None:
            raise ValueError("give diameter_m (round bin) or floor_area_m2, not both")
        if self.airflow is not None:
            value, unit = self.airflow
            if str(unit).lower() not in AIRFLOW_UNITS:
                raise ValueError(f"airflow unit {unit!r}: use one of {', '.join(AIRFLOW_UNITS)}")
            unit = str(unit).lower()
            _positive("airflow", value, optional=False)
            set_(self, "airflow", (float(value), unit))
        self._check_fan()
        if isinstance(self.band_seed, bool) or not isinstance(self.band_seed, int) \
                or self.band_seed < 0:
            raise ValueError(f"band_seed must be an integer >= 0, got {self.band_seed!r}")
        if self.sample_box_m is not None:
            box = tuple(float(v) for v in self.sample_box_m)
            if len(box) != 6 or not all(math.isfinite(v) for v in box) \
                    or not all(box[2 * i] < box[2 * i + 1] for i in range(3)):
                raise ValueError("sample_box_m must be (xmin, xmax, ymin, ymax, zmin, zmax), "
                                 f"each min < max, got {self.sample_box_m!r}")
            set_(self, "sample_box_m", box)
        if self.margin_m is not None and not (math.isfinite(self.margin_m)
                                              and self.margin_m >= 0):
            raise ValueError(f"margin_m must be >= 0, got {self.margin_m!r}")

    def _check_fan(self) -> None:
        q, p = self.fan_airflow_m3_s, self.fan_static_pressure_pa
        if q is None and p is None:
            return
        if q is None or p is None:
            raise ValueError("give both fan_airflow_m3_s and fan_static_pressure_pa")
        q, p = tuple(float(v) for v in q), tuple(float(v) for v in p)
        if len(q) != len(p) or len(q) < 2:
            raise ValueError(f"the fan curve needs two or more (airflow, pressure) points of "
                             f"equal count, got {len(q)} and {len(p)}")
        if not all(math.isfinite(v) and v >= 0 for v in q + p):
            raise ValueError("the fan curve's airflow and pressure must be finite and >= 0")
        if not all(a < b for a, b in zip(q, q[1:])):
            raise ValueError("the fan curve's airflow must ascend")
        if self.diameter_m is None and self.floor_area_m2 is None:
            raise ValueError("a fan curve needs the bin: diameter_m (round) or floor_area_m2")
        check_fan_shape(q, p)
        object.__setattr__(self, "fan_airflow_m3_s", q)
        object.__setattr__(self, "fan_static_pressure_pa", p)

    @property
    def fan(self):
        """(airflow m³/s, static pressure Pa) of the fan as two tuples, or None."""
        if self.fan_airflow_m3_s is None:
            return None
        return self.fan_airflow_m3_s, self.fan_static_pressure_pa
