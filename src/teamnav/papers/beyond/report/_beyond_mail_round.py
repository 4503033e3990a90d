"""The ``beyond`` section's N-places block: a mail round of N = 2..5 places.

Vaughan, Støy, Sukhatme & Matarić, "Try to see it my way" (2002): §2.1 "We have since generalized
the method to handle N places by recording N trails (though we will only present results here for
an N=2 experiment)"; §4 "the next stage is to examine the system's ability to work with multiple
locations in a mail-delivery application". The brain is ``trail-share-v1`` as the paper runs it
(§2.2-2.3), its round (:class:`~teamnav.papers.trails.brains.forager.PlaceRound`) listing N places; the
scenario and sweep are ``beyond-mail-round`` (the MIT basement hallways, one corridor loop of
about 139 m; the places and their order are in the scenario file, chosen before any run).

Measured per case (the sweep's cases ``nN``: the team of 4 with the paper's one Crumb for the
last Place visited, §2.2 step 2; ``nN-solo``: its first robot alone; ``nN-every``: the team with
one Crumb per visited Place, the alternative §2.2 names for future work):

- **legs**: a robot's leg ends when it reaches the place its round seeks (the brain's own
  :class:`PlaceRound` replayed on the run's place events, so a place passed on the way is not a
  leg, as for the brain); **rounds** = legs / N. Both per hour of the run, for the team.
- **efficiency** (Try §3.6: "average time between Places ... gives an average speed of 0.23 m/s
  ... approximately 92% of maximum efficiency"): the shortest routes of the legs made (for a
  disc of the robots' radius, :class:`~teamnav.world.shortest_path.GridPaths`; the paper used
  its ~31 m route), summed, over the summed lifetimes, over the cruise speed. Lifetime (Try
  Table 1) is the time of the robot's last leg; a robot that made no leg was working the whole
  run, so its lifetime is the run's length (a choice where the paper is silent: all its robots
  made trips; :mod:`~teamnav.papers.trails.metrics` counts such a robot as 0).
- **memory**: the largest Trail a robot held (``crumbs_max`` of the ``trails`` metric, Try §2.1.3)
  and the radio bytes sent per robot per minute (``bytes_sent`` of ``messages``: each 2-s
  temporary trail carries a copy of every Place, §2.2 step 2, so it grows with N).

No verdict: no paper number exists for N > 2 (``claims/beyond.yaml`` says so, and fixes the
seeds, length and metrics before the report runs). Quick mode (CI): N = 2 and 3, seed 0, 10 min.
Full mode: every case of the sweep, seeds 0-9, 30 min (110 runs).
"""

from __future__ import annotations

import json
from functools import lru_cache
from typing import Any, Sequence

import numpy as np

from teamnav.papers.trails.brains.forager import PlaceRound
from teamnav.experiments.report.model import Plot, Series, Table, Text
from teamnav.papers.trails.report import _trails as T

__all__ = ["FULL_DURATION_S", "MAIL_SWEEP", "QUICK_CASES", "QUICK_DURATION_S", "RoundSetup", "case_setup",
           "mail_round", "round_legs", "run_values", "sharing_text"]

MAIL_SWEEP = "beyond-mail-round"
#: quick mode (CI): the smallest rounds, one seed
QUICK_CASES = ("n2", "n3")
QUICK_DURATION_S = 600.0
FULL_DURATION_S = 1800.0
FULL_SEEDS = tuple(range(10))


class RoundSetup:
    """What a case's runs are judged against, read from its scenario (nothing hard-coded).

    Attributes
    ----------
    round : list of str
        Event names in visiting order (every robot group's ``round``; they must agree).
    event_of : dict of str to str
        Place name -> the event it fires (arrivals record place names).
    leg_m : list of float
        ``leg_m[i]``: shortest route [m] from ``round[i]`` to ``round[(i + 1) % N]``.
    n_robots : int
        Robots in the run.
    cruise_mps : float
        The robots' cruise speed [m/s].
    """

    def __init__(self, round_: list[str], event_of: dict[str, str], leg_m: list[float], n_robots: int,
                 cruise_mps: float) -> None:
        if len(leg_m) != len(round_):
            raise ValueError(f"leg_m must give one route per leg of the round ({len(round_)}), got {len(leg_m)}")
        if not (cruise_mps > 0.0 and n_robots >= 1):
            raise ValueError(f"cruise_mps must be > 0 and n_robots >= 1, got {cruise_mps!r} and {n_robots!r}")
        self.round, self.event_of, self.leg_m = list(round_), dict(event_of), [float(x) for x in leg_m]
        self.n_robots, self.cruise_mps = int(n_robots), float(cruise_mps)

    @property
    def n_places(self) -> int:
        return len(self.round)


def round_legs(arrivals: Sequence[Sequence[Any]], n_robots: int, round_: Sequence[str],
               event_of: dict[str, str]) -> list[tuple[int, float, int]]:
    """Every leg of every robot: ``(robot, time [s], leg index i)``, leg i going from ``round[i]``
    to ``round[(i + 1) % N]``, in time order.

    ``arrivals``: ``[[t_s, robot, place], ...]`` (the ``trails_series`` metric's
    ``arrivals_series``). Each robot starts at ``round[0]`` (the scenario starts it inside that
    place, Try §3.5), and its events go through :class:`PlaceRound`, the brain's own round.

    Raises
    ------
    ValueError
        A place the scenario does not have, or a robot index outside ``[0, n_robots)``.

    Examples
    --------
    >>> arr = [[5.0, 0, "b"], [6.0, 0, "a"], [9.0, 0, "c"], [12.0, 0, "b"], [20.0, 0, "c"]]
    >>> round_legs(arr, 1, ["a", "b", "c"], {"a": "a", "b": "b", "c": "c"})
    [(0, 5.0, 0), (0, 9.0, 1)]
    """
    rounds = [PlaceRound(list(round_)) for _ in range(n_robots)]
    out = []
    for t, r, place in sorted(((float(a[0]), int(a[1]), str(a[2])) for a in arrivals), key=lambda a: (a[0], a[1])):
        if place not in event_of:
            raise ValueError(f"arrivals_series: place {place!r} is not one of the scenario's places {sorted(event_of)}")
        if not 0 <= r < n_robots:
            raise ValueError(f"arrivals_series: robot {r} is outside [0, {n_robots})")
        pr = rounds[r]
        for _ in pr.observe((event_of[place],), t):  # the goal was index - 1; the leg began one before it
            out.append((r, t, (pr.index - 2) % len(round_)))
    return out


def run_values(row: dict, setup: RoundSetup, duration_s: float) -> dict[str, float]:
    """One run's legs and rounds per hour, efficiency and memory (module docstring).

    Returns NaN-free keys only: ``legs_per_hour``, ``rounds_per_hour``, ``legs_per_robot_hour``,
    ``efficiency`` (fraction of cruise), ``crumbs_max`` and ``bytes_per_robot_min`` (where the row
    has them)."""
    if not duration_s > 0.0:
        raise ValueError(f"duration_s must be > 0, got {duration_s!r}")
    raw = row.get("arrivals_series")
    if not isinstance(raw, str):
        raise ValueError("the row has no arrivals_series: run the sweep with the trails_series metric")
    legs = round_legs(json.loads(raw), setup.n_robots, setup.round, setup.event_of)
    hours = duration_s / 3600.0
    life = np.full(setup.n_robots, duration_s)  # no leg: working all run long
    for r in range(setup.n_robots):
        times = [t for rr, t, _ in legs if rr == r]
        if times:
            life[r] = max(times)
    route_m = sum(setup.leg_m[i] for _, _, i in legs)
    out = {"legs_per_hour": len(legs) / hours, "rounds_per_hour": len(legs) / setup.n_places / hours,
           "legs_per_robot_hour": len(legs) / setup.n_robots / hours,
           "efficiency": route_m / float(life.sum()) / setup.cruise_mps}
    if isinstance(row.get("crumbs_max"), (int, float)):
        out["crumbs_max"] = float(row["crumbs_max"])
    if isinstance(row.get("bytes_sent"), (int, float)):
        out["bytes_per_robot_min"] = float(row["bytes_sent"]) / setup.n_robots / (duration_s / 60.0)
    return out


@lru_cache(maxsize=4)
def _paths(scenario_name: str, clearance_m: float):
    """The scenario's map as shortest paths for a disc of ``clearance_m`` (built once: about a second)."""
    from teamnav.experiments.spec import build_grid, load_scenario
    from teamnav.world.shortest_path import GridPaths

    return GridPaths(build_grid(load_scenario(scenario_name)), clearance_m)


def case_setup(scenario_name: str, case: dict) -> RoundSetup:
    """The :class:`RoundSetup` of one sweep case (its overrides applied to the scenario).

    Raises
    ------
    ValueError
        The robot groups' rounds differ, or a round names an event no place fires.
    """
    from teamnav.experiments.spec import load_scenario

    sc = load_scenario(scenario_name, overrides={k: v for k, v in case.items() if k != "case"})
    groups = [g for g in sc.robots if g.count > 0]
    rounds = {tuple((g.params or {}).get("round", ())) for g in groups}
    if len(rounds) != 1:
        raise ValueError(f"case {case.get('case')!r}: every robot group's params.round must be the same, got {sorted(rounds)}")
    round_ = rounds.pop()
    event_of = {p.name: p.event for p in sc.places if p.event}
    lacking = [e for e in round_ if e not in event_of.values()]
    if lacking:
        raise ValueError(f"case {case.get('case')!r}: params.round names {lacking}, which no place fires "
                         f"(places fire {sorted(event_of.values())})")
    if any(k == "map" or k.startswith("map.") for k in case):
        raise ValueError(f"case {case.get('case')!r}: a case may not change the map (the routes are the scenario's)")
    xy = {p.event: (float(p.x_m), float(p.y_m)) for p in sc.places if p.event}
    pts = np.array([xy[e] for e in round_], dtype=float)
    lengths = _paths(scenario_name, max(float(g.radius_m) for g in groups)).lengths(pts, pts)
    n = len(round_)
    legs = [float(lengths[i, (i + 1) % n]) for i in range(n)]
    cruise = float((groups[0].params or {}).get("cruise_speed_mps", 0.25))
    return RoundSetup(list(round_), event_of, list(legs), sum(int(g.count) for g in groups), cruise)


def sharing_text(team: list[dict], solo: list[dict], team_setup: RoundSetup, solo_setup: RoundSetup,
                 duration_s: float) -> str:
    """The per-seed difference in legs per robot per hour, the team minus its first robot alone, on
    the seeds both ran: ``"+1.9 ± 1.8 legs/robot/h (s.e., 10 seeds): no difference beyond the
    seeds' spread"``; a difference beyond twice its standard error is named as one."""
    a = {r.get("seed"): run_values(r, team_setup, duration_s)["legs_per_robot_hour"] for r in team}
    b = {r.get("seed"): run_values(r, solo_setup, duration_s)["legs_per_robot_hour"] for r in solo}
    common = sorted(k for k in set(a) & set(b) if k is not None)
    if len(common) < 2:
        return "too few paired seeds to compare"
    d = np.array([a[k] - b[k] for k in common])
    m, se = float(d.mean()), float(d.std(ddof=1) / np.sqrt(d.size))
    verdict = ("no difference beyond the seeds' spread: sharing does not help here" if abs(m) <= 2.0 * se
               else "the team's robots make more legs each" if m > 0 else "the team's robots make fewer legs each")
    return f"{m:+.1f} ± {se:.1f} legs/robot/h (s.e., {d.size} seeds): {verdict}"


def _kind(label: str) -> str:
    return "solo" if label.endswith("-solo") else "every" if label.endswith("-every") else "team"


KIND_TEXT = {"team": "4 robots, a Crumb for the last Place (the paper)", "every": "4 robots, a Crumb per visited Place (§2.2 alternative)",
             "solo": "1 robot (bug) alone"}


def mail_round(ctx) -> list:
    """The block: a table per case and two plots against N (efficiency; Trail size and bytes)."""
    from teamnav.experiments.sweep import load_sweep

    missing = T.brains_missing(["trail-share-v1"])
    if missing is not None:
        return [missing]
    quick = bool(ctx.quick)
    spec = load_sweep(MAIL_SWEEP)
    cases = {str(c["case"]): c for c in spec.cases}
    labels = list(QUICK_CASES) if quick else list(cases)
    seeds, dur = ([0], QUICK_DURATION_S) if quick else (list(FULL_SEEDS), FULL_DURATION_S)
    data = T.by_case(T.ok(ctx.sweep(T.case_spec(MAIL_SWEEP, labels), seeds=seeds, duration_s=dur)))
    setups = {lab: case_setup(spec.scenario, cases[lab]) for lab in labels}
    per: dict[str, dict[str, np.ndarray]] = {}
    for lab in labels:
        vals = [run_values(r, setups[lab], dur) for r in data.get(lab, [])]
        per[lab] = {k: np.array([v[k] for v in vals if k in v], dtype=float)
                    for k in ("legs_per_hour", "rounds_per_hour", "legs_per_robot_hour", "efficiency", "crumbs_max",
                              "bytes_per_robot_min")}
    order = sorted(labels, key=lambda lab: ({"team": 0, "every": 1, "solo": 2}[_kind(lab)], setups[lab].n_places))
    rows = []
    for lab in order:
        s, v = setups[lab], per[lab]
        rows.append([str(s.n_places), KIND_TEXT[_kind(lab)], f"{sum(s.leg_m):.1f}", T.msd(v["legs_per_hour"], "{:.1f}"),
                     T.msd(v["rounds_per_hour"], "{:.2f}"), T.msd(v["legs_per_robot_hour"], "{:.1f}"),
                     T.msd(100.0 * v["efficiency"], "{:.1f}", "%"), T.msd(v["crumbs_max"], "{:.0f}"),
                     T.msd(v["bytes_per_robot_min"], "{:.0f}")])
    first = setups[labels[0]]
    blocks: list = [Text(
        "The papers' future work, N places (Try §2.1: the method was \u201cgeneralized ... to handle N places\u201d but only "
        "N = 2 was shown; §4: \u201ca mail-delivery application\u201d): trail-share-v1 robots carry a mail round of N places "
        f"in a fixed cyclic order (scenario {spec.scenario}: the MIT basement hallways, a real map whose corridors form "
        f"one loop of about 139 m; places {', '.join(setups[max(labels, key=lambda x: setups[x].n_places)].round)} "
        "in that order, the round of N using the first N). The 2002 team's per-robot drift, cruise "
        f"{first.cruise_mps:g} m/s. "
        + (f"Seeds {seeds[0]}-{seeds[-1]}" if len(seeds) > 1 else f"Seed {seeds[0]}") + f", {dur / 60:g} min per run"
        + (" (quick mode: N = 2 and 3, one seed; the pipeline works, the numbers are not the result)." if quick else "."))]
    blocks.append(Table(
        "Mail round: units, efficiency and memory against N",
        ["N", "team", "round's route [m]", "legs per hour (team)", "rounds per hour (team)", "legs per robot per hour",
         "efficiency (route over lifetime / cruise)", "largest Trail (crumbs)", "bytes sent per robot per minute"],
        rows, note=f"mean ± std over runs (n = runs); sweep {MAIL_SWEEP}. A leg ends at the place the round seeks "
                   "(passing another is not a leg); route = shortest path for the robots' radius. No verdict: no paper "
                   "gives a number for N > 2 (claims/beyond.yaml)."))
    eff_series, mem_series = [], []
    for kind in ("team", "every", "solo"):
        labs = sorted((lab for lab in labels if _kind(lab) == kind and per[lab]["efficiency"].size),
                      key=lambda lab: setups[lab].n_places)
        if not labs:
            continue
        x = [float(setups[lab].n_places) for lab in labs]
        e = [100.0 * per[lab]["efficiency"] for lab in labs]
        eff_series.append(Series(KIND_TEXT[kind], x, [float(a.mean()) for a in e], [float(np.percentile(a, 25)) for a in e],
                                 [float(np.percentile(a, 75)) for a in e], style="line+points"))
        c = [per[lab]["crumbs_max"] for lab in labs]
        if all(a.size for a in c):
            mem_series.append(Series(KIND_TEXT[kind], x, [float(a.mean()) for a in c], [float(a.min()) for a in c],
                                     [float(a.max()) for a in c], style="line+points"))
    if eff_series:
        blocks.append(Plot("Mail round efficiency against N", "places in the round (N)", "% of cruise speed", eff_series,
                           caption="mean over seeds, band 25-75 %; no paper number for N > 2 (no verdict)."))
    thr = []
    for kind in ("team", "every", "solo"):
        labs = sorted((lab for lab in labels if _kind(lab) == kind and per[lab]["legs_per_robot_hour"].size),
                      key=lambda lab: setups[lab].n_places)
        if labs:
            a = [per[lab]["legs_per_robot_hour"] for lab in labs]
            thr.append(Series(KIND_TEXT[kind], [float(setups[lab].n_places) for lab in labs], [float(x.mean()) for x in a],
                              [float(np.percentile(x, 25)) for x in a], [float(np.percentile(x, 75)) for x in a],
                              style="line+points"))
    if thr:
        sharing = "; ".join(f"N = {setups[lab].n_places}: {sharing_text(data.get(lab, []), data.get(lab + '-solo', []), setups[lab], setups[lab + '-solo'], dur)}"
                            for lab in sorted(labels, key=lambda x: setups[x].n_places)
                            if _kind(lab) == "team" and lab + "-solo" in setups)
        blocks.append(Plot("Legs per robot per hour against N: what sharing buys", "places in the round (N)",
                           "legs per robot per hour", thr,
                           caption="mean over seeds, band 25-75 %. Team minus bug alone, per seed: "
                                   + (sharing or "no solo runs in this mode") + "."))
    if mem_series:
        blocks.append(Plot("Largest Trail a robot held against N", "places in the round (N)", "crumbs", mem_series,
                           caption="mean over seeds, band min-max; crumbs expire after 4 min (Try §2.3 step 2)."))
    return blocks
