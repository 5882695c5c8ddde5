r"""Empirical airflow-resistance equations to set beside the network result.

All three return the pressure gradient in Pa/m at a superficial velocity ``velocity_m_s``.

Ergun (1952), as the thesis uses it (4.2.3):

.. math:: \frac{\Delta P}{L} = 150 \frac{\mu (1-\varepsilon)^2 v}{\varepsilon^3 d^2}
          + 1.75 \frac{\rho (1-\varepsilon) v^2}{\varepsilon^3 d}

Kozeny–Carman (Carman 1937, constant 180 = 36 × 5):

.. math:: \frac{\Delta P}{L} = 180 \frac{\mu (1-\varepsilon)^2 v}{\varepsilon^3 d^2}

ASABE D272 (Hukill & Ives 1955), soybeans a = 1.02e4 Pa·s²/m³, b = 16.0 s/m:

.. math:: \frac{\Delta P}{L} = \frac{a v^2}{\ln(1 + b v)}

With the thesis's bed (d = 6.5 mm, ε = 0.408, μ = 1.932e-5 Pa·s, ρ = 1.20 kg/m³) at
0.013 m/s over 0.25 m these give 1.27 Pa (Ergun) and 2.28 Pa (ASABE), the values of thesis
Table 4.5 / section 4.2.3 (tested).
"""

from __future__ import annotations

import numpy as np

from .._air import MU_AIR_PA_S, RHO_AIR_KG_M3
from .._grains import d272_constants

__all__ = ["ergun_gradient", "kozeny_carman_gradient", "asabe_d272_gradient",
           "ASABE_SOYBEAN_A", "ASABE_SOYBEAN_B"]

#: ASABE D272 Hukill–Ives constants a (Pa·s²/m³) and b (s/m) for soybeans, from the grain
#: library (network._grains, with their source).
ASABE_SOYBEAN_A, ASABE_SOYBEAN_B = d272_constants("soybean")


def _check(porosity, diameter_m, velocity_m_s):
    if not 0 < porosity < 1:
        raise ValueError(f"porosity must be in (0, 1), got {porosity!r}")
    if not diameter_m > 0:
        raise ValueError(f"diameter must be > 0, got {diameter_m!r}")
    if not velocity_m_s >= 0:
        raise ValueError(f"velocity must be >= 0, got {velocity_m_s!r}")


def ergun_gradient(velocity_m_s, *, porosity, diameter_m, viscosity_pa_s=MU_AIR_PA_S,
                   density_kg_m3=RHO_AIR_KG_M3):
    """Ergun pressure gradient, Pa/m (see module docstring).

    >>> round(float(0.25 * ergun_gradient(0.013, porosity=0.408, diameter_m=6.5e-3)), 2)
    1.27
    """
    _check(porosity, diameter_m, velocity_m_s)
    e, v, d = porosity, velocity_m_s, diameter_m
    return (150 * viscosity_pa_s * (1 - e) ** 2 * v / (e**3 * d**2)
            + 1.75 * density_kg_m3 * (1 - e) * v**2 / (e**3 * d))


def kozeny_carman_gradient(velocity_m_s, *, porosity, diameter_m, viscosity_pa_s=MU_AIR_PA_S):
    """Kozeny–Carman pressure gradient, Pa/m (Carman constant 180)."""
    _check(porosity, diameter_m, velocity_m_s)
    e = porosity
    return 180 * viscosity_pa_s * (1 - e) ** 2 * velocity_m_s / (e**3 * diameter_m**2)


def asabe_d272_gradient(velocity_m_s, *, a=ASABE_SOYBEAN_A, b=ASABE_SOYBEAN_B):
    """ASABE D272 (Hukill–Ives) pressure gradient, Pa/m; defaults are soybeans.

    >>> round(float(0.25 * asabe_d272_gradient(0.013)), 2)
    2.28
    """
    if not velocity_m_s > 0:
        raise ValueError(f"velocity must be > 0, got {velocity_m_s!r}")
    return a * velocity_m_s**2 / np.log1p(b * velocity_m_s)
