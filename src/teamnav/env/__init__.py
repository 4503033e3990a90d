"""teamnav as an environment: drive some robots of any scenario from outside.

- :class:`ParallelEnv`: a PettingZoo ``ParallelEnv``; the robots of chosen groups are agents,
  the others keep their scenario brains.
- :class:`SingleRobotEnv`: a Gymnasium ``Env`` for one robot among scripted teammates.
- :class:`BatchedEnv`: ``num_envs`` copies of a scenario stepped in one call, struct-of-arrays
  data, following Gymnasium's vector API.
- :mod:`teamnav.env.rewards`: the registry of task rewards (``progress``, ``collision``,
  ``delivery``, ``localization``).

An agent observes what a brain observes (odometry, range scans, detections, inbox, events,
in its own frames: DESIGN's "truth and belief never mix"), as a ``Dict`` of Boxes, and acts
with ``(v, omega)`` (unicycle) or ``(vx, vy)`` (holonomic step) on exactly a brain's timing.
``env.robot(agent)`` gives the observation object itself (message bodies included), the radio
(``send``), the recorder (``log``), the ``finished`` flag and the scenario's own brain for that
robot (``scenario_controller()``), so a built-in rule can be wrapped and run from outside.
Episodes can be written as run folders (``record_dir=`` or ``save_run``) for ``teamnav replay``.

Needs the ``env`` extra: ``pip install 'teamnav[env]'`` (pettingzoo, gymnasium).

Examples
--------
::

    from teamnav.env import ParallelEnv

    env = ParallelEnv("blazing-a-trail", duration_s=60, reward="delivery")
    obs, infos = env.reset(seed=1)
    while env.agents:
        actions = {a: env.action_space(a).sample() for a in env.agents}
        obs, rewards, terminations, truncations, infos = env.step(actions)
"""

from teamnav.env.batched import BatchedEnv
from teamnav.env.config import EnvSpec, load_env_scenario
from teamnav.env.parallel import ParallelEnv
from teamnav.env.single import SingleRobotEnv

__all__ = ["BatchedEnv", "EnvSpec", "ParallelEnv", "SingleRobotEnv", "load_env_scenario"]


def _register_with_gymnasium() -> None:
    """``gymnasium.make("teamnav/SingleRobot-v0", scenario="demo", robot=0, ...)`` (once per process)."""
    import gymnasium

    if "teamnav/SingleRobot-v0" not in gymnasium.registry:
        gymnasium.register(id="teamnav/SingleRobot-v0", entry_point="teamnav.env.single:SingleRobotEnv",
                           disable_env_checker=True)


_register_with_gymnasium()
