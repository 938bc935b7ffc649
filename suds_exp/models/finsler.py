"""GMR+F: GMR whose map is homogeneous of degree one in the shape velocity but not
linear in it (the paper's Future Work, "systems with Finsler contact models").

With asymmetric friction the body moves differently when a joint opens and when it
closes: the motility map is v_b = A+(r) [dr_a/dt]+ + A-(r) [dr_a/dt]-, separate maps for
the positive and negative parts of each shape velocity ([x]+ = max(x, 0), [x]- =
min(x, 0)): continuous, homogeneous of degree one and convex, linear only when
A+ = A-. GMR+F gives the mixture exactly those inputs: every dr_a/dt column is split into
its two parts (after GMR's "homogeneous" division by the speed), so a component's affine
conditional mean is A+_k [u]+ + A-_k [u]- rather than B_k u, and one component can hold
a kink where a joint reverses. Everything else is `GMR`.
"""

from __future__ import annotations

import numpy as np

from suds_exp.errors import ConfigError
from suds_exp.models.gmr import GMR


class GMRFinsler(GMR):
    """A-GBR of v_b on (r_a, [dr_a/dt]+, [dr_a/dt]-) (see the module docstring); the
    parameters and attributes of `GMR`, with 2 m rate inputs in place of m."""

    name = "GMR+F"

    def _validate(self):
        super()._validate()
        if self.augment == "dilation":
            # dilated copies scale the rate columns GMR names; the split ones are others
            raise ConfigError(f"{self.name}: augment='dilation'; expected 'homogeneous' or 'none'")

    def _inputs(self, samples):
        X, f = super()._inputs(samples)
        rate = np.flatnonzero([c in self.dra_columns_ for c in self.columns_in_])
        u = X[:, rate]
        rest = np.delete(X, rate, axis=1)
        return np.hstack([rest, np.maximum(u, 0.0), np.minimum(u, 0.0)]), f
