r"""Branched-path pressure-drop model (thesis section 3.5.1, Appendix F).

Air enters each tetrahedron of a flow path through one face (the *mother tube*, from the
inlet-face centroid :math:`C_0` to the tetrahedron centroid :math:`C_t`) and divides into the
three other faces (the *daughter tubes*, :math:`C_t \to C_i`, :math:`i = 1, 2, 3`). The pressure
drop of one tetrahedron is the straight loss plus the branching loss (Eq. 3.28)

.. math:: \Delta P = \Delta P_S + \Delta P_{b}.

Both are laminar pipe losses written with a Darcy factor :math:`f_D = F/\mathrm{Re}`
(Eqs. 3.30–3.37), which for a pipe of diameter :math:`D`, length :math:`L` and flow rate
:math:`Q` is

.. math:: \Delta P = f_D \frac{L}{D} \frac{\rho V^2}{2}
          = \frac{2 F \mu Q L}{\pi D^4}, \qquad V = \frac{4 Q}{\pi D^2},

so :math:`F = 64` is Hagen–Poiseuille (:math:`128 \mu Q L / \pi D^4`) and the density cancels.
The branches use :math:`F = 2100` (Lee et al. 2007) times a multiplier of the branching angle
:math:`\theta_i` between :math:`C_t - C_0` and :math:`C_i - C_t` (Eq. 3.39):
``'MFx3'`` :math:`f = 3 - 2\cos\theta`, ``'MFx2'`` :math:`f = 2 - \cos\theta`. The mother flow
divides in proportion to the daughter cross-sections (Eq. 3.38), so all daughters carry the same
velocity :math:`Q_0 / \sum_j \pi D_j^2/4`.

Choices the thesis leaves open (which daughters count, closed and lone daughters, the three
local widths) and what they give on a stand-in packing: docs/airpaths-branched.md.

Functions
---------
laminar_pipe_dp(q_m3_s, length_m, diameter_m, *, coefficient=64, mu_pa_s=1.932e-5)
branching_multiplier(theta_rad, kind)
local_width(full_area_m2, open_area_m2, width)
branched_pressure_drop(c_in, c_tet, c_out, d_in, d_out, exit_local, q0_m3_s, ...)

References
----------
Lee, J. W., Kang, M. Y., Yang, S., Kim, J. (2007). Energy loss due to flow branching in
the human bronchial tree. (as cited by the thesis, section 3.5.1).
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from .._air import MU_AIR_PA_S

__all__ = [
    "MULTIPLIERS",
    "WIDTHS",
    "BranchedResult",
    "laminar_pipe_dp",
    "branching_multiplier",
    "equivalent_diameter",
    "local_width",
    "branched_pressure_drop",
]

logger = logging.getLogger(__name__)

#: Multiplier functions of the branching angle (Eq. 3.39).
MULTIPLIERS = ("MFx3", "MFx2")
#: Local flow-path width choices (section 3.5.1).
WIDTHS = ("min", "max", "average")
_BRANCH_SUMS = ("all", "path")


def laminar_pipe_dp(q_m3_s, length_m, diameter_m, *, coefficient=64.0, mu_pa_s=MU_AIR_PA_S):
    r"""Laminar pressure drop of a round pipe with Darcy factor :math:`f_D = F/\mathrm{Re}`, Pa.

    .. math:: \Delta P = \frac{2 F \mu Q L}{\pi D^4}

    (Eqs. 3.30–3.35; :math:`F = 64` is Hagen–Poiseuille, :math:`128\mu Q L/\pi D^4`).

    Parameters
    ----------
    q_m3_s, length_m, diameter_m : array_like, m^3/s, m, m
        Flow rate, pipe length, pipe diameter (broadcast together). A zero diameter gives
        ``inf`` for a nonzero flow and 0 for a zero flow.
    coefficient : float, optional
        :math:`F` (default 64, straight pipe; the thesis uses 2100 in branches).
    mu_pa_s : float, optional
        Dynamic viscosity (default 1.932e-5 Pa s, the thesis's air).

    Returns
    -------
    ndarray, Pa

    Examples
    --------
    >>> import numpy as np
    >>> dp = laminar_pipe_dp(1e-6, 0.1, 1e-3, mu_pa_s=1e-3)
    >>> bool(np.isclose(dp, 128 * 1e-3 * 1e-6 * 0.1 / (np.pi * 1e-12)))
    True
    """
    q = np.asarray(q_m3_s, dtype=float)
    L = np.asarray(length_m, dtype=float)
    D = np.asarray(diameter_m, dtype=float)
    if np.any(D < 0) or np.any(L < 0):
        raise ValueError("pipe lengths and diameters must be >= 0")
    with np.errstate(divide="ignore", invalid="ignore"):
        dp = 2.0 * coefficient * mu_pa_s * q * L / (np.pi * D**4)
    return np.where(q == 0, 0.0, dp)


def branching_multiplier(theta_rad, kind="MFx3"):
    r"""Branching-loss multiplier :math:`f(\theta)` (Eq. 3.39, Lee et al. 2007/2008).

    ``'MFx3'``: :math:`3 - 2\cos\theta` (a 90° branch loses three times a straight one);
    ``'MFx2'``: :math:`2 - \cos\theta` (twice). Both are 1 at :math:`\theta = 0`.

    Parameters
    ----------
    theta_rad : array_like, rad
        Angle between the mother-tube direction and the daughter direction.
    kind : {'MFx3', 'MFx2'}

    Returns
    -------
    ndarray, dimensionless

    Examples
    --------
    >>> float(branching_multiplier(np.pi / 2, "MFx3")), float(branching_multiplier(0.0, "MFx2"))
    (3.0, 1.0)
    """
    th = np.asarray(theta_rad, dtype=float)
    if kind == "MFx3":
        return 3.0 - 2.0 * np.cos(th)
    if kind == "MFx2":
        return 2.0 - np.cos(th)
    raise ValueError(f"unknown multiplier {kind!r}; expected one of {MULTIPLIERS}")


def equivalent_diameter(area_m2):
    r"""Diameter of the circle of the same area, :math:`d = 2\sqrt{S/\pi}` (Eq. 3.24), m.

    Negative areas (a face closed by its grains) give 0.

    Examples
    --------
    >>> float(equivalent_diameter(np.pi))
    2.0
    """
    a = np.asarray(area_m2, dtype=float)
    return 2.0 * np.sqrt(np.clip(a, 0.0, None) / np.pi)


def local_width(full_area_m2, open_area_m2, width="average"):
    r"""Local flow-path width (LFPW) of faces, m (section 3.5.1, Eq. 3.24).

    Parameters
    ----------
    full_area_m2 : array_like, m^2
        Area of the face triangle (Heron, Eq. 3.18): gives the maximum width.
    open_area_m2 : array_like, m^2
        Open area between the three grains (Eq. 3.23): gives the minimum width (0 if <= 0).
    width : {'min', 'max', 'average'}
        ``'average'`` is the arithmetic mean of the minimum and maximum *diameters*. Every
        choice is 0 where the face is closed (open area <= 0): no air passes a closed face,
        whatever the width estimate. (The thesis reselects tetrahedra so that its path
        tetrahedra have no closed face; a Delaunay tetrahedron can have one.)

    Returns
    -------
    ndarray, m
    """
    dmax = equivalent_diameter(full_area_m2)
    dmin = equivalent_diameter(open_area_m2)
    if width == "max":
        return np.where(dmin > 0, dmax, 0.0)
    if width == "min":
        return dmin
    if width == "average":
        return np.where(dmin > 0, 0.5 * (dmin + dmax), 0.0)
    raise ValueError(f"unknown width {width!r}; expected one of {WIDTHS}")


@dataclasses.dataclass(frozen=True)
class BranchedResult:
    """Pressure drops of the branched model along one path (M tetrahedra).

    Attributes
    ----------
    dp_straight_pa : (M,) ndarray, Pa
        Mother-tube (inlet section) loss per tetrahedron.
    dp_branch_pa : (M, 3) ndarray, Pa
        Loss of each daughter tube (0 for a closed one).
    theta_rad : (M, 3) ndarray, rad
        Branching angles.
    dp_tetra_pa : (M,) ndarray, Pa
        Loss counted per tetrahedron (straight + the daughters selected by ``branches``).
    total_pa : float
        Sum over the path.
    """

    dp_straight_pa: np.ndarray
    dp_branch_pa: np.ndarray
    theta_rad: np.ndarray
    dp_tetra_pa: np.ndarray
    total_pa: float


def branched_pressure_drop(
    c_in,
    c_tet,
    c_out,
    d_in,
    d_out,
    exit_local,
    q0_m3_s,
    *,
    multiplier="MFx3",
    branches="path",
    mu_pa_s=MU_AIR_PA_S,
    straight_coefficient=64.0,
    branch_coefficient=2100.0,
):
    r"""Pressure drop of the branched-path model along a chain of M tetrahedra (Eq. 3.28).

    .. math::
        \Delta P_S = \frac{2 \cdot 64\, \mu Q_0 L_0}{\pi D_0^4}, \qquad
        \Delta P_{bi} = f(\theta_i) \frac{2 \cdot 2100\, \mu Q_i L_i}{\pi D_i^4}, \qquad
        Q_i = Q_0 \frac{D_i^2}{\sum_j D_j^2}

    with :math:`L_0 = |C_t - C_0|`, :math:`L_i = |C_i - C_t|` and
    :math:`\cos\theta_i = \widehat{(C_t - C_0)} \cdot \widehat{(C_i - C_t)}` (Eqs. 3.32–3.39).

    Parameters
    ----------
    c_in : (M, 3) array_like, m
        Inlet-face centroids :math:`C_0`.
    c_tet : (M, 3) array_like, m
        Tetrahedron centroids :math:`C_t` (mean of the four vertices).
    c_out : (M, 3, 3) array_like, m
        Centroids of the three outlet faces of each tetrahedron.
    d_in : (M,) array_like, m
        Mother-tube diameter (a local width of the inlet face).
    d_out : (M, 3) array_like, m
        Daughter diameters (0 for a closed face: it carries no flow).
    exit_local : (M,) array_like of int in {0, 1, 2}
        Which daughter the path continues through (used by ``branches='path'``).
    q0_m3_s : float or (M,) array_like, m^3/s
        Flow entering each tetrahedron.
    multiplier : {'MFx3', 'MFx2'}, optional
    branches : {'all', 'path'}, optional
        ``'path'`` (default) keeps the exit daughter only (Eq. 3.28 as written); ``'all'``
        sums the three daughters' losses as the script of Appendix F does.
    mu_pa_s : float, optional
        Viscosity, default 1.932e-5 Pa s.
    straight_coefficient, branch_coefficient : float, optional
        :math:`F` of the mother tube (64) and of dividing daughters (2100). A tetrahedron with a
        single open daughter does not divide: that daughter uses ``straight_coefficient`` and
        no multiplier.

    Returns
    -------
    BranchedResult

    Raises
    ------
    ValueError
        Bad shapes, negative diameters, a tetrahedron with no open daughter or a closed inlet,
        an unknown option.
    """
    c_in = np.asarray(c_in, dtype=float)
    c_tet = np.asarray(c_tet, dtype=float)
    c_out = np.asarray(c_out, dtype=float)
    d_in = np.asarray(d_in, dtype=float)
    d_out = np.asarray(d_out, dtype=float)
    exit_local = np.asarray(exit_local, dtype=np.intp)
    m = c_in.shape[0] if c_in.ndim == 2 else -1
    if (
        c_in.shape != (m, 3)
        or c_tet.shape != (m, 3)
        or c_out.shape != (m, 3, 3)
        or d_in.shape != (m,)
        or d_out.shape != (m, 3)
        or exit_local.shape != (m,)
    ):
        raise ValueError(
            "expected c_in (M,3), c_tet (M,3), c_out (M,3,3), d_in (M,), d_out (M,3), "
            f"exit_local (M,); got {c_in.shape}, {c_tet.shape}, {c_out.shape}, {d_in.shape}, "
            f"{d_out.shape}, {exit_local.shape}"
        )
    if multiplier not in MULTIPLIERS:
        raise ValueError(f"unknown multiplier {multiplier!r}; expected one of {MULTIPLIERS}")
    if branches not in _BRANCH_SUMS:
        raise ValueError(f"unknown branches {branches!r}; expected one of {_BRANCH_SUMS}")
    if np.any(d_in < 0) or np.any(d_out < 0):
        raise ValueError("diameters must be >= 0")
    if np.any((exit_local < 0) | (exit_local > 2)):
        raise ValueError("exit_local must be 0, 1 or 2")
    if np.any(d_in <= 0):
        raise ValueError(f"{int(np.sum(d_in <= 0))} tetrahedra have a closed inlet face (d_in = 0)")
    open_ = d_out > 0
    n_open = open_.sum(axis=1)
    if np.any(n_open == 0):
        raise ValueError(f"{int(np.sum(n_open == 0))} tetrahedra have no open outlet face")
    q0 = np.broadcast_to(np.asarray(q0_m3_s, dtype=float), (m,))

    u0 = c_tet - c_in
    l0 = np.linalg.norm(u0, axis=1)
    ui = c_out - c_tet[:, None, :]
    li = np.linalg.norm(ui, axis=2)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_t = np.einsum("mk,mjk->mj", u0, ui) / (l0[:, None] * li)
    theta = np.arccos(np.clip(np.nan_to_num(cos_t, nan=1.0), -1.0, 1.0))

    dp_s = laminar_pipe_dp(q0, l0, d_in, coefficient=straight_coefficient, mu_pa_s=mu_pa_s)
    share = np.where(open_, d_out**2, 0.0)
    qi = q0[:, None] * share / share.sum(axis=1, keepdims=True)
    divides = (n_open > 1)[:, None]
    coef = np.where(divides, branch_coefficient, straight_coefficient)
    mult = np.where(divides, branching_multiplier(theta, multiplier), 1.0)
    dp_b = mult * laminar_pipe_dp(qi, li, d_out, coefficient=1.0, mu_pa_s=mu_pa_s) * coef
    if branches == "all":
        dp_t = dp_s + dp_b.sum(axis=1)
    else:
        dp_t = dp_s + dp_b[np.arange(m), exit_local]
    return BranchedResult(
        dp_straight_pa=dp_s,
        dp_branch_pa=dp_b,
        theta_rad=theta,
        dp_tetra_pa=dp_t,
        total_pa=float(dp_t.sum()),
    )
