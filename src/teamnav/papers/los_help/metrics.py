"""Metrics of the line-of-sight help experiments (Sgorbissa & Arkin §6).

§6 measures "the *average number of motion steps* required by R1 to complete exploration
tasks"; with a fixed step length, steps are proportional to the path length. R1 is the robot
whose brain logs ``targets_reached`` and ``finished`` (``los-explorer-v1``; a helper logs no
``finished``); its ``moves`` counter is the
number of motion steps it made.

Keys
----
``los_finished``
    1 when R1 reached every target, each within its step budget (``max_steps_per_target``;
    the run stopped early, scenario ``stop_when_finished``), else 0 (§6: the potential field
    alone "fails").
``los_gave_up``
    1 when R1 abandoned the task because a target's step budget ran out.
``los_steps``
    R1's motion steps to finish the task; for a run that did not finish, the steps it made
    until it gave up (or the run's end): not comparable, leave failures out of means.
    Logs are kept every ``record_every`` steps, so for a finished run the steps after the
    last kept sample are added as if R1 moved at each (an upper bound, off by less than
    ``record_every``, and never more than the steps the run took).
``los_frac_<mode>``
    Where R1's steps went, as fractions of its steps: ``goal_seen`` (own goal in sight,
    §2 point 4), ``follow_teammate`` (heading to a teammate offering the shortest D, §3),
    ``ghost`` (to a ghost or own past viewpoint, §4), ``trouble_follow`` (to a teammate not
    in trouble, §5), ``promised`` (to its goal on a teammate's direct promise), ``slide``
    (along a side direction to a seen point); the rest is the navigator towards the goal.
``los_temp_switches``
    Times R1's temporary goal (teammate, ghost, trouble helper) changed (oscillation).
``los_steps_per_target``
    ``los_steps`` over the targets reached (over 1 when none was).
``los_targets_reached``
    Targets R1 reached.
``los_max_target_steps``
    The most steps (simulation steps, what the step budget ``max_steps_per_target`` counts: the
    budget runs from the step the target became current) any one *reached* target took; 0 when
    none was reached. Read from the kept samples of ``targets_reached`` (every ``record_every``
    steps): a target counts as reached at the first kept sample that shows it, so each duration
    is off by less than ``record_every`` steps; a finished run's targets reached after its last
    kept sample count as reached at the run's last step (an upper bound, as for ``los_steps``).
    Ours (§6 gives no budget): with it a smaller budget is judged after the fact, since the budget
    changes nothing before R1 gives up: a run would have given up under a budget ``B`` exactly
    when one of its targets took more than ``B`` steps (:mod:`.report._los_budget`).
``los_msgs_r1``, ``los_bytes_r1``
    Messages and bytes R1 sent (its own counters, §4.4).
``los_msgs_per_robot``, ``los_bytes_per_robot``
    The same, averaged over every robot that logs ``msgs_sent`` (R1 and the helpers).
``los_trouble_frac``
    Fraction of R1's kept samples in which it was "in trouble" (``tr``, §5).
``los_leg_<part>``
    Where R1's path goes, in motion steps per target reached, from its true positions (ours:
    §6 reports only the total): ``leave`` (from the last target until R1 first stands in a
    corridor: leaving the room it reached it in), ``corridor`` (in the corridors),
    ``other_rooms`` (off the corridors between its first and last corridor sample of the leg:
    rooms entered by mistake), ``enter`` (from its last corridor sample to the target). A leg
    that never reaches a corridor counts whole as ``leave``. Kept samples (``record_every``)
    resolve it, so each part is off by up to a sample per change. Only for maps whose
    ``regions`` name corridors (``corridor*``: the built-in office maps); otherwise absent.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from teamnav.experiments.metrics import RunData, register

#: what ``teamnav run`` prints of these metrics (see :mod:`teamnav.experiments.metric_sets`)
HEADLINE: dict[str, tuple[tuple[str, str], ...]] = {
    "los_help": (
        ("los_finished", "0/1"),
        ("los_gave_up", "0/1"),
        ("los_steps", "steps"),
        ("los_targets_reached", "targets"),
        ("los_steps_per_target", "steps/target"),
        ("los_msgs_r1", "messages"),
        ("los_bytes_r1", "bytes"),
        ("los_trouble_frac", "fraction"),
    ),
    "los_legs": (
        ("los_leg_leave", "steps/target"),
        ("los_leg_corridor", "steps/target"),
        ("los_leg_other_rooms", "steps/target"),
        ("los_leg_enter", "steps/target"),
    ),
}


def _last_by_robot(data: RunData) -> dict[int, dict[str, Any]]:
    """Each robot's last logged values (with the step they were kept at under ``"_step"``)."""
    last: dict[int, dict[str, Any]] = {}
    for entry in data.logs:
        values = entry.get("values") or {}
        robot = int(entry.get("robot", -1))
        prev = last.get(robot)
        if prev is None or int(entry.get("step", 0)) >= prev["_step"]:
            last[robot] = {**values, "_step": int(entry.get("step", 0))}
    return last


def _explorer(last: dict[int, dict[str, Any]]) -> int | None:
    ids = sorted(r for r, v in last.items() if "targets_reached" in v and "finished" in v)
    return ids[0] if ids else None


def max_target_steps(data: RunData, robot: int, finished: bool) -> int:
    """``los_max_target_steps`` of ``robot`` (see the module docstring): the longest gap between the
    steps at which its kept samples first show each next count of ``targets_reached`` (the first
    target's budget starts at step 0); a ``finished`` run's targets missing from the last kept
    sample are reached at ``data.n_steps``."""
    entries = sorted((int(e.get("step", 0)), int((e.get("values") or {}).get("targets_reached", 0)),
                      bool((e.get("values") or {}).get("finished", False)))
                     for e in data.logs if int(e.get("robot", -1)) == robot)
    longest, since, count = 0, 0, 0
    for step, reached, _fin in entries:
        if reached > count:  # targets first seen reached at this sample (after the first, ~0 steps each)
            longest = max(longest, step - since)
            since, count = step, reached
    if finished and entries and not entries[-1][2]:
        # the last target was reached after the last kept sample, by the run's last step
        longest = max(longest, int(data.n_steps) - since)
    return int(longest)


def los_help(data: RunData) -> dict[str, float | int]:
    """R1's motion steps, targets and messages (see the module docstring); {} without an explorer log."""
    last = _last_by_robot(data)
    r1 = _explorer(last)
    if r1 is None:
        return {}
    v = last[r1]
    finished = bool(data.finished)
    reached = int(v.get("targets_reached", 0))
    moves = int(v.get("moves", 0))
    gave_up = bool(v.get("gave_up", False))
    finished = finished and not gave_up
    if finished:
        steps = min(moves + max(0, int(data.n_steps) - v["_step"]), int(data.n_steps))
    else:
        steps = moves
    total = max(int(v["_step"]) + 1, 1)
    frac = {f"los_frac_{k}": float(v.get(src, 0)) / total for k, src in (
        ("goal_seen", "goal_seen_steps"), ("follow_teammate", "steps_follow_teammate"), ("ghost", "steps_ghost"),
        ("trouble_follow", "steps_trouble_follow"), ("promised", "promised_steps"), ("slide", "slide_steps"))}
    trouble = [bool((e.get("values") or {}).get("tr", False)) for e in data.logs if int(e.get("robot", -1)) == r1]
    msgs = [int(x["msgs_sent"]) for x in last.values() if "msgs_sent" in x]
    nbytes = [int(x["bytes_sent"]) for x in last.values() if "bytes_sent" in x]
    return {
        "los_finished": int(finished),
        "los_steps": int(steps),
        "los_steps_per_target": float(steps) / max(reached, 1),
        "los_targets_reached": reached,
        "los_max_target_steps": max_target_steps(data, r1, finished),
        "los_msgs_r1": int(v.get("msgs_sent", 0)),
        "los_bytes_r1": int(v.get("bytes_sent", 0)),
        "los_msgs_per_robot": float(np.mean(msgs)) if msgs else 0.0,
        "los_bytes_per_robot": float(np.mean(nbytes)) if nbytes else 0.0,
        "los_trouble_frac": float(np.mean(trouble)) if trouble else 0.0,
        "los_gave_up": int(gave_up),
        "los_temp_switches": int(v.get("temp_switches", 0)),
        **frac,
    }


def _corridors(data: RunData) -> list[tuple[float, float, float, float]]:
    """The corridor rectangles of a built-in map (its ``regions`` named ``corridor*``), else []."""
    name = str(getattr(data.grid, "name", ""))
    if not name.startswith("builtin:"):
        return []
    from teamnav.world import BUILTIN_MAPS, builtin_map

    key = name.split(":", 1)[1]
    if key not in BUILTIN_MAPS:
        return []
    return [r for k, r in builtin_map(key).regions.items() if k.startswith("corridor")]


def los_legs(data: RunData) -> dict[str, float]:
    """R1's steps per target by part of its legs (``los_leg_<part>``, see the module docstring)."""
    rects = _corridors(data)
    last = _last_by_robot(data)
    r1 = _explorer(last)
    if not rects or r1 is None:
        return {}
    entries = sorted(((int(e.get("step", 0)), float(e.get("t_s", 0.0)), e.get("values") or {})
                      for e in data.logs if int(e.get("robot", -1)) == r1), key=lambda e: e[0])
    if len(entries) < 2:
        return {}
    t = np.array([e[1] for e in entries])
    k = np.clip(np.searchsorted(data.t_s, t - 1e-9), 0, data.true_pose.shape[0] - 1)
    xy = data.true_pose[k, r1, :2]
    inside = np.zeros(len(entries), dtype=bool)
    for x0, y0, x1, y1 in rects:
        inside |= (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
    target = np.array([int(e[2].get("target_index", 0)) for e in entries])
    moves = np.array([int(e[2].get("moves", 0)) for e in entries])
    # the steps made between two samples belong to the leg of the earlier sample's target and are
    # placed where R1 stands at the later one
    dm = np.diff(moves, prepend=moves[0])
    leg_of = np.concatenate([[-1], target[:-1]])
    parts = {"leave": 0.0, "corridor": 0.0, "other_rooms": 0.0, "enter": 0.0}
    reached = 0
    for leg in range(int(target.max())):  # legs whose target was reached
        sel = np.flatnonzero(leg_of == leg)
        if sel.size == 0:
            continue
        steps, cor = dm[sel], inside[sel]
        reached += 1
        if not cor.any():
            parts["leave"] += float(steps.sum())
            continue
        first, lastc = int(np.argmax(cor)), int(len(cor) - 1 - np.argmax(cor[::-1]))
        parts["leave"] += float(steps[:first].sum())
        parts["enter"] += float(steps[lastc + 1:].sum())
        mid_steps, mid_cor = steps[first:lastc + 1], cor[first:lastc + 1]
        parts["corridor"] += float(mid_steps[mid_cor].sum())
        parts["other_rooms"] += float(mid_steps[~mid_cor].sum())
    if not reached:
        return {}
    return {f"los_leg_{p}": v / reached for p, v in parts.items()}


register("los_help", los_help,
         "Sgorbissa & Arkin §6: R1's motion steps to finish its targets, whether it gave up, targets reached, "
         "messages/bytes, where its steps went")
register("los_legs", los_legs,
         "Sgorbissa & Arkin §6 (ours): R1's steps per target leaving the room it was in, in the corridors, in "
         "rooms entered by mistake and entering the target's room")
