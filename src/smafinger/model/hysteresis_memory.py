"""Stack operations of the return-point-memory rule for Eqs. (9)-(10) (Madelung's rules).

A branch is written about its anchor: xi = x0 + slope (g - g0), g = g_A(tau_A) on a heating
branch (direction +1), g = g_M(tau_M) on a cooling branch (-1). A branch through the anchor
(g_r, x_r) aimed at the target (g_t, x_t) has slope (x_r - x_t)/(g_r - g_t) (0 when the two g
are equal: ``docs/hysteresis.md`` shows that their xi are then equal too).

Stack rows (one reversal point each; columns ``S_*``): tau_A, tau_M, xi, g_A, g_M of the
point, then x0, g0, slope of the branch that reached it, resumed when the point is passed
again. With ``depth`` rows in use:

- the current branch passes through the current point and is aimed at row depth-2 (its
  target), or at the end of the major curve (heating: xi = 0 at g_A = 0; cooling: xi = 1 at
  g_M = 1) when depth < 2;
- row j stores a branch through row j aimed at row j-2 (the end of the major curve for
  j < 2), in the direction that reached row j;
- reaching the target (tau_A >= target's on heating, tau_M <= target's on cooling) drops the
  target and every row above it and resumes the target's stored branch: continuous because
  that branch passes through the target, and the same numbers as before the excursion.

A wire with no known history (the first motion, or a clamp to the major loop, which erases
the history as reaching a major curve does) starts on the major curve it lies on, or, inside
the loop, on the first-order cooling curve from the point R of the major heating curve that
passes through it (:func:`_no_history`).

Overflow (a reversal with a full stack) merges the innermost loop: the two rows under the
new point are dropped and the new point's stored branch is re-aimed through it at row
depth-4. A branch between two points of equal g is flat, which needs their xi equal; the
rules above guarantee it, a merge need not, so a row a new branch could not end at is
dropped with its loop (``_unreachable``). Continuity, monotonicity and the major loop are
kept; the merged loops' return points are lost (counted in ``merges``).
"""

import math

from ..jit import njit
from .kinetics import g_cooling, g_heating

S_TAU_A, S_TAU_M, S_XI, S_G_A, S_G_M, S_X0, S_G0, S_SLOPE = range(8)
STACK_COLUMNS = 8
LOOP_TOL = 1e-12  # a committed excursion out of the major loop beyond this is clamped and counted


@njit(cache=True, forceinline=True)
def _tau_col(d):
    return S_TAU_A if d > 0 else S_TAU_M


@njit(cache=True, forceinline=True)
def _g_col(d):
    return S_G_A if d > 0 else S_G_M


@njit(cache=True, forceinline=True)
def _reached(d, tau, target_tau):
    """True once tau has reached the target in direction d (heating: rising, cooling: falling)."""
    if d > 0:
        return tau >= target_tau
    return tau <= target_tau


@njit(cache=True, forceinline=True)
def branch_slope(x_r, g_r, x_t, g_t):
    """Slope b >= 0 of the branch through (g_r, x_r) aimed at (g_t, x_t); 0 when g_r == g_t."""
    dg = g_r - g_t
    if dg == 0.0:
        return 0.0
    b = (x_r - x_t) / dg
    if b > 0.0:
        return b
    return 0.0


@njit(cache=True, forceinline=True)
def _target_point(stack, depth, d):
    """(tau, xi, g) of the target of a branch in direction d with ``depth`` rows in use."""
    if depth >= 2:
        t = depth - 2
        return stack[t, _tau_col(d)], stack[t, S_XI], stack[t, _g_col(d)]
    if d > 0:
        return math.inf, 0.0, 0.0
    return -math.inf, 1.0, 1.0


@njit(cache=True, forceinline=True)
def aim(stack, depth, d, x0, g0):
    """Slope of the branch through (g0, x0) aimed at the target for ``depth`` rows."""
    _, x_t, g_t = _target_point(stack, depth, d)
    return branch_slope(x0, g0, x_t, g_t)


@njit(cache=True, forceinline=True)
def _resumed(stack, t):
    """The branch resumed once row t is passed: the one that reached it (x0, g0, slope)."""
    return stack[t, S_X0], stack[t, S_G0], stack[t, S_SLOPE]


@njit(cache=True, forceinline=True)
def branch_target(stack, depth, d, x0, g0, slope):
    """Target (tau, xi) and parent branch (x0, g0, slope) of the current branch.

    The parent is the branch resumed at the target; with no target it is the branch itself.
    """
    tau, x_t, _ = _target_point(stack, depth, d)
    if depth >= 2:
        px0, pg0, pb = _resumed(stack, depth - 2)
    else:
        px0, pg0, pb = x0, g0, slope
    return tau, x_t, px0, pg0, pb


@njit(cache=True, forceinline=True)
def _into_loop(xi, gA, gM):
    """min(max(xi, g_M), g_A): xi clamped to the major loop (g_A if the loop is empty)."""
    if xi < gM:
        xi = gM
    if xi > gA:
        xi = gA
    return xi


@njit(cache=True, forceinline=True)
def _write(stack, j, tauA, tauM, xi, gA, gM, x0, g0, slope):
    stack[j, S_TAU_A] = tauA
    stack[j, S_TAU_M] = tauM
    stack[j, S_XI] = xi
    stack[j, S_G_A] = gA
    stack[j, S_G_M] = gM
    stack[j, S_X0] = x0
    stack[j, S_G0] = g0
    stack[j, S_SLOPE] = slope


@njit(cache=True, forceinline=True)
def _unreachable(stack, t, d, x, g):
    """True if a branch in direction d through (g, x) cannot end at row t: the same g but
    another xi (possible only after a merge; a loop the branch could not close)."""
    return stack[t, _g_col(d)] == g and abs(stack[t, S_XI] - x) > LOOP_TOL


@njit(cache=True, forceinline=True)
def _push(stack, depth, tauA, tauM, xi, gA, gM, d, x0, g0, slope):
    """Push a reversal point; on a full stack merge the innermost loop. Returns (depth, merged).

    Merge: the point takes the place of the two rows under it (more if its new branch could
    not end at the row it would be aimed at), with a branch through it aimed at row j-2.
    """
    if depth < stack.shape[0]:
        _write(stack, depth, tauA, tauM, xi, gA, gM, x0, g0, slope)
        return depth + 1, 0
    g = gA if d > 0 else gM
    j = depth - 2
    while j >= 2 and _unreachable(stack, j - 2, d, xi, g):
        j -= 2
    _write(stack, j, tauA, tauM, xi, gA, gM, xi, g, aim(stack, j, d, xi, g))
    return j + 1, 1


@njit(cache=True)
def _cooled_from(xi, T, sigma, gM, m):
    """Temperature T_R (at this stress) of the point R on the major heating curve from which
    the first-order cooling curve passes through (g_M, xi): bisection (the curve's value here
    falls from g_A(T) at T_R = T to g_M at T_R past both bands)."""
    lo = T
    hi = max(T, m.A_F0_C + sigma / m.c_A_Pa_per_C, m.M_S0_C + sigma / m.c_M_Pa_per_C) + 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        xR = g_heating(mid, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)[0]
        gR = g_cooling(mid, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)[0]
        if xR + branch_slope(xR, gR, 1.0, 1.0) * (gM - gR) > xi:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True)
def _no_history(stack, xi, T, sigma, gA, gM, m):
    """A state found at xi (inside the loop) with no known history: (d, x0, g0, slope, depth).

    On the major heating curve (xi >= g_A - LOOP_TOL): that curve, heating. On the major
    cooling curve: that curve, cooling. Inside: the wire came from full martensite along
    the major heating curve to a reversal point R (row 0) and is cooling on the first-order
    curve from R, which passes through here.
    """
    if xi >= gA - LOOP_TOL:
        return 1, xi, gA, branch_slope(xi, gA, 0.0, 0.0), 0
    if xi <= gM + LOOP_TOL:
        return -1, xi, gM, branch_slope(xi, gM, 1.0, 1.0), 0
    TR = _cooled_from(xi, T, sigma, gM, m)
    xR = g_heating(TR, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)[0]
    gMR = g_cooling(TR, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)[0]
    _write(stack, 0, TR - sigma / m.c_A_Pa_per_C, TR - sigma / m.c_M_Pa_per_C, xR, xR, gMR,
           xR, xR, branch_slope(xR, xR, 0.0, 0.0))
    return -1, xi, gM, branch_slope(xi, gM, 1.0, 1.0), 1


@njit(cache=True, forceinline=True)
def _own(d, tauA, tauM, gA, gM):
    """(tau, g) of the branch direction d: (tau_A, g_A) heating, (tau_M, g_M) cooling."""
    if d > 0:
        return tauA, gA
    return tauM, gM


@njit(cache=True, forceinline=True)
def memory_update(d, x0, g0, slope, lim_tau, lim_g, clamps, merges, stack, depth, T, sigma,
                  direction, m):
    """One sub-step start of the memory rule (see the module docstring).

    ``d, x0, g0, slope`` is the current branch (d = 0: virgin hold at x0) and ``lim_tau``,
    ``lim_g`` its extreme so far (xi holds while tau is back from it); ``direction`` is the
    engine's +1 / -1 / 0. Order: wipe out the loops whose target was reached; advance the
    extreme; if the branch left the major loop by more than LOOP_TOL, clamp (counted) and
    restart with no history (a major curve erases it); on a reversal push the point (its own
    tau at the branch's extreme) and aim the new branch from here.
    Returns (d, x0, g0, slope, lim_tau, lim_g, clamps, merges, depth).
    """
    gA = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)[0]
    gM = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)[0]
    tauA = T - sigma / m.c_A_Pa_per_C
    tauM = T - sigma / m.c_M_Pa_per_C
    if d == 0:
        if direction == 0:
            return d, x0, g0, slope, lim_tau, lim_g, clamps, merges, depth
        if x0 > gA + LOOP_TOL or x0 < gM - LOOP_TOL:
            clamps += 1
        xi = _into_loop(x0, gA, gM)
        d, x0, g0, slope, depth = _no_history(stack, xi, T, sigma, gA, gM, m)
        lim_tau, lim_g = _own(d, tauA, tauM, gA, gM)
    else:
        tau, g = _own(d, tauA, tauM, gA, gM)
        while depth >= 2 and _reached(d, tau, stack[depth - 2, _tau_col(d)]):
            x0, g0, slope = _resumed(stack, depth - 2)
            depth -= 2
        if _reached(d, tau, lim_tau):
            lim_tau, lim_g = tau, g
        xi = x0 + slope * (lim_g - g0)
        if xi > gA + LOOP_TOL or xi < gM - LOOP_TOL:
            clamps += 1
            xi = _into_loop(xi, gA, gM)
            d, x0, g0, slope, depth = _no_history(stack, xi, T, sigma, gA, gM, m)
            lim_tau, lim_g = _own(d, tauA, tauM, gA, gM)
        xi = _into_loop(xi, gA, gM)
    want = direction if direction != 0 else d  # 0: keep the branch the wire is on now
    if want == -d:
        qA, qM, qgA, qgM = tauA, tauM, gA, gM
        if d > 0:
            qA, qgA = lim_tau, lim_g
        else:
            qM, qgM = lim_tau, lim_g
        depth, merged = _push(stack, depth, qA, qM, xi, qgA, qgM, d, x0, g0, slope)
        merges += merged
        d = want
        lim_tau, lim_g = _own(d, tauA, tauM, gA, gM)
        # a target already reached here (c_A != c_M after a stress change, or a loop of zero
        # width) or that this branch cannot end at (after a merge): its loop is dropped and
        # the new branch keeps its anchor at the current point
        while depth >= 2 and (_reached(d, lim_tau, stack[depth - 2, _tau_col(d)])
                              or _unreachable(stack, depth - 2, d, xi, lim_g)):
            depth -= 2
        x0, g0 = xi, lim_g
        slope = aim(stack, depth, d, x0, g0)
    return d, x0, g0, slope, lim_tau, lim_g, clamps, merges, depth
