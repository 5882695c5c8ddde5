r"""The conduit model's sections: the flow rate of a throat section at height h above the face,
and the resistance of a conduit half integrated over them (:func:`side_resistance`, the
equation in :mod:`network.conductance._conduit`'s module docstring).
"""

from __future__ import annotations

import numpy as np

import throats

__all__ = ["colmax", "section_estimate", "side_resistance"]


def section_estimate(rho, sides):
    r"""Closed-form flow-rate estimate of throat sections: Happel's cell model.

    The section (triangle with a disk at each vertex, symmetry on the edges) is a cell of a
    2-D array of cylinders with flow along their axes. Happel's (1959) free-surface cell model
    of that flow (AIChE J. 5:174; also Sparrow & Loeffler 1959 for exact square and hexagonal
    arrays) gives the permeability :math:`K = (b^2/4) f(\phi)` of a cell of radius b, with

    .. math:: f(\phi) = -\ln\phi - \tfrac32 + 2\phi - \tfrac12\phi^2,
              \qquad \phi = 1 - A/A_\triangle,

    the solid fraction of the section (A: exact open area, :func:`throats.open_area`;
    :math:`A_\triangle`: triangle area). The disks' angles at the vertices add up to
    :math:`\pi`, so a triangle holds half a cylinder and is half a cell,
    :math:`\pi b^2 = 2A_\triangle`, and the flow rate per unit pressure gradient is

    .. math:: Q \approx K A_\triangle = \frac{A_\triangle^2}{2\pi} f(\phi).

    Against FE on the simple-cubic section (right isosceles triangle, legs 1, equal disks
    :math:`\rho`): -0.7, -1.2, -2.8, -4.5, -7.5, -13, -24 % at :math:`\rho` = 0.05, 0.1, 0.2, 0.25,
    0.3, 0.35, 0.4 (the cell model is a dilute theory), where the wetted-perimeter estimate
    :math:`A^3/(2P_w^2)` is 18, 7.1, 3.2, 2.5, 2.1, 1.7, 1.4 times FE. Used for ratios
    :math:`Q(h)/Q(h')` along one conduit: all sections share the triangle, so the ratio
    depends on the solid fractions alone. :math:`f` falls to 0 as :math:`(1-\phi)^3/3` when
    the disks close the section.

    Parameters
    ----------
    rho : (N, 3) array_like
        Disk radii at the vertices (0 allowed), any length unit.
    sides : (N, 3) array_like
        [l12, l13, l23], same unit.

    Returns
    -------
    q : (N,) ndarray
        Flow rate per unit pressure gradient times viscosity, unit⁴; ``inf`` where no disk
        is left (no wall).

    Examples
    --------
    Square array of cylinders of radius 0.1 (spacing 1), half a cell; FE gives 0.0814:

    >>> round(float(section_estimate([[0.1] * 3], [[1.0, 1.0, 2 ** 0.5]])[0]), 4)
    0.0805
    """
    rho = np.asarray(rho, dtype=float)
    s = np.asarray(sides, dtype=float)
    q = np.full(rho.shape[0], np.inf)
    live = rho.max(axis=1) > 0
    if not live.any():
        return q
    # throats.open_area wants positive radii: a vanished disk becomes a point (area 1e-24 l²)
    point = 1e-12 * s[live].min(axis=1, keepdims=True)
    area = throats.open_area(np.maximum(rho[live], point), s[live])
    a_tri = throats.triangle_area(s[live])
    phi = np.clip(1.0 - area / a_tri, 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = -np.log(phi) - 1.5 + 2.0 * phi - 0.5 * phi**2
        q[live] = np.where(phi > 0, a_tri**2 * np.maximum(f, 0.0) / (2.0 * np.pi), np.inf)
    return q


def _section_radii(radii, h):
    """Disk radii (N, m, 3) of the sections at heights h (N, m)."""
    out = np.square(radii)[:, None, :] - np.square(h)[..., None]     # same bits as r**2 - h**2
    np.maximum(out, 0.0, out=out)
    return np.sqrt(out, out=out)


def colmax(a):
    """Largest entry along the last axis (length 2 or 3): np.max(a, axis=-1), same values,
    without numpy's slow reduction over a short axis."""
    out = np.maximum(a[..., 0], a[..., 1])
    for c in range(2, a.shape[-1]):
        np.maximum(out, a[..., c], out=out)
    return out


def side_resistance(radii, sides, h_side, y_window, *, n_sections: int = 8,
                    section_q=None, section_factor=None):
    r"""Viscosity-free resistance :math:`R_P/\mu` of N conduit halves (unit⁻³).

    .. math:: \frac{R_P}{\mu} = \int_0^{H_P} y\,\Bigl[1 + \frac{s}{1+s}\Bigr] dh,\quad
              s = \tfrac43 a_{eq}'^2 = \frac{1}{12}\sqrt{\frac{8}{\pi y}}\Bigl(\frac{y'}{y}\Bigr)^2

    Parameters
    ----------
    radii, sides : (N, 3) array_like
        The window's sphere radii and side lengths (one length unit).
    h_side : (N,) or (N, k) array_like
        Height of the pore centre above the face plane (same unit), >= 0; with k columns
        (the two sides of a throat) all sides share one set of sections, sampled up to the
        largest height, and each is integrated up to its own.
    y_window : (N,) array_like
        :math:`1/(Q^*\bar r^4)` of the window (unit⁻⁴); ``inf`` for a closed window.
    n_sections : int, keyword-only
        Intervals per side (default 8).
    section_q : callable or None, keyword-only
        ``section_q(rho (M,3), sides (M,3)) -> (M,)`` flow rate of sections (unit⁴, inf when
        no wall, NaN when the source cannot answer reliably: such a section is continued
        from the last answered one by :func:`section_estimate` ratios). None: the window
        value scaled by :func:`section_estimate` ratios.
    section_factor : callable or None, keyword-only
        ``section_factor(h (N, m+1)) -> (N, k, m+1)``: the flow rate of each side's section at
        the nodes h, relative to the three-disk section's (sections that other spheres cut
        too, :mod:`._mates`; 0 closes the section). None: 1.

    Returns
    -------
    (N,) or (N, k) ndarray
        Resistance divided by viscosity; 0 where ``h_side`` is 0, ``inf`` for closed windows.

    Examples
    --------
    A section that does not change (here: h beyond the disks is cut off, radii 0) gives
    ``y * h``; with no disk at all the conduit has no wall and no resistance:

    >>> float(side_resistance([[0., 0., 0.]], [[1., 1., 1.]], [0.5], [2.0])[0])
    0.0
    """
    radii = np.asarray(radii, dtype=float)
    sides = np.asarray(sides, dtype=float)
    h_side = np.asarray(h_side, dtype=float)
    one = h_side.ndim == 1
    hs = h_side[:, None] if one else h_side                      # (N, k) sides
    y0 = np.asarray(y_window, dtype=float)
    n = radii.shape[0]
    m = int(n_sections)
    if m < 2:
        raise ValueError(f"n_sections must be >= 2, got {n_sections!r}")
    rmax = colmax(radii)
    H = np.minimum(np.maximum(hs, 0.0), rmax[:, None])           # (N, k)
    Hmax = colmax(H) if H.shape[1] > 1 else H[:, 0]
    # one set of nodes serves every side of a throat (the sections depend on h only),
    # uniform in theta with h = rmax sin(theta): the disks shrink smoothly,
    # rho_k = sqrt(r_k^2 - h^2), and the nodes gather where the sphere walls turn steep
    with np.errstate(invalid="ignore", divide="ignore"):
        th_end = np.arcsin(np.clip(np.where(rmax > 0, Hmax / rmax, 0.0), 0.0, 1.0))
    t = np.linspace(0.0, 1.0, m + 1)
    theta = th_end[:, None] * t[None, :]                          # (N, m+1)
    h = rmax[:, None] * np.sin(theta)
    dhdth = rmax[:, None] * np.cos(theta)
    rho = _section_radii(radii, h)                               # (N, m+1, 3)
    flat_rho = rho.reshape(-1, 3)
    if section_q is None:
        q = section_estimate(flat_rho, np.repeat(sides, m + 1, axis=0)).reshape(n, m + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(np.isinf(q), 0.0, y0[:, None] * q[:, :1] / q)
        y[:, 0] = y0
    else:
        q = np.full(n * (m + 1), np.inf)
        # the window (node 0) is y_window already; sections with no disk left have no wall
        live = colmax(rho) > 0                                  # (N, m+1)
        live[:, 0] = False
        live &= (Hmax > 0)[:, None]
        idx = np.flatnonzero(live)
        if idx.size:
            q[idx] = section_q(flat_rho[idx], sides[idx // (m + 1)])
        q = q.reshape(n, m + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(np.isinf(q), 0.0, 1.0 / q)
        y[:, 0] = y0
        miss = np.isnan(y)
        if miss.any():
            # sections the Q* source could not answer reliably (outside the table: NaN) are
            # continued from the last answered section by closed-form ratios
            bad = np.flatnonzero(miss.any(axis=1))
            mb = miss[bad]
            ce = section_estimate(rho[bad].reshape(-1, 3),
                                  np.repeat(sides[bad], m + 1, axis=0)).reshape(-1, m + 1)
            j = np.arange(m + 1)[None, :]
            last = np.maximum.accumulate(np.where(~mb, j, 0), axis=1)
            rows = np.arange(bad.size)[:, None]
            yb = y[bad]
            with np.errstate(divide="ignore", invalid="ignore"):
                cont = np.where(np.isinf(ce), 0.0, yb[rows, last] * ce[rows, last] / ce)
            y[bad] = np.where(mb, cont, yb)
    if section_factor is not None:
        with np.errstate(divide="ignore"):
            ys = y[:, None, :] / section_factor(h)             # (N, k, m+1); 0: closed
        R = np.empty_like(H)
        for c in range(H.shape[1]):
            # nodes side c integrates over: up to the first at or above its height
            jc = np.clip((h < (H[:, c] * (1 - 1e-12))[:, None]).sum(axis=1), 1, m)
            used = np.arange(m + 1)[None, :] <= jc[:, None]
            yc = ys[:, c]
            bad = used & ~np.isfinite(yc)
            yc = np.where(np.isfinite(yc), yc, np.where(used, yc, y))
            R[:, c] = _integrate(yc, y0, h, dhdth, th_end, H[:, c:c + 1], m)[:, 0]
            R[:, c] = np.where(bad.any(axis=1) & (H[:, c] > 0), np.inf, R[:, c])
        return R[:, 0] if one else R
    R = _integrate(y, y0, h, dhdth, th_end, H, m)
    return R[:, 0] if one else R


def _integrate(y, y0, h, dhdth, th_end, H, m):
    """:func:`side_resistance`'s integral of the sections' y at the nodes h (N, m+1) up to
    each column of H (N, k)."""
    n = y.shape[0]
    fin = np.isfinite(y)
    closed = ~np.isfinite(y0)
    for c in range(m + 1):                                      # any(~fin, axis=1), by columns
        closed |= ~fin[:, c]
    y = np.where(fin, y, 0.0)
    dth = np.maximum(th_end / m, 1e-300)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # inf: a steep wall
        dy = np.gradient(y, axis=1) / dth[:, None] / dhdth
    dy[:, 0] = 0.0                                              # symmetry at the window
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.sqrt(8.0 / (np.pi * y)) * (dy / y) ** 2 / 12.0
        f = np.where(y > 0, 1.0 + s / (1.0 + s), 1.0)
    f = np.where(np.isnan(f), 2.0, f)                           # s = inf/inf: steep wall
    F = y * f                                                   # (N, m+1)
    seg = 0.5 * (F[:, 1:] + F[:, :-1]) * np.diff(h, axis=1)     # (N, m)
    C = np.concatenate([np.zeros((n, 1)), np.cumsum(seg, axis=1)], axis=1)
    R = np.empty_like(H)
    rows = np.arange(n)
    for c in range(H.shape[1]):
        Hc = H[:, c]
        # the segment [h_{j-1}, h_j] holding Hc; trapezoid up to h_{j-1}, then the part
        # segment with F linearly interpolated
        below = Hc * (1 - 1e-12)
        j = np.zeros(n, dtype=np.int64)
        for c2 in range(m + 1):                                 # nodes below Hc, by columns
            j += h[:, c2] < below
        np.clip(j, 1, m, out=j)
        h0, h1 = h[rows, j - 1], h[rows, j]
        F0, F1 = F[rows, j - 1], F[rows, j]
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(h1 > h0, (Hc - h0) / (h1 - h0), 0.0)
        w = np.clip(w, 0.0, 1.0)
        R[:, c] = C[rows, j - 1] + (Hc - h0) * (F0 + 0.5 * w * (F1 - F0))
    R = np.where(H > 0, R, 0.0)
    return np.where(closed[:, None], np.inf, R)
