"""The toy paper's brain: drive in a circle of the given radius."""

from pydantic import BaseModel, ConfigDict, Field

from teamnav.control import Action


class Circler:
    class Params(BaseModel):
        model_config = ConfigDict(extra="forbid")
        speed_mps: float = Field(0.3, gt=0.0)
        radius_m: float = Field(0.5, gt=0.0)

    def __init__(self, params, rng, info):
        self.p = params

    def step(self, obs):
        return Action(v_mps=self.p.speed_mps, omega_radps=self.p.speed_mps / self.p.radius_m), []

    def log(self):
        return {}
