"""phase-only baseline: body velocity as a Fourier series in phase.

This is the phase-dependent constant term C(phase) of TLS alone: it knows where in the
cycle the robot is but nothing about how the shape deviates from the mean gait.
"""

from __future__ import annotations

import pandas as pd

from suds_exp.models import fourier
from suds_exp.models.base import (
    Learner,
    as_array,
    require_columns,
)
from suds_exp.models.params import Integer, Param
from suds_exp.robot import VB_COLUMNS


class PhaseOnly(Learner):
    """v_b(phase) = sum_m a_m cos(m phase) + b_m sin(m phase), m = 0..order.

    Parameters
    ----------
    order : int, default `fourier.PHASE_ORDER` (10)
        Highest harmonic of the Fourier series (2 * order + 1 coefficients per output);
        the same default as TLS's ``gait_order``, whose constant term this is.

    Attributes
    ----------
    coef_ : array of shape (2 * order + 1, 3)
        Fourier coefficients of vx (mm/s), vy (mm/s), wz (rad/s).
    """

    name = "phase-only"
    _hyper_parameters = {"order": Param(fourier.PHASE_ORDER, Integer(0))}

    def fit(self, samples: pd.DataFrame, y=None) -> PhaseOnly:
        self._validate()
        order = int(self.order)
        require_columns(samples, ("phase", *VB_COLUMNS), self.name)
        phase = as_array(samples, ["phase"], self.name)[:, 0]
        v = as_array(samples, VB_COLUMNS, self.name)
        self.coef_ = fourier.fit(phase, v, order)
        self.n_features_in_ = 1
        return self

    def predict(self, samples: pd.DataFrame) -> pd.DataFrame:
        """Predicted vx, vy (mm/s), wz (rad/s), same index as `samples`."""
        self._check_fitted()
        require_columns(samples, ("phase",), self.name)
        phase = as_array(samples, ["phase"], self.name)[:, 0]
        return self._output_frame(fourier.basis(phase, self.order) @ self.coef_, samples)
