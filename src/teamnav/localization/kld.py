"""KLD-sampling: the sample set size adapts to the belief's spread.

Fox et al. §3.1: "MCL determines the sample set size on-the-fly: it typically uses many
samples during global localization or if the position of the robot is lost, and only a small
number of samples is used during position tracking". The rule used here is the one Fox later
published for exactly that: draw samples until their number exceeds the KL bound

    n(k) = (k - 1) / (2 eps) * (1 - 2 / (9 (k - 1)) + sqrt(2 / (9 (k - 1))) z_{1-delta})^3

where ``k`` is the number of histogram bins (x, y, theta) holding at least one drawn sample,
so that with probability ``1 - delta`` the KL divergence between the sample-based maximum
likelihood estimate and the true posterior stays below ``eps``.

Ref: D. Fox, "Adapting the sample size in particle filters through KLD-sampling",
Int. J. Robotics Research 22(12), 2003, doi:10.1177/0278364903022012001, eq. (12) and Table 1.
"""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

__all__ = ["KLDParams", "kld_bound", "kld_count_kernel"]


class KLDParams(BaseModel):
    """Parameters of KLD-sampling (Fox 2003, Table 1).

    ``epsilon``: KL error bound; ``delta``: failure probability (``z_{1-delta}`` is the standard
    normal quantile); ``bin_xy_m`` / ``bin_theta_deg``: histogram bin size; the count stays in
    ``[min_particles, max_particles]``.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    epsilon: float = Field(0.05, gt=0.0, le=1.0)
    delta: float = Field(0.01, gt=0.0, lt=0.5)
    bin_xy_m: float = Field(0.5, gt=0.0, le=100.0)
    bin_theta_deg: float = Field(10.0, gt=0.0, le=360.0)
    min_particles: int = Field(100, ge=1, le=10_000_000)
    max_particles: int = Field(50_000, ge=1, le=10_000_000)

    def model_post_init(self, __context) -> None:
        if self.min_particles > self.max_particles:
            raise ValueError(f"kld.min_particles must be <= kld.max_particles ({self.max_particles}), "
                             f"got {self.min_particles}")

    @property
    def z(self) -> float:
        """Upper ``1 - delta`` quantile of the standard normal."""
        return NormalDist().inv_cdf(1.0 - self.delta)


@njit(cache=True)
def kld_bound(k, epsilon, z):
    """Fox 2003 eq. (12): samples needed for ``k`` occupied bins (``k <= 1``: 1)."""
    if k <= 1:
        return 1.0
    a = 2.0 / (9.0 * (k - 1))
    b = 1.0 - a + math.sqrt(a) * z
    return (k - 1) / (2.0 * epsilon) * b * b * b


@njit(cache=True)
def kld_count_kernel(poses, order, xmin, ymin, bin_xy, bin_th, occupied, nx, ny, nth, epsilon, z, n_min, n_max):
    """Number of samples KLD-sampling takes from ``poses[order]`` (drawn in that order).

    ``occupied`` is a zeroed (nx*ny*nth,) uint8 scratch histogram; it is zeroed again on return.
    Samples outside the histogram fall into its border bins.
    """
    k = 0
    n = 0
    limit = min(n_max, order.shape[0])
    touched = np.empty(limit, dtype=np.int64)
    while n < limit:
        p = order[n]
        ix = min(max(int((poses[p, 0] - xmin) / bin_xy), 0), nx - 1)
        iy = min(max(int((poses[p, 1] - ymin) / bin_xy), 0), ny - 1)
        it = min(max(int((poses[p, 2] + math.pi) / bin_th), 0), nth - 1)
        key = (iy * nx + ix) * nth + it
        touched[n] = key
        n += 1
        if occupied[key] == 0:
            occupied[key] = 1
            k += 1
        if n >= n_min and n >= kld_bound(k, epsilon, z):
            break
    for j in range(n):
        occupied[touched[j]] = 0
    return n
