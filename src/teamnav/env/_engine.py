"""What an environment needs from :class:`~teamnav.sim.engine.Simulation`, in one place.

``Simulation.decide_first`` and ``Simulation.set_commands`` are the engine's public hooks for
it (used here when present); the fallbacks below write the same internals for an engine
without them.

An outside agent decides *after* it has seen its observation, but the engine asks a brain for
its action in the same call that builds the observation (``Simulation.step`` senses, then
calls every brain, then stores the commands for the next step). To keep an agent's action on
exactly the timing of a built-in brain's (decided on the observation of step k, executed by
the motion of step k + 1, no extra step of latency), the environment

1. takes the first decision of an episode at reset, which ``step()`` otherwise does lazily
   (:func:`decide_first`), so reset can return the observation of step 0 before any motion;
2. overwrites the agents' stored commands after they decided and before the next motion
   (:func:`set_commands`); their proxy brains returned a placeholder ``Action.stop()`` (or,
   for a group of agents only, were not stepped: ``observes_whole_group``, and the
   environment reads ``Simulation.observed``).

Both write engine internals (``_observe_and_decide``, ``_decided``, ``_v_cmd``, ``_w_cmd``,
``_dir_cmd``). Two more helpers keep agents under the scenario's ``faults`` as the engine keeps
brains: :func:`send_messages` puts an agent's outbox on the radio as the engine does (a
muted robot's or a blacked-out message is dropped), and :func:`dead` says whose brain the
engine no longer steps (the environment then ends that agent's episode). The minimal public hook that would replace this module is two methods on
``Simulation``::

    def decide_first(self) -> None:
        '''Take the first decision now (what the first step() does lazily); idempotent.'''
        if not self._decided:
            self._observe_and_decide(None, None)
            self._decided = True

    def set_commands(self, ids, v_mps, omega_radps, direction_rad) -> None:
        '''Replace the stored commands of robots ``ids`` before the next step moves them.'''
        (checks: ids in range, finite v / omega, direction finite or NaN), then
        self._v_cmd[ids] = v_mps; self._w_cmd[ids] = omega_radps; self._dir_cmd[ids] = direction_rad

:func:`check_engine` fails loudly, naming what is missing, if the engine changes shape.
"""

from __future__ import annotations

import functools

import numpy as np

_NEEDED = ("_observe_and_decide", "_decided", "_v_cmd", "_w_cmd", "_dir_cmd")


def check_engine(sim) -> None:
    """Raise a clear error if ``sim`` lacks the internals this module writes."""
    if callable(getattr(sim, "decide_first", None)) and callable(getattr(sim, "set_commands", None)):
        return
    missing = [a for a in _NEEDED if not hasattr(sim, a)]
    if missing:
        raise RuntimeError(
            "teamnav.env drives the engine through Simulation internals that are gone "
            f"({', '.join(missing)}); see teamnav/env/_engine.py for the hook it needs"
        )


def decide_first(sim) -> None:
    """Take the first decision of the episode now (observation of step 0, no motion)."""
    hook = getattr(sim, "decide_first", None)
    if callable(hook):
        hook()
        return
    if not sim._decided:
        sim._observe_and_decide(None, None)
        sim._decided = True


def set_commands(sim, ids, v_mps, omega_radps, direction_rad) -> None:
    """Store commands for robots ``ids`` (finite ``v``/``omega``; ``direction`` NaN = stay,
    None = leave as the brain left it) for the next :meth:`Simulation.step`; the engine clips
    them to each robot's limits."""
    hook = getattr(sim, "set_commands", None)
    if callable(hook):
        hook(ids, v_mps, omega_radps, direction_rad, check=False)  # the environment checked its actions
        return
    sim._v_cmd[ids] = v_mps
    sim._w_cmd[ids] = omega_radps
    if direction_rad is not None:
        sim._dir_cmd[ids] = direction_rad


def command_writer(sim):
    """:func:`set_commands` for ``sim``, resolved once (an environment calls it every step)."""
    hook = getattr(sim, "set_commands", None)
    if callable(hook):
        return functools.partial(hook, check=False)  # the environment checked its actions
    return lambda ids, v_mps, omega_radps, direction_rad: set_commands(sim, ids, v_mps, omega_radps, direction_rad)


def send_messages(sim, outgoing) -> None:
    """Agents' ``(robot id, Message)`` on the radio, heard from where the robots are now, with
    the engine's radio faults (a muted sender, a blackout) applied as to a brain's outbox."""
    if not outgoing or sim.radio is None:
        return
    s = sim.state
    fx = getattr(sim, "faults", None)
    if fx is None:
        sim.radio.send(outgoing, s.x_m, s.y_m)
    else:
        sim.radio.send(outgoing, s.x_m, s.y_m, muted=fx.radio_off if fx.any_radio_off else None, blocked=fx.blackout)


def dead(sim, ids) -> np.ndarray | None:
    """Bool per robot of ``ids``: its brain is off (a ``faults`` death); None without faults."""
    fx = getattr(sim, "faults", None)
    if fx is None:
        return None
    return fx.dead[ids]
