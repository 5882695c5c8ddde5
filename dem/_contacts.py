r"""Linear spring–dashpot contact law with Coulomb friction (PFC3D linear model).

The contact law is a pure function of the contact kinematics: it knows nothing of
neighbour lists, containers or the integrator (STYLE.md item 11). It is written once, as the
numba-compiled scalar function :func:`contact_law` of one contact; the time-step kernels
(:mod:`dem._kernels`) call it for every pair and wall contact, and
:func:`linear_contact_forces` applies it to arrays of contacts.

Conventions (one row per contact): ``normal`` is the unit vector from particle *i*
towards its partner *j* (or towards the wall), ``overlap`` δ = r_i + r_j − |x_j − x_i| > 0,
``v_rel`` is the velocity of the contact point on *i* relative to the one on *j*. The
returned force acts on *i*; *j* receives its negative.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = [
    "series_stiffness",
    "damping_coefficient",
    "restitution_coefficient",
    "damping_ratio_for_restitution",
    "linear_contact_forces",
    "contact_law",
    "rolling_moment",
    "rolling_torque",
]


def series_stiffness(k_a, k_b):
    r"""Contact stiffness of two springs in series, N/m (PFC3D linear contact model).

    .. math:: k = \frac{k_a k_b}{k_a + k_b}

    Two soybeans with k_pn = 4.0e6 N/m touch with k = 2.0e6 N/m; a soybean on a
    Plexiglas wall (1.8e7 N/m) with 3.27e6 N/m.

    >>> float(series_stiffness(4.0e6, 4.0e6))
    2000000.0
    """
    k_a = np.asarray(k_a, dtype=float)
    k_b = np.asarray(k_b, dtype=float)
    return k_a * k_b / (k_a + k_b)


def damping_coefficient(beta, mass_eff_kg, stiffness_n_m):
    r"""Viscous dashpot coefficient for a critical-damping ratio β, N·s/m.

    .. math:: c = 2 \beta \sqrt{m^* k}

    PFC3D "viscous damping" (the thesis sets β = 0.1 in the normal and shear directions,
    Appendix A); m* is the effective mass m_i m_j / (m_i + m_j) (m_i for a wall).
    """
    return 2.0 * np.asarray(beta, dtype=float) * np.sqrt(
        np.asarray(mass_eff_kg, dtype=float) * np.asarray(stiffness_n_m, dtype=float)
    )


def restitution_coefficient(beta):
    r"""Normal coefficient of restitution of a linear spring–dashpot contact.

    .. math:: e = \exp\!\left(-\frac{\pi \beta}{\sqrt{1 - \beta^2}}\right)

    (damped harmonic oscillator, contact ends when the spring force returns to zero;
    exact for the tension-free dashpot only in the limit of small β).
    For β = 0.1, e = 0.7292.

    >>> round(float(restitution_coefficient(0.1)), 4)
    0.7292
    """
    beta = np.asarray(beta, dtype=float)
    if np.any((beta < 0) | (beta >= 1)):
        raise ValueError(f"damping ratio must be in [0, 1), got {beta}")
    return np.exp(-np.pi * beta / np.sqrt(1.0 - beta**2))


def damping_ratio_for_restitution(e):
    r"""Critical-damping ratio β whose linear spring–dashpot contact has restitution e, the
    inverse of :func:`restitution_coefficient`:

    .. math:: \beta = \frac{-\ln e}{\sqrt{\pi^2 + \ln^2 e}}

    >>> round(float(damping_ratio_for_restitution(0.7292)), 4)
    0.1
    """
    e = np.asarray(e, dtype=float)
    if np.any((e <= 0) | (e > 1)):
        raise ValueError(f"restitution must be in (0, 1], got {e}")
    ln = np.log(e)
    return -ln / np.sqrt(np.pi**2 + ln**2)


@numba.njit(inline="always", cache=True, error_model="numpy")
def contact_law(overlap, nx, ny, nz, vx, vy, vz, xx, xy, xz, kn, ks, cn, ct, mu, dt):
    """One contact of :func:`linear_contact_forces` (same arguments, scalars; see there).

    Returns ``(fx, fy, fz, fn, ftx, fty, ftz, xix, xiy, xiz)``: force on *i*, normal force,
    tangential force on *i*, updated spring. The operations are those of the array form, in
    the same order (no fused multiply-add), so both give the same bits.
    """
    vn = vx * nx + vy * ny + vz * nz
    fn = kn * overlap
    fn += cn * vn
    if fn < 0.0:
        fn = 0.0
    vtx = vx - vn * nx
    vty = vy - vn * ny
    vtz = vz - vn * nz
    sn = xx * nx + xy * ny + xz * nz
    xix = xx - sn * nx + vtx * dt
    xiy = xy - sn * ny + vty * dt
    xiz = xz - sn * nz + vtz * dt
    ftx = xix * (-ks) - ct * vtx
    fty = xiy * (-ks) - ct * vty
    ftz = xiz * (-ks) - ct * vtz
    ft_mag = np.sqrt(ftx * ftx + fty * fty + ftz * ftz)
    limit = mu * fn
    if ft_mag > limit:
        scale = limit / ft_mag
        ftx *= scale
        fty *= scale
        ftz *= scale
        inv = -1.0 / ks
        xix = (ftx + ct * vtx) * inv
        xiy = (fty + ct * vty) * inv
        xiz = (ftz + ct * vtz) * inv
    return ftx - fn * nx, fty - fn * ny, ftz - fn * nz, fn, ftx, fty, ftz, xix, xiy, xiz


@numba.njit(inline="always", cache=True, error_model="numpy")
def rolling_moment(mu_r, fn, radius):
    r"""Magnitude of one contact's rolling-friction torque, N·m (EDEM's standard rolling friction,
    the "directional constant torque" of Ai et al. 2011, type A):

    .. math:: M_r = \mu_r F_n R_i

    ``mu_r`` the coefficient of rolling friction (dimensionless), ``fn`` the contact's normal
    force F_n (N), ``radius`` R_i the distance of the contact point from the centre of the
    sphere that touches (m; a sphere of a multi-sphere grain: its own radius). The torque acts
    against the spin of the body the sphere belongs to (:func:`rolling_torque`), so the
    magnitudes of all contacts of one body add.

    >>> rolling_moment(0.04, 2.0, 0.0015)
    0.00012
    """
    return mu_r * fn * radius


@numba.njit(inline="always", cache=True, error_model="numpy")
def rolling_torque(moment, wx, wy, wz, stop):
    r"""Rolling-friction torque on a body of spin ω = (wx, wy, wz) rad/s, N·m, 3-tuple:

    .. math:: \mathbf T_r = -\min(M, M_{stop})\,\frac{\boldsymbol\omega}{|\boldsymbol\omega|},
              \qquad M = \sum_c \mu_r F_{n,c} R_c

    (EDEM's standard rolling friction: each contact c of the body pushes against the body's own
    angular velocity with :func:`rolling_moment`). ω is the spin the body would have at the end of
    the step without this torque (its spin plus Δt I⁻¹ times the other torques on it), and
    ``stop`` :math:`M_{stop}` (N·m) the torque that brings that spin to zero along ω̂ in the step,
    |ω| / (Δt ω̂·I⁻¹ω̂). A constant torque would reverse a spin smaller than M Δt ω̂·I⁻¹ω̂ and
    chatter about ω = 0; limited so, it stops the spin and holds the body at rest while the other
    torques on it stay below M (static rolling resistance: a sphere on a slope stays at rest up
    to tan θ = μ_r, the definition of μ_r by Ai et al. 2011). While the body rolls, ω differs from
    its spin by O(Δt) and the torque is EDEM's. No spin (or M = 0): no torque.

    >>> [round(t, 12) for t in rolling_torque(2.0, 0.0, 3.0, 4.0, 10.0)]
    [-0.0, -1.2, -1.6]
    >>> [round(t, 12) for t in rolling_torque(2.0, 0.0, 3.0, 4.0, 1.0)]
    [-0.0, -0.6, -0.8]
    """
    w = np.sqrt(wx * wx + wy * wy + wz * wz)
    if not (moment > 0.0 and w > 0.0):
        return 0.0, 0.0, 0.0
    m = min(moment, stop) / w
    return -m * wx, -m * wy, -m * wz


@numba.njit(cache=True, error_model="numpy")
def _contact_loop(overlap, normal, v_rel, shear, kn, ks, cn, ct, mu, dt, force, fn, ft, xi):
    for c in range(overlap.shape[0]):
        out = contact_law(overlap[c], normal[0, c], normal[1, c], normal[2, c], v_rel[0, c], v_rel[1, c],
                          v_rel[2, c], shear[0, c], shear[1, c], shear[2, c], kn, ks, cn[c], ct[c], mu, dt)
        force[0, c], force[1, c], force[2, c], fn[c] = out[0], out[1], out[2], out[3]
        ft[0, c], ft[1, c], ft[2, c] = out[4], out[5], out[6]
        xi[0, c], xi[1, c], xi[2, c] = out[7], out[8], out[9]


def linear_contact_forces(overlap, normal, v_rel, shear_disp, *, kn, ks, cn, ct, mu, dt):
    r"""Forces of Nc linear spring–dashpot contacts with a Coulomb-limited shear spring.

    .. math::

        F_n &= \max(0,\; k_n \delta + c_n v_n), \qquad v_n = \mathbf v_{rel}\cdot\mathbf n \\
        \boldsymbol\xi &\leftarrow \boldsymbol\xi - (\boldsymbol\xi\cdot\mathbf n)\mathbf n
                          + \mathbf v_t\,\Delta t, \qquad
        \mathbf F_t = -k_s \boldsymbol\xi - c_t \mathbf v_t, \quad
        |\mathbf F_t| \le \mu F_n

    When the Coulomb limit is exceeded the shear force is scaled back onto the cone
    and the spring is reset to the sliding value
    :math:`\boldsymbol\xi = -(\mathbf F_t + c_t\mathbf v_t)/k_s` (as in LAMMPS
    ``granular hooke/history``). The normal dashpot cannot pull (PFC "notens").

    Vectors are passed component-first, shape (3, Nc) (each component contiguous, which
    is what makes the numpy arithmetic fast); transpose (Nc, 3) data with ``.T``.

    Parameters
    ----------
    overlap : (Nc,) array, m
        δ > 0 for touching pairs.
    normal : (3, Nc) array
        Unit vector from *i* to its partner.
    v_rel : (3, Nc) array, m/s
        Velocity of *i*'s contact point relative to the partner's.
    shear_disp : (3, Nc) array, m
        Accumulated tangential spring displacement ξ (contact history).
    kn, ks : float, N/m
        Contact normal and shear stiffness.
    cn, ct : float or (Nc,) array, N·s/m
        Normal and shear dashpot coefficients.
    mu : float
        Coulomb friction coefficient.
    dt : float, s
        Time step.

    Returns
    -------
    force : (3, Nc) array, N
        Total contact force on *i* (normal + tangential).
    fn : (Nc,) array, N
        Normal force magnitude (≥ 0).
    ft : (3, Nc) array, N
        Tangential force on *i*.
    shear_disp : (3, Nc) array, m
        Updated spring displacement (a new array).
    """
    overlap = np.ascontiguousarray(overlap, dtype=float)
    nc = overlap.shape[0]
    arrays = [np.ascontiguousarray(a, dtype=float) for a in (normal, v_rel, shear_disp)]
    if overlap.ndim != 1 or any(a.shape != (3, nc) for a in arrays):
        raise ValueError(f"need overlap (Nc,) and (3, Nc) vectors, got {overlap.shape}, "
                         f"{[a.shape for a in arrays]}")
    cn_a, ct_a = (np.ascontiguousarray(np.broadcast_to(np.asarray(c, dtype=float), (nc,))) for c in (cn, ct))
    force, ft, xi = np.empty((3, nc)), np.empty((3, nc)), np.empty((3, nc))
    fn = np.empty(nc)
    _contact_loop(overlap, *arrays, float(kn), float(ks), cn_a, ct_a, float(mu), float(dt), force, fn, ft, xi)
    return force, fn, ft, xi
