"""Air properties: the one home of the viscosity and density defaults and their checks.

The thesis uses μ = 1.932e-5 Pa·s and ρ = 1.20 kg/m³ (air near 20 °C; Appendix G). Every
function of the package that needs a viscosity or density takes it as a keyword with these
defaults; a CLI checks the user's value once, at the door, with :func:`check_viscosity` /
:func:`check_density`, and the library checks again only at its public entry points.
"""

from __future__ import annotations

import math

__all__ = ["MU_AIR_PA_S", "P_ATM_PA", "RHO_AIR_KG_M3", "check_viscosity", "check_density",
           "check_positive"]

#: Dynamic viscosity of air used by the thesis (Appendix G), Pa·s.
MU_AIR_PA_S = 1.932e-5
#: Density of air used by the thesis, kg/m³.
RHO_AIR_KG_M3 = 1.20
#: Standard atmospheric pressure, Pa: the flow is incompressible while the pressure drop is a
#: small part of it (10 % of it changes the density by 10 %).
P_ATM_PA = 101_325.0


def check_positive(name: str, value) -> float:
    """``float(value)`` if it is finite and > 0, else ValueError naming ``name`` and the value.

    >>> check_positive("depth", 0.25)
    0.25
    """
    try:
        v = float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a number > 0, got {value!r}") from exc
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return v


def check_viscosity(viscosity_pa_s) -> float:
    """Dynamic viscosity μ in Pa·s, checked finite and > 0."""
    return check_positive("viscosity_pa_s", viscosity_pa_s)


def check_density(density_kg_m3) -> float:
    """Density ρ in kg/m³, checked finite and > 0."""
    return check_positive("density_kg_m3", density_kg_m3)
