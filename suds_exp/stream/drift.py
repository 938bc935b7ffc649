"""Page-Hinkley drift alarm on a learner's per-cycle error (Page 1954; Hinkley 1971).

The test watches x_t = log(RMSE of vx in cycle t): the log makes it scale-free (one
threshold for any robot speed) and turns "the error doubled" into a shift of log 2 = 0.69.
With xbar_t the running mean of x_1..x_t,

    m_t = sum_{i <= t} (x_i - xbar_i - delta),   M_t = min_{i <= t} m_i,
    alarm when m_t - M_t > threshold,

i.e. a sustained rise of the error by more than `delta` above its history. After an alarm
the test restarts on the new level. The first `burn_in` cycles only feed the mean.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass
class PageHinkley:
    """One-sided (increase) Page-Hinkley test; `update(x)` -> (statistic, alarm).

    delta : tolerated rise of log-error per cycle (0.1: about +10 %).
    threshold : alarm level of the cumulative rise, in log units (1.5: e.g. a doubled
        error held for about 3 cycles).
    burn_in : cycles that only feed the running mean after a (re)start.
    """

    delta: float = 0.1
    threshold: float = 1.5
    burn_in: int = 5
    _n: int = field(default=0, init=False)
    _mean: float = field(default=0.0, init=False)
    _m: float = field(default=0.0, init=False)
    _min: float = field(default=0.0, init=False)

    def reset(self) -> None:
        self._n, self._mean, self._m, self._min = 0, 0.0, 0.0, 0.0

    def update(self, error: float) -> tuple[float, bool]:
        """Feed one cycle's error (> 0); returns (m_t - M_t, whether it alarms now)."""
        x = math.log(max(error, 1e-12))
        self._n += 1
        self._mean += (x - self._mean) / self._n
        self._m += x - self._mean - self.delta
        self._min = min(self._min, self._m)
        stat = self._m - self._min
        if self._n > self.burn_in and stat > self.threshold:
            self.reset()
            return stat, True
        return stat, False
