"""The one result type of the conductance stage, whatever the model."""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["ConductanceResult"]


@dataclasses.dataclass(frozen=True)
class ConductanceResult:
    """Conductances of M throats and how they were obtained.

    Attributes
    ----------
    g : (M,) ndarray, m³ Pa⁻¹ s⁻¹
        Hydraulic conductance of each throat (its whole pore-throat-pore conduit).
    model : str
        ``'thesis'`` or ``'conduit'``.
    qstar : (M,) ndarray
        Window Q* in mean-radius units (NaN where not needed: throats inside a pore body).
    stats : dict
        JSON-ready summary (policy, Q* sources, seconds, model options); what ``network.solve``
        writes under ``"qstar"``.
    h_m : (M, 2) ndarray or None
        Conduit heights on each side of the window (conduit model), m.
    internal : (M,) bool ndarray or None
        Throats inside one merged pore body (conduit model).
    """

    g: np.ndarray
    model: str
    qstar: np.ndarray
    stats: dict
    h_m: np.ndarray | None = dataclasses.field(default=None, repr=False)
    internal: np.ndarray | None = dataclasses.field(default=None, repr=False)
