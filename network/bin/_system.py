r"""The bin's system curve, a pressure for a wanted airflow, and the fan's operating point.

Every solve after the first starts from the previous solution scaled to the new pressure, on
the same mesh. The airflow Q(P) of the plenum rises monotonically with the fan's static
pressure P (the law's resistance grows with speed), as Q ∝ P between P^{1/2} (inertial) and
P (Darcy): :func:`pressure_for_airflow` finds P by the secant method on ln Q against ln P.
The fan's operating point is where the fan curve crosses the computed system curve
(``network.report``'s :func:`~network.report.system.operating_point` on the curve's points,
log-log interpolated), then solved exactly by the secant method on P - P_fan(Q(P)).
"""

from __future__ import annotations

import math

import numpy as np

from ..report.system import curve_range, operating_point
from ._solve import NewtonFailure

__all__ = ["solve_checked", "system_curve", "pressure_for_airflow", "fan_operating_point"]


def solve_checked(problem, pressure_pa, p0=None):
    """:meth:`BinProblem.solve`, NewtonFailure naming the pressure when it did not converge."""
    sol = problem.solve(pressure_pa, p0)
    if not sol.converged:
        raise NewtonFailure(f"Newton's method did not converge at a static pressure of "
                            f"{pressure_pa:.6g} Pa (residual {sol.residual:.2e} after "
                            f"{sol.iterations} iterations)")
    return sol


def system_curve(problem, pressures_pa, start=None):
    """Solutions at ascending pressures, each from the previous one (or ``start``)."""
    out, p0 = [], None if start is None else start.p
    for P in sorted(pressures_pa):
        s = solve_checked(problem, float(P), p0)
        out.append(s)
        p0 = s.p
    return out


def pressure_for_airflow(problem, airflow_m3_s, guess_pa, *, rtol=1e-9, maxiter=40):
    """The solution whose plenum inflow is ``airflow_m3_s`` (relative tolerance ``rtol``)."""
    lq = math.log(airflow_m3_s)
    s = solve_checked(problem, guess_pa)
    pts = [(math.log(guess_pa), math.log(s.inflow_m3_s))]
    n = 0.8                                   # d ln Q / d ln P to start
    for _ in range(maxiter):
        if abs(s.inflow_m3_s / airflow_m3_s - 1) <= rtol:
            return s
        if len(pts) >= 2 and pts[-1][0] != pts[-2][0]:
            n = (pts[-1][1] - pts[-2][1]) / (pts[-1][0] - pts[-2][0])
            n = min(max(n, 0.3), 1.2)
        lp = pts[-1][0] + (lq - pts[-1][1]) / n
        s = solve_checked(problem, math.exp(lp), s.p)
        pts.append((lp, math.log(s.inflow_m3_s)))
    raise NewtonFailure(f"no static pressure found for {airflow_m3_s:.6g} m^3/s in {maxiter} "
                        f"solves (last {math.exp(pts[-1][0]):.6g} Pa gave "
                        f"{math.exp(pts[-1][1]):.6g} m^3/s)")


def _dense(q, p, n=400):
    lq, lp = np.log(q), np.log(p)
    qq = np.geomspace(q[0], q[-1], n)
    return qq, np.exp(np.interp(np.log(qq), lq, lp))


def fan_operating_point(problem, curve, fan_q, fan_p, *, rtol=1e-9, maxiter=40):
    """(solution at the operating point, None) or (None, message with both ranges)."""
    q = np.array([s.inflow_m3_s for s in curve])
    p = np.array([s.pressure_pa for s in curve])
    sq, sp = _dense(q, p)
    op = operating_point(sq, sp, fan_q, fan_p)
    if op is None:
        return None, ("no operating point: " + curve_range("system curve", sq, sp) + "; "
                      + curve_range("fan", fan_q, fan_p))
    near = curve[int(np.argmin(np.abs(p - op[1])))]
    P0 = op[1]
    s0 = solve_checked(problem, P0, near.p)
    f0 = P0 - float(np.interp(s0.inflow_m3_s, fan_q, fan_p))
    if abs(f0) <= rtol * P0:
        return s0, None
    P1 = P0 * (1 - 0.01 * np.sign(f0))
    s1 = solve_checked(problem, P1, s0.p)
    for _ in range(maxiter):
        f1 = P1 - float(np.interp(s1.inflow_m3_s, fan_q, fan_p))
        if abs(f1) <= rtol * P1 or f1 == f0:
            return s1, None
        P0, f0, P1 = P1, f1, P1 - f1 * (P1 - P0) / (f1 - f0)
        s1 = solve_checked(problem, P1, s1.p)
    return s1, None
