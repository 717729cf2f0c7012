"""The sinkage of vertical equilibrium, F_z(z) = W, solved for many conditions at once.

F_z rises with the sinkage z, from F_z(0) = 0 to F_z(z_max) at the deepest sinkage allowed, so each condition's
root lies in (0, z_max) when F_z(z_max) >= W (the condition is *supported*) and the solve brackets it: the Illinois
variant of false position (Dowell & Jarratt 1971), which keeps the bracket and converges superlinearly, to
|F_z - W| <= tolerance W.

A least-squares fit asks for the sinkage at parameters a finite-difference step apart (``diff_step`` 1e-4), so the
root moves by about that much from one call to the next. :class:`SinkageWarmStart` carries the last call's roots
and slopes dF_z/dz to the next: one Newton step from the last root and one secant step after it reach the
tolerance where the bracketed solve from (0, z_max) takes about ten evaluations of F_z. Every evaluated point
narrows the bracket, so a poor start (other conditions, a large step) costs evaluations, never the answer: warm and
cold solves agree to the tolerance. Only the conditions not yet converged are evaluated.
"""

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: Newton/secant steps tried from a warm start before the bracketed iteration takes over.
WARM_STEPS = 3


@dataclass
class SinkageWarmStart:
    """The roots of the last solve, to start the next one from (pass the same object to successive solves over
    the same conditions; it is overwritten by each). Empty until the first solve; a solve over another number of
    conditions ignores what it holds."""

    sinkage: np.ndarray | None = None
    #: dF_z/dz at each root [N/m], from the last two points evaluated there (NaN where unknown).
    stiffness: np.ndarray | None = None

    def usable_for(self, count: int) -> bool:
        return self.sinkage is not None and self.sinkage.shape == (count,)


@dataclass(frozen=True)
class SinkageSolution:
    """Roots of F_z(z) = W per condition: ``sinkage`` [m] (z_max where unsupported), ``supported`` (False where
    even z_max cannot carry W) and the number of F_z evaluations each condition took."""

    sinkage: np.ndarray
    supported: np.ndarray
    evaluations: np.ndarray


def solve_sinkage(excess: Callable[[np.ndarray, np.ndarray], np.ndarray], load: np.ndarray, z_max: float, *,
                  tolerance: float = 1e-10, max_iterations: int = 200,
                  warm: SinkageWarmStart | None = None) -> SinkageSolution:
    """Solve excess(z, rows) = F_z(z) - W = 0 for z in (0, z_max) per condition.

    ``excess(z, rows)`` returns F_z(z) - W [N] for the conditions indexed by ``rows`` (an integer array) at their
    sinkages ``z`` [m]; F_z(0) = 0 is assumed (no sinkage, no force), so excess(0) = -W. ``load`` [N] is W per
    condition. With ``warm`` the solve starts from its roots and leaves its own there.
    Raises RuntimeError when a condition has not converged after ``max_iterations`` bracketed steps.
    """
    load = np.asarray(load, float)
    count = load.size
    limit = tolerance * load
    lo, f_lo = np.zeros(count), -load.copy()
    hi, f_hi = np.full(count, float(z_max)), np.full(count, np.nan)  # f_hi NaN: F_z(z_max) not evaluated yet
    z, f = np.full(count, float(z_max)), np.full(count, np.nan)
    z_prev, f_prev = np.full(count, np.nan), np.full(count, np.nan)
    evaluations = np.zeros(count, int)
    done = np.zeros(count, bool)
    side = np.zeros(count, int)  # which end the last bracketed step kept (-1 lo, +1 hi), for the Illinois rule

    def evaluate(rows, at):
        value = excess(at, rows)
        evaluations[rows] += 1
        z_prev[rows], f_prev[rows] = z[rows], f[rows]
        z[rows], f[rows] = at, value
        below = value < 0.0  # the root lies above: the point becomes the bracket's low end
        lo[rows[below]], f_lo[rows[below]] = at[below], value[below]
        hi[rows[~below]], f_hi[rows[~below]] = at[~below], value[~below]
        done[rows] = ~(np.abs(value) > limit[rows])  # NaN (a soil the model cannot evaluate) ends the row too
        return below

    if warm is not None and warm.usable_for(count):
        start = np.clip(warm.sinkage, 1e-9 * z_max, (1.0 - 1e-12) * z_max)
        rows = np.arange(count)
        evaluate(rows, start[rows])
        slope = np.asarray(warm.stiffness, float) if warm.stiffness is not None else np.full(count, np.nan)
        for _ in range(WARM_STEPS):
            rows = np.flatnonzero(~done)
            if rows.size == 0:
                break
            with np.errstate(divide="ignore", invalid="ignore"):
                secant = (f[rows] - f_prev[rows]) / (z[rows] - z_prev[rows])
                step_slope = np.where(np.isfinite(secant) & (secant > 0.0), secant, slope[rows])
                cand = z[rows] - f[rows] / step_slope
            inside = np.isfinite(cand) & (cand > lo[rows]) & (cand < hi[rows])
            rows, cand = rows[inside], cand[inside]
            if rows.size == 0:
                break
            evaluate(rows, cand)

    # F_z(z_max) where no evaluated point has shown the root below it: whether the condition is supported at all
    unknown = np.flatnonzero(~done & np.isnan(f_hi))
    if unknown.size:
        evaluate(unknown, hi[unknown])
    # a point at or above the root was found, else F_z(z_max) < W (or F_z is NaN: that row keeps z_max)
    supported = (done & np.isfinite(f)) | np.isfinite(f_hi)
    active = ~done & supported
    for _ in range(max_iterations):
        rows = np.flatnonzero(active)
        if rows.size == 0:
            break
        l, fl, h, fh = lo[rows], f_lo[rows], hi[rows], f_hi[rows]
        cand = h - fh * (h - l) / np.where(fh != fl, fh - fl, 1.0)
        cand = np.where((cand > l) & (cand < h), cand, 0.5 * (l + h))  # guard against round-off
        keep_side = side[rows]
        below = evaluate(rows, cand)
        # Illinois: when the same end survives twice, halve the function value kept at the other end
        halve_hi = rows[below & (keep_side == -1)]
        halve_lo = rows[~below & (keep_side == 1)]
        f_hi[halve_hi] *= 0.5
        f_lo[halve_lo] *= 0.5
        side[rows] = np.where(below, -1, 1)
        active[rows] = ~done[rows]
    else:
        raise RuntimeError(f"sinkage did not converge in {max_iterations} iterations")
    sinkage = np.where(supported, z, float(z_max))
    if warm is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            stiffness = (f - f_prev) / (z - z_prev)
        known = np.isfinite(stiffness) & (stiffness > 0.0)
        if warm.usable_for(count) and warm.stiffness is not None:
            stiffness = np.where(known, stiffness, warm.stiffness)  # a root met at once keeps the slope it had
        else:
            stiffness = np.where(known, stiffness, np.nan)
        warm.sinkage, warm.stiffness = sinkage.copy(), stiffness
    return SinkageSolution(sinkage, supported, evaluations)
