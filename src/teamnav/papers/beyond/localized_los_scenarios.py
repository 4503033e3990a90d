"""Scenarios and sweeps of the beyond section's combination 2, "localized LOS help" (generated files).

The LOS help experiment of :mod:`teamnav.papers.los_help.tasks` (Sgorbissa & Arkin §6: R1
reaches room-centre targets helped by R2..R4 patrolling the corridors, VisBug-21 on both maps,
line-of-sight radio and detector, eqs. 1-2 noise) with every robot's LOS brain wrapped by
``localized-v1`` (MCL on the robot's omnidirectional laser, the map given), and the brains'
``frame_source`` as the swept rule (:mod:`teamnav.papers.beyond.brains.localized_los` documents the
rules and why the frames below are what they are).

What changes against ``los-help-{simple,complex}``, and why:

- ``odometry: {frame: world}`` (exact, as §6.1) and ``targets_xy`` / ``patrol_xy`` in world
  coordinates (:func:`~teamnav.papers.los_help.tasks.frame_to_world` of the paper scenario's
  own-frame lists): the filter's pose is a map pose, and the wrapper starts it at the first
  odometry pose (tracking from the known start); ``give_map: true``.
- the task: R1's first :data:`N_TARGETS` targets of task 1 (the paper's tasks have 200; 10 keep
  the 120-run sweep cheap: first 20, cut to 10 when the shared machine gave these runs ~2 % of a
  core, before any err_max 0.4 run; docs/report/beyond.md states the cost).
- MCL: :data:`MCL_PARAMS` (``localized-v1``'s defaults but for the particle count: a robot that
  tracks from a known start with exact odometry needs few samples; ours).

Sweeps ``beyond-localized-los-simple`` and ``-complex`` (one per map: a sweep has one scenario):
cases ``<source>-e<err_max>`` for source in ``bearings``, ``mcl``, ``fused`` and err_max 0 and
0.4 (eqs. 1-2 on every robot's detector; the ``fused`` rule's own model ``frame_err_max`` set to
the same value), seeds 0-9. Run ``python -m teamnav.papers.beyond.localized_los_scenarios`` after
changing anything here and commit the files it writes.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from teamnav.papers.los_help import tasks as L

__all__ = ["CASES", "ERR_MAX", "MAPS", "MCL_PARAMS", "N_TARGETS", "SOURCES", "case_label", "scenario_data",
           "sweep_data", "write_files"]

MAPS: tuple[str, ...] = ("simple", "complex")
SOURCES: tuple[str, ...] = ("bearings", "mcl", "fused")
#: eqs. 1-2's err_max: none (the bearings' own eq. 2 noise remains) and Fig. 16/17's largest
ERR_MAX: tuple[float, ...] = (0.0, 0.4)
N_TARGETS: int = 10
N_SEEDS: int = 10
MCL_PARAMS: dict[str, Any] = {"particles": 200, "sensor": "laser"}


def scenario_name(map_key: str) -> str:
    return f"beyond-localized-los-{map_key}"


def sweep_name(map_key: str) -> str:
    return scenario_name(map_key)


def case_label(source: str, err_max: float) -> str:
    """``bearings-e0``, ``fused-e0.4``, ..."""
    return f"{source}-e{err_max:g}"


def _start_pose(group: dict[str, Any]) -> tuple[float, float, float]:
    st = group["start"]
    if st.get("poses"):
        return tuple(float(v) for v in st["poses"][0])  # type: ignore[return-value]
    x0, x1, y0, y1 = st["region"]
    return (0.5 * (x0 + x1), 0.5 * (y0 + y1), float(st["theta_deg"]))


def scenario_data(map_key: str, *, n_targets: int = N_TARGETS, frame_source: str = "bearings",
                  err_max: float = 0.0) -> dict[str, Any]:
    """The scenario (YAML data): :func:`teamnav.papers.los_help.tasks.scenario_data` of task 1
    with every brain under ``localized-v1``, world frames and the map given."""
    base = L.scenario_data(map_key, n_targets=n_targets, err_max=err_max)
    groups = []
    for g in base["robots"]:
        g = copy.deepcopy(g)
        pose = _start_pose(g)
        inner = dict(g.pop("params"))
        for key in ("targets_xy", "patrol_xy"):
            if key in inner:
                inner[key] = L._rounded(L.frame_to_world(pose, inner[key]))
        inner["frame_source"] = frame_source
        inner["frame_err_max"] = float(err_max)
        brain = g.pop("controller")
        g["odometry"] = {"frame": "world"}
        g["controller"] = "localized-v1"
        g["params"] = {"brain": brain, **MCL_PARAMS, "brain_params": inner}
        groups.append(g)
    det = groups[0]["detector"]
    for g in groups[1:]:
        g["detector"] = det  # one dict: written as an anchor and aliases (one override sets all)
    fig = "Fig. 11" if map_key == "simple" else "Fig. 13"
    return {
        "name": scenario_name(map_key),
        "description": (f"Beyond the papers, combination 2 (localized LOS help): Sgorbissa & Arkin §6 ({fig}, {L.MAPS[map_key]}), "
                        f"R1's first {n_targets} targets of task 1 helped by R2..R4, every LOS brain on an MCL pose "
                        f"(localized-v1, Fox et al. §3.1, map given, world frames); frame_source bearings (§3.1), "
                        f"mcl or fused (sweep {sweep_name(map_key)})."),
        "map": base["map"],
        "give_map": True,
        **{k: base[k] for k in ("duration_s", "dt_s", "seed", "record_every", "stop_when_finished")},
        "metrics": [*base["metrics"], "localization"],
        "robots": groups,
        "radio": base["radio"],
    }


def _case(n_groups: int, source: str, err_max: float) -> dict[str, Any]:
    out: dict[str, Any] = {"case": case_label(source, err_max), "robots.0.detector.err_max": float(err_max)}
    for k in range(n_groups):
        out[f"robots.{k}.params.brain_params.frame_source"] = source
        out[f"robots.{k}.params.brain_params.frame_err_max"] = float(err_max)
    return out


#: every case of a sweep, in the report's order (source within err_max)
CASES: tuple[tuple[str, float], ...] = tuple((s, e) for e in ERR_MAX for s in SOURCES)


def sweep_data(map_key: str) -> dict[str, Any]:
    """The named sweep of ``map_key``: the cases of :data:`CASES`, seeds 0-9."""
    n = len(L.LAYOUTS[map_key].helpers) + 1
    return {
        "name": sweep_name(map_key),
        "description": (f"Beyond the papers, combination 2 on {L.MAPS[map_key]}: frames from bearings (§3.1), MCL poses or "
                        f"both fused, err_max 0 / 0.4 (eqs. 1-2), {N_TARGETS} targets of task 1, R1..R4, "
                        f"{N_SEEDS} seeds."),
        "scenario": scenario_name(map_key),
        "cases": [_case(n, s, e) for s, e in CASES],
        "seeds": N_SEEDS,
    }


_HEADER = ("# GENERATED by `python -m teamnav.papers.beyond.localized_los_scenarios` "
           "(teamnav/papers/beyond/localized_los_scenarios.py):\n# edit that module, not this file. {what}\n")


def write_files(scenario_dir: Path | None = None, sweep_dir: Path | None = None) -> list[Path]:
    """(Re)write ``scenarios/beyond-localized-los-{simple,complex}.yaml`` and the sweeps."""
    here = Path(__file__).resolve().parent
    scenario_dir = scenario_dir or here / "scenarios"
    sweep_dir = sweep_dir or here / "sweeps"
    out = []
    for m in MAPS:
        p = scenario_dir / f"{scenario_name(m)}.yaml"
        p.write_text(L.to_yaml(scenario_data(m), _HEADER.format(what=f"`teamnav run {scenario_name(m)}`.")))
        out.append(p)
        p = sweep_dir / f"{sweep_name(m)}.yaml"
        p.write_text(L.to_yaml(sweep_data(m), _HEADER.format(what=f"`teamnav sweep {sweep_name(m)} --out DIR`.")))
        out.append(p)
    return out


if __name__ == "__main__":  # pragma: no cover
    for path in write_files():
        print(path)
