"""Grain and wall properties: the thesis's Table 3.1 soybean in a Plexiglas bin by default."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ._contacts import series_stiffness

__all__ = ["Material", "SOYBEAN"]


@dataclass(frozen=True)
class Material:
    """Grain and wall properties (defaults: soybean in Plexiglas, thesis Table 3.1).

    Stiffnesses are per-entity values as in PFC3D; a contact uses the series
    combination (:func:`dem._contacts.series_stiffness`). ``damping_ratio`` is the critical-damping
    ratio of grain-grain dashpots; ``wall_damping_ratio`` that of grain-wall ones (None: the same).
    ``rolling_friction`` and ``wall_rolling_friction`` are the coefficients of rolling friction
    mu_r of grain-grain and grain-wall contacts (torque mu_r F_n R against the body's spin,
    :func:`dem._contacts.rolling_torque`; 0, the default: none).
    """

    density_kg_m3: float = 1285.0
    kn_n_m: float = 4.0e6
    ks_n_m: float = 2.0e6
    friction: float = 0.47
    wall_kn_n_m: float = 1.8e7
    wall_ks_n_m: float = 0.9e7
    wall_friction: float = 0.3
    damping_ratio: float = 0.1
    radius_min_m: float = 0.00275
    radius_max_m: float = 0.00375
    wall_damping_ratio: float | None = None
    rolling_friction: float = 0.0
    wall_rolling_friction: float = 0.0

    def __post_init__(self):
        for name in ("density_kg_m3", "kn_n_m", "ks_n_m", "wall_kn_n_m", "wall_ks_n_m"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be positive and finite, got {v}")
        for name in ("friction", "wall_friction", "rolling_friction", "wall_rolling_friction"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be >= 0, got {v}")
        if not 0 <= self.damping_ratio < 1:
            raise ValueError(f"damping_ratio must be in [0, 1), got {self.damping_ratio}")
        if self.wall_damping_ratio is not None and not 0 <= self.wall_damping_ratio < 1:
            raise ValueError(f"wall_damping_ratio must be in [0, 1), got {self.wall_damping_ratio}")
        if not 0 < self.radius_min_m <= self.radius_max_m:
            raise ValueError(
                f"need 0 < radius_min_m <= radius_max_m, got {self.radius_min_m}, {self.radius_max_m}"
            )

    @property
    def wall_beta(self):
        """Critical-damping ratio of grain-wall dashpots."""
        return self.damping_ratio if self.wall_damping_ratio is None else self.wall_damping_ratio

    @cached_property
    def kn_pp(self):
        """Particle–particle contact normal stiffness, N/m."""
        return float(series_stiffness(self.kn_n_m, self.kn_n_m))

    @cached_property
    def ks_pp(self):
        return float(series_stiffness(self.ks_n_m, self.ks_n_m))

    @cached_property
    def kn_pw(self):
        """Particle–wall contact normal stiffness, N/m."""
        return float(series_stiffness(self.kn_n_m, self.wall_kn_n_m))

    @cached_property
    def ks_pw(self):
        return float(series_stiffness(self.ks_n_m, self.wall_ks_n_m))


SOYBEAN = Material()
