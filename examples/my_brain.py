"""A brain of your own, outside the package: ``teamnav run demo --controller my_brain:Cautious``."""
import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from teamnav.control import Action, Message


class Cautious:
    """Drives on, turns towards the open side when something is close ahead, greets every second."""

    class Params(BaseModel):                      # validated before the run: a typo stops it
        model_config = ConfigDict(extra="forbid")
        speed_mps: float = Field(0.4, gt=0.0)
        clearance_m: float = Field(0.8, gt=0.0)

    def __init__(self, params, rng: np.random.Generator, info):   # info: RobotInfo (id, limits, sensors)
        self.p, self.id = params, info.robot_id

    def step(self, obs):                          # obs: the Observation a built-in brain gets
        scan = next(iter(obs.scans.values()))     # ranges in the robot's own body frame
        ahead = np.abs(scan.angles_rad) < 0.5
        near = scan.ranges_m[ahead].min() if ahead.any() else np.inf
        side = np.sign(scan.ranges_m[scan.angles_rad > 0].sum() - scan.ranges_m[scan.angles_rad < 0].sum()) or 1.0
        turn = side * 1.2 if near < self.p.clearance_m else 0.0
        speed = 0.0 if near < 0.5 * self.p.clearance_m else self.p.speed_mps
        hello = [Message(self.id, obs.time_s, {"inbox": len(obs.inbox)}, kind="hello")] if obs.step % 10 == 0 else []
        return Action(v_mps=speed, omega_radps=turn), hello

    def log(self):
        return {}
