"""How many threads the step kernels use: chosen by timing, since the result does not depend on it.

The kernels sum every particle's forces in a fixed order, so one thread and two give the same
bits; only the speed differs. On an idle two-core machine two threads take a 20 000-sphere step
in about half the time. On a shared one they can be far slower: a parallel loop waits at its
end for its slowest thread, and a thread that loses its core to another process for a time
slice stalls the step, and on a busy machine two threads can run several times slower than one
(``docs/dem-speed.md``). :class:`ThreadChooser` therefore
times a few steps with each candidate, keeps the faster, and probes again later.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["ThreadChooser", "MIN_PARALLEL_PARTICLES"]

#: Below this many particles a step is too short for a parallel loop to pay (one thread only).
MIN_PARALLEL_PARTICLES = 4000


class ThreadChooser:
    """Thread count of the step kernels: fixed, or the faster of 1 and all by periodic timing.

    Parameters
    ----------
    n_particles : int
    threads : int | None
        A fixed count (capped at numba's ``NUMBA_NUM_THREADS``), or None to choose by timing
        (one thread below :data:`MIN_PARALLEL_PARTICLES` particles).
    probe_steps : int
        Steps timed with each candidate (the median counts).
    period : int
        Steps between probes at first; doubled each time the same count wins again (to 32x).
    """

    def __init__(self, n_particles, *, threads=None, probe_steps=6, period=400):
        top = numba.config.NUMBA_NUM_THREADS
        if threads is not None:
            if not int(threads) >= 1:
                raise ValueError(f"threads must be >= 1, got {threads}")
            self.candidates = [min(int(threads), top)]
        elif n_particles < MIN_PARALLEL_PARTICLES or top == 1:
            self.candidates = [1]
        else:
            self.candidates = [top, 1]
        self.current = self.candidates[0]
        self.probe_steps = int(probe_steps)
        self._base = self._period = int(period)
        self._times = {c: [] for c in self.candidates}
        self._left = 0 if len(self.candidates) > 1 else None  # steps until the next probe
        self._probe = list(self.candidates) if len(self.candidates) > 1 else []  # still to time
        self._last_best = None
        self.steps_by_threads = {c: 0 for c in self.candidates}
        numba.set_num_threads(self.current)

    def record(self, seconds):
        """Account one step that took ``seconds`` with :attr:`current` threads."""
        self.steps_by_threads[self.current] += 1
        if self._left is None:
            return
        if self._probe:
            times = self._times[self.current]
            times.append(seconds)
            if len(times) >= self.probe_steps:
                self._probe.pop(0)
                if self._probe:
                    self._switch(self._probe[0])
                else:
                    self._decide()
            return
        self._left -= 1
        if self._left <= 0:
            self._times = {c: [] for c in self.candidates}
            self._probe = list(self.candidates)
            self._switch(self._probe[0])

    def _decide(self):
        best = min(self.candidates, key=lambda c: float(np.median(self._times[c])))
        if best == self._last_best:
            self._period = min(2 * self._period, 32 * self._base)
        else:
            self._period = self._base
        self._last_best = best
        self._left = self._period
        self._switch(best)

    def _switch(self, threads):
        if threads != self.current:
            self.current = threads
            numba.set_num_threads(threads)
