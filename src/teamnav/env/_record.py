"""Run folders and pictures of an episode driven from outside.

:func:`save_run` writes the same run folder as ``teamnav run`` (recorder files, resolved
scenario, metrics, map, robots, trajectories figure), so ``teamnav replay``, ``teamnav export``
and the figures work on it; ``env.json`` adds which robots were agents and their returns.
``scenario.yaml`` is the scenario with the episode's seed and the scenario's own brains:
``teamnav run`` on it runs the built-in brains where the agents were.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["render_rgb", "save_run"]


def _json_ready(values: dict[str, Any]) -> dict[str, Any]:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in values.items()}


def save_run(core, out_dir: str | os.PathLike, *, force: bool = False) -> Path:
    """Write the current episode of ``core`` as a run folder at ``out_dir``.

    Raises
    ------
    OutputDirError
        ``out_dir`` exists and is not empty, and ``force`` is False.
    """
    from teamnav.env._core import _all_finished
    from teamnav.experiments import metrics as metric_registry
    from teamnav.experiments.runner import OutputDirError, run_data
    from teamnav.experiments.spec import scenario_to_yaml
    from teamnav.viz.plots import plot_run
    from teamnav.world.mapio import save_map

    if core.sim is None:
        raise RuntimeError("nothing to save: call reset() and step() first")
    out = Path(out_dir)
    if out.exists() and not force:
        if not out.is_dir():
            raise OutputDirError(f"output folder {out} exists and is a file; choose another folder or pass force=True")
        if any(out.iterdir()):
            raise OutputDirError(f"output folder {out} exists and is not empty; choose another folder or pass force=True")
    out.parent.mkdir(parents=True, exist_ok=True)
    st = core.setup
    sim = core.sim
    scn = core.episode_scenario()
    core.finalize_logs()
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.env-", suffix=".partial", dir=out.parent))
    try:
        sim.recorder.save(staging)
        finished = bool(scn.stop_when_finished and _all_finished(sim))
        data = run_data(staging, scn, st.grid, int(sim.step_index), core.wall_s, finished=finished)
        values = metric_registry.compute(scn.metric_names, data)
        (staging / "scenario.yaml").write_text(scenario_to_yaml(scn), encoding="utf-8")
        (staging / "metrics.json").write_text(json.dumps(_json_ready(values), indent=2) + "\n", encoding="utf-8")
        agent_of = dict(zip(st.agent_ids.tolist(), st.agent_names))
        group, controller, radius = [], [], []
        i = 0
        for g in scn.robots:
            for _ in range(g.count):
                group.append(g.name)
                controller.append(f"env agent {agent_of[i]}" if i in agent_of else g.controller)
                radius.append(g.radius_m)
                i += 1
        (staging / "robots.json").write_text(json.dumps({"group": group, "controller": controller, "radius_m": radius}) + "\n",
                                             encoding="utf-8")
        env = {
            "agents": dict(zip(st.agent_names, st.agent_ids.tolist())),
            "reward": st.reward_spec,
            "episode_return": dict(zip(st.agent_names, [float(x) for x in core.episode_return])),
            "steps": int(sim.step_index),
            "seed": int(core.seed),
            "observe_truth": bool(st.spec.observe_truth),
        }
        (staging / "env.json").write_text(json.dumps(env, indent=2) + "\n", encoding="utf-8")
        save_map(st.grid, staging / "map.yaml")
        plot_run(staging, title=f"{scn.name}: {scn.n_robots} robots, {sim.time_s:g} s, seed {scn.seed} (driven by teamnav.env)")
        from teamnav.experiments.runner import current_umask

        mask = current_umask()
        os.chmod(staging, 0o777 & ~mask)
        for p in staging.iterdir():
            os.chmod(p, 0o666 & ~mask)
        if out.exists():
            shutil.rmtree(out) if out.is_dir() else out.unlink()
        os.replace(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return out


def render_rgb(core, *, dpi: int = 80) -> np.ndarray:
    """An RGB picture (H, W, 3) uint8 of the episode so far: the map, true paths, odometry
    (dashed) and current poses, drawn by :func:`teamnav.viz.plots.plot_trajectories`."""
    from PIL import Image

    from teamnav.viz.plots import plot_trajectories

    sim = core.sim
    if sim is None:
        raise RuntimeError("nothing to render: call reset() first")
    rec = sim.recorder
    true = np.asarray(rec.true_pose, dtype=float)
    odom = np.asarray(rec.odom_pose, dtype=float)
    steps = rec.steps
    if steps.shape[0] == 0 or int(steps[-1]) != sim.step_index:
        true = np.concatenate([true, sim.state.poses()[None]], axis=0)
        odom = np.concatenate([odom, sim.odometry.pose[None]], axis=0)
    scn = core.setup.scenario
    radius = np.concatenate([np.full(g.count, g.radius_m) for g in scn.robots])
    with tempfile.TemporaryDirectory(prefix="teamnav-render-") as d:
        path = plot_trajectories(core.setup.grid, true, Path(d) / "frame.png", odom_pose=odom, radius_m=radius,
                                 title=f"{scn.name}: t = {sim.time_s:.1f} s", dpi=dpi)
        with Image.open(path) as im:
            return np.asarray(im.convert("RGB")).copy()
