"""The toy paper's metric set: how far the robots got from the box's centre line."""

import numpy as np

from teamnav.experiments.metrics import register

HEADLINE = {"toy": (("toy_spread_m", "m"),)}


def toy(data):
    x = np.asarray(data.true_pose[..., 0], dtype=float)
    return {"toy_spread_m": float(np.ptp(x))} if x.size else {}


register("toy", toy, "spread of the robots' x positions [m] (the toy paper)")
