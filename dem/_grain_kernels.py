r"""The compiled kernels of the rigid-grain step (numba): grain poses to spheres, spheres to grains.

A grain g is a rigid body of spheres s (contiguous, ``start[g]:start[g+1]``) with body-frame
offsets :math:`\mathbf b_s` (m), centre :math:`\mathbf X_g`, velocity :math:`\mathbf V_g`,
unit quaternion :math:`q_g` (w, x, y, z; body to world) and world angular momentum
:math:`\mathbf L_g` (kg m² s⁻¹, scaled inertia). Between the two kernels run the sphere step's
own contact kernels (:func:`dem._kernels.pair_forces`, :func:`dem._kernels.particle_update`
without its update), so grains and spheres share one contact law, one neighbour list and one
wall treatment.

1. :func:`grain_poses`, one iteration per grain: :math:`R = R(q)`,
   :math:`\boldsymbol\omega = R\,(S I)^{-1} R^T \mathbf L` (I the principal moments, S the mass
   scale), and for each of its spheres :math:`\mathbf d_s = R\mathbf b_s`,
   :math:`\mathbf x_s = \mathbf X + \mathbf d_s`,
   :math:`\mathbf v_s = \mathbf V + \boldsymbol\omega\times\mathbf d_s`, spin
   :math:`\boldsymbol\omega`. The sphere kernels then see the contact-point velocity
   :math:`\mathbf v_s + \boldsymbol\omega\times r_s\mathbf n = \mathbf V + \boldsymbol\omega\times
   (\mathbf d_s + r_s\mathbf n)`, that of the grain.
2. :func:`grain_update`, one iteration per grain: its spheres' forces :math:`\mathbf F_s` and
   torques :math:`\mathbf T_s = r_s\,\mathbf n\times\mathbf F_t` (about the sphere centres)
   summed in sphere order, :math:`\mathbf F = \sum_s \mathbf F_s - S m g\,\hat{\mathbf z}`,
   :math:`\mathbf T = \sum_s (\mathbf d_s\times\mathbf F_s + \mathbf T_s)` (the arm of each
   contact point is :math:`\mathbf d_s + r_s\mathbf n`, and :math:`\mathbf n\times\mathbf F =
   \mathbf n\times\mathbf F_t`), plus the rolling torque of the grain's contacts
   (:func:`dem._contacts.rolling_torque` of the summed moments :math:`M = \sum_c \mu_r F_{n,c} r_c`,
   against the spin :math:`\boldsymbol\omega^*` the step gives without it, limited to the torque
   that stops that spin in the step, :math:`|\omega^*| / (\Delta t\,\hat\omega^*\cdot (SI)^{-1}\hat\omega^*)`;
   :func:`grain_rolling`); then, when asked, the update

.. math::

    \mathbf V \mathrel{+}= \mathbf F\,\Delta t/(S m),\quad \mathbf X \mathrel{+}= \mathbf V\Delta t,
    \quad \mathbf L \mathrel{+}= \mathbf T\Delta t,\quad
    q_{1/2} = e^{\boldsymbol\omega(q)\Delta t/2} q,\quad
    q \leftarrow \frac{e^{\boldsymbol\omega(q_{1/2})\Delta t} q}{|e^{\boldsymbol\omega(q_{1/2})\Delta t} q|},

with :math:`e^{\boldsymbol\phi} = (\cos\tfrac{|\phi|}{2}, \tfrac{\boldsymbol\phi}{|\phi|}\sin\tfrac{|\phi|}{2})`
(series :math:`\tfrac12 - |\phi|^2/48` for the sine factor below 1e-8 rad). Without torque L is
unchanged bit for bit.
"""

from __future__ import annotations

import numba
import numpy as np

from ._contacts import rolling_torque

__all__ = ["advance_one", "finish_grain", "grain_poses", "grain_rolling", "grain_update", "pose_one", "update_one"]


@numba.njit(inline="always", cache=True, error_model="numpy")
def _matrix(w, x, y, z):
    """Rotation matrix of the quaternion (w, x, y, z), row by row (as :func:`dem._rigid.quat_to_matrix`)."""
    return (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y))


@numba.njit(inline="always", cache=True, error_model="numpy")
def _omega(m, lx, ly, lz, ix, iy, iz):
    r"""World angular velocity :math:`R\,\mathrm{diag}(1/I)\,R^T\mathbf L` (rad/s) for the matrix ``m``."""
    bx = (m[0] * lx + m[3] * ly + m[6] * lz) / ix
    by = (m[1] * lx + m[4] * ly + m[7] * lz) / iy
    bz = (m[2] * lx + m[5] * ly + m[8] * lz) / iz
    return (m[0] * bx + m[1] * by + m[2] * bz, m[3] * bx + m[4] * by + m[5] * bz, m[6] * bx + m[7] * by + m[8] * bz)


@numba.njit(inline="always", cache=True, error_model="numpy")
def _rotate_by(px, py, pz, w, x, y, z):
    r""":math:`e^{\phi} q` as (w, x, y, z): the unit quaternion of the rotation vector
    :math:`\phi` = (px, py, pz) (angle :math:`|\phi|` in rad about :math:`\phi/|\phi|`) times q."""
    angle = np.sqrt(px * px + py * py + pz * pz)
    half = 0.5 * angle
    s = np.sin(half) / angle if angle > 1e-8 else 0.5 - angle**2 / 48.0
    aw, ax, ay, az = np.cos(half), px * s, py * s, pz * s
    return (aw * w - ax * x - ay * y - az * z,
            aw * x + ax * w + ay * z - az * y,
            aw * y - ax * z + ay * w + az * x,
            aw * z + ax * y - ay * x + az * w)


@numba.njit(inline="always", cache=True, error_model="numpy")
def pose_one(g, X, V, q, L, inertia, start, body, x, v, w, arm):
    """:func:`grain_poses` for grain ``g`` alone (the body of its loop)."""
    m = _matrix(q[g, 0], q[g, 1], q[g, 2], q[g, 3])
    ox, oy, oz = _omega(m, L[g, 0], L[g, 1], L[g, 2], inertia[g, 0], inertia[g, 1], inertia[g, 2])
    for s in range(start[g], start[g + 1]):
        dx = m[0] * body[s, 0] + m[1] * body[s, 1] + m[2] * body[s, 2]
        dy = m[3] * body[s, 0] + m[4] * body[s, 1] + m[5] * body[s, 2]
        dz = m[6] * body[s, 0] + m[7] * body[s, 1] + m[8] * body[s, 2]
        arm[s, 0], arm[s, 1], arm[s, 2] = dx, dy, dz
        x[s, 0], x[s, 1], x[s, 2] = X[g, 0] + dx, X[g, 1] + dy, X[g, 2] + dz
        v[s, 0] = V[g, 0] + (oy * dz - oz * dy)
        v[s, 1] = V[g, 1] + (oz * dx - ox * dz)
        v[s, 2] = V[g, 2] + (ox * dy - oy * dx)
        w[s, 0], w[s, 1], w[s, 2] = ox, oy, oz


@numba.njit(parallel=True, cache=True, error_model="numpy")
def grain_poses(X, V, q, L, inertia, start, body, x, v, w, arm):
    """Sphere state from the grain state (step 1 of the module notes); writes ``x, v, w, arm``.

    ``X, V, L`` (G, 3) m, m/s, kg m²/s; ``q`` (G, 4); ``inertia`` (G, 3) scaled principal moments,
    kg m²; ``start`` (G+1,) int64; ``body`` (N, 3) body-frame offsets, m; outputs (N, 3): sphere
    centres (m), velocities (m/s), spins (rad/s), world offsets d_s = R b_s (m).
    """
    for g in numba.prange(X.shape[0]):
        pose_one(g, X, V, q, L, inertia, start, body, x, v, w, arm)


@numba.njit(inline="always", cache=True, error_model="numpy")
def grain_rolling(g, q, L, inertia, mr, dt, tx, ty, tz):
    r"""Rolling torque on grain g for the summed rolling moment ``mr`` (N·m), the other torques
    (tx, ty, tz) acting: against the spin :math:`\boldsymbol\omega^* = I^{-1}(\mathbf L + \mathbf T\Delta t)`
    the step gives without it, limited to :math:`|\omega^*| / (\Delta t\,\hat\omega^*\cdot I^{-1}\hat\omega^*)`
    (:func:`dem._contacts.rolling_torque`; I the scaled inertia in the world frame)."""
    m = _matrix(q[g, 0], q[g, 1], q[g, 2], q[g, 3])
    ix, iy, iz = inertia[g, 0], inertia[g, 1], inertia[g, 2]
    ox, oy, oz = _omega(m, L[g, 0] + tx * dt, L[g, 1] + ty * dt, L[g, 2] + tz * dt, ix, iy, iz)
    w = np.sqrt(ox * ox + oy * oy + oz * oz)
    if not w > 0.0:
        return 0.0, 0.0, 0.0
    ux, uy, uz = ox / w, oy / w, oz / w
    cx, cy, cz = _omega(m, ux, uy, uz, ix, iy, iz)
    return rolling_torque(mr, ox, oy, oz, w / (dt * (ux * cx + uy * cy + uz * cz)))


@numba.njit(inline="always", cache=True, error_model="numpy")
def finish_grain(g, fx, fy, fz, tx, ty, tz, mr, X, V, q, L, inertia, weight, inv_m, dt, force, torque, advance):
    """Grain ``g``'s step from its summed sphere forces (fx, fy, fz) N, torques (tx, ty, tz) N·m and
    rolling moment ``mr`` N·m: the rolling torque (:func:`grain_rolling`), its weight, the sums
    written to ``force``/``torque`` and, when ``advance``, the update (:func:`advance_one`)."""
    if mr > 0.0:
        rx, ry, rz = grain_rolling(g, q, L, inertia, mr, dt, tx, ty, tz)
        tx += rx
        ty += ry
        tz += rz
    fz -= weight[g]
    force[g, 0], force[g, 1], force[g, 2] = fx, fy, fz
    torque[g, 0], torque[g, 1], torque[g, 2] = tx, ty, tz
    if advance:
        advance_one(g, fx, fy, fz, tx, ty, tz, X, V, q, L, inertia, inv_m, dt)


@numba.njit(inline="always", cache=True, error_model="numpy")
def update_one(g, X, V, q, L, inertia, start, arm, force_s, torque_s, roll_s, weight, inv_m, dt, force, torque,
               advance):
    """:func:`grain_update` for grain ``g`` alone (the body of its loop)."""
    fx = fy = fz = 0.0
    tx = ty = tz = 0.0
    mr = 0.0
    for s in range(start[g], start[g + 1]):
        f0, f1, f2 = force_s[s, 0], force_s[s, 1], force_s[s, 2]
        fx += f0
        fy += f1
        fz += f2
        tx += (arm[s, 1] * f2 - arm[s, 2] * f1) + torque_s[s, 0]
        ty += (arm[s, 2] * f0 - arm[s, 0] * f2) + torque_s[s, 1]
        tz += (arm[s, 0] * f1 - arm[s, 1] * f0) + torque_s[s, 2]
        mr += roll_s[s]
    finish_grain(g, fx, fy, fz, tx, ty, tz, mr, X, V, q, L, inertia, weight, inv_m, dt, force, torque, advance)


@numba.njit(inline="always", cache=True, error_model="numpy")
def advance_one(g, fx, fy, fz, tx, ty, tz, X, V, q, L, inertia, inv_m, dt):
    """The update of grain ``g`` under its net force (fx, fy, fz) and torque (tx, ty, tz) (module
    notes; :func:`update_one` after its sums)."""
    V[g, 0] += fx * inv_m[g]
    V[g, 1] += fy * inv_m[g]
    V[g, 2] += fz * inv_m[g]
    X[g, 0] += V[g, 0] * dt
    X[g, 1] += V[g, 1] * dt
    X[g, 2] += V[g, 2] * dt
    L[g, 0] += tx * dt
    L[g, 1] += ty * dt
    L[g, 2] += tz * dt
    lx, ly, lz = L[g, 0], L[g, 1], L[g, 2]
    ix, iy, iz = inertia[g, 0], inertia[g, 1], inertia[g, 2]
    qw, qx, qy, qz = q[g, 0], q[g, 1], q[g, 2], q[g, 3]
    ox, oy, oz = _omega(_matrix(qw, qx, qy, qz), lx, ly, lz, ix, iy, iz)
    hw, hx, hy, hz = _rotate_by(ox * (0.5 * dt), oy * (0.5 * dt), oz * (0.5 * dt), qw, qx, qy, qz)
    ox, oy, oz = _omega(_matrix(hw, hx, hy, hz), lx, ly, lz, ix, iy, iz)
    nw, nx, ny, nz = _rotate_by(ox * dt, oy * dt, oz * dt, qw, qx, qy, qz)
    norm = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    q[g, 0], q[g, 1], q[g, 2], q[g, 3] = nw / norm, nx / norm, ny / norm, nz / norm


@numba.njit(parallel=True, cache=True, error_model="numpy")
def grain_update(X, V, q, L, inertia, start, arm, force_s, torque_s, roll_s, weight, inv_m, dt, force, torque,
                 advance):
    """Net force and torque on every grain (step 2 of the module notes), and the update.

    ``arm`` (N, 3) from :func:`grain_poses`; ``force_s``, ``torque_s`` (N, 3) the spheres' contact
    forces (N) and torques about their centres (N m); ``roll_s`` (N,) the spheres' summed rolling
    moments (N m), whose torque acts against the grain's spin (module notes); ``weight`` (G,)
    S m g, N; ``inv_m`` (G,) Δt/(S m); writes ``force``, ``torque`` (G, 3); ``advance``: also
    update V, X, L, q.
    """
    for g in numba.prange(X.shape[0]):
        update_one(g, X, V, q, L, inertia, start, arm, force_s, torque_s, roll_s, weight, inv_m, dt, force, torque,
                   advance)
