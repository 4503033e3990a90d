"""collab-mcl experiments: scenarios, sweeps, the localization metrics, the detection model
learned in simulation, and (slow) the paper's results."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from teamnav.papers.collab_mcl.detection_training import DEFAULT_DETECTOR, generate_training_data
from teamnav.papers.collab_mcl.metrics import LOCALIZED_M, localization
from teamnav.experiments.metrics import RunData
from teamnav.experiments.runner import run
from teamnav.experiments.spec import load_scenario
from teamnav.experiments.sweep import expand, load_sweep
from teamnav.localization import fit_detection_model
from teamnav.world import builtin_map

SCENARIOS = ["collab-mcl-hallway", "collab-mcl-hexagon", "collab-mcl-detection"]
TINY = {"max_particles": 300, "min_particles": 100}


def _tiny(name: str) -> dict:
    scn = load_scenario(name)
    out = {f"robots.{i}.count": min(g.count, 2) for i, g in enumerate(scn.robots)}
    for i in range(len(scn.robots)):
        for k, v in TINY.items():
            out[f"robots.{i}.params.{k}"] = v
    return out


@pytest.mark.parametrize("name", SCENARIOS)
def test_scenario_validates_and_runs_briefly(name):
    scn = load_scenario(name, overrides=_tiny(name), duration_s=3.0)
    assert scn.give_map and all(g.controller == "mcl-wander-v1" for g in scn.robots)
    m = run(scn, progress=False).metrics
    assert 0.0 <= m["loc_localized_fraction"] <= 1.0
    series = json.loads(m["loc_error_series"])
    assert len(series["t_s"]) == len(series["mean"]) >= 3


def test_hexagon_groups_are_one_sensor_kind_each():
    scn = load_scenario("collab-mcl-hexagon")
    kinds = [[s.kind for s in g.sensors] for g in scn.robots]
    assert kinds == [["sonar"], ["laser"]] and [g.count for g in scn.robots] == [4, 4]


def test_sweeps_grid_single_vs_collaborative_over_enough_seeds():
    trials = expand(load_sweep("collab-mcl-hallway"))
    assert len(trials) == 16
    assert sorted({t.params["robots.0.params.collaborate"] for t in trials}) == [False, True]
    assert len({t.seed for t in trials}) >= 8
    det = expand(load_sweep("collab-mcl-detection"))
    assert len({t.seed for t in det}) >= 10


def _rundata(errors: np.ndarray, t_s: np.ndarray, kinds=("sonar", "laser")) -> RunData:
    """Robots at x = 10 m; each logs 4 samples at distance errors[k, i] from its true position."""
    n = errors.shape[1]
    truth = np.zeros((t_s.shape[0], n, 3))
    truth[:, :, 0] = 10.0
    truth[:, :, 1] = np.arange(n)
    logs = []
    for k, t in enumerate(t_s):
        for i in range(n):
            e = errors[k, i]
            pts = [10.0 + e, i, 10.0 - e, i, 10.0, i + e, 10.0, i - e]
            v = {"pts": pts, "syncs": k}
            if k == 0:
                v.update(sensor_kind=kinds[i % len(kinds)], group=f"g{i % 2}")
            logs.append({"step": k * 10, "t_s": float(t), "robot": i, "values": v})
    return RunData(t_s=t_s, true_pose=truth, odom_pose=truth.copy(), stalled=np.zeros((t_s.shape[0], n), bool),
                   radius_m=np.full(n, 0.25), grid=builtin_map("hexagon").grid, logs=logs, n_steps=10 * len(t_s),
                   dt_s=0.1)


def test_metric_time_to_localize_with_censoring():
    t = np.arange(10.0)
    err = np.full((10, 2), 5.0)
    err[4:, 0] = 1.0  # robot 0 below 1.5 m from t = 4 s; robot 1 never
    m = localization(_rundata(err, t))
    assert m["loc_censored"] == 1
    assert m["loc_time_to_localize_s"] == pytest.approx((4.0 + 10.0) / 2)  # censored at the duration
    assert m["loc_localized_fraction"] == 0.5 and m["loc_final_localized_fraction"] == 0.5
    assert m["loc_final_error_m"] == pytest.approx(3.0)
    assert m["loc_time_to_localize_s_sonar"] == 4.0 and m["loc_time_to_localize_s_laser"] == 10.0
    assert m["loc_syncs"] == 2 * 9
    s = json.loads(m["loc_error_series"])
    assert s["by_kind"]["sonar"][0] == 5.0 and s["by_kind"]["sonar"][-1] == 1.0
    assert LOCALIZED_M == 1.5


def test_metric_is_empty_for_runs_without_particle_logs():
    d = _rundata(np.ones((3, 2)), np.arange(3.0))
    bare = RunData(t_s=d.t_s, true_pose=d.true_pose, odom_pose=d.odom_pose, stalled=d.stalled, radius_m=d.radius_m,
                   grid=d.grid, logs=[{"step": 0, "t_s": 0.0, "robot": 0, "values": {"mode": 1}}])
    assert localization(bare) == {}


def test_detection_model_fit_recovers_the_simulated_noise():
    """§4.2: the ML fit on data labelled from known poses recovers the detector's settings."""
    cfg = DEFAULT_DETECTOR.model_copy(update={"range_noise_std_m": 0.3, "bearing_noise_std_deg": 4.0,
                                              "p_false_negative": 0.1, "p_false_positive": 0.05})
    data = generate_training_data(cfg, n_robots=8, duration_s=300.0, seed=3)
    m = fit_detection_model(data)
    assert m.n_detections > 300
    assert m.range_std_m == pytest.approx(0.3, rel=0.12)
    assert math.degrees(m.bearing_std_rad) == pytest.approx(4.0, rel=0.12)
    assert abs(m.range_bias_m) < 0.05 and abs(m.bearing_bias_rad) < math.radians(0.6)
    assert m.p_false_negative == pytest.approx(0.1, abs=0.04)
    assert m.p_false_positive == pytest.approx(0.05, abs=0.02)


# ---------------------------------------------------------------------------- reproductions
@pytest.mark.slow
def test_fig11_single_detection_collapses_the_corridor_belief(tmp_path):
    from teamnav.experiments.sweep import sweep

    rows = sweep("collab-mcl-detection", out_dir=tmp_path, progress=False).rows()
    final = {c: [r["metrics"]["loc_final_error_m_g_robin"] for r in rows
                 if r["params"]["robots.1.params.collaborate"] is c] for c in (False, True)}
    assert np.all(np.array(final[True]) < 1.5)  # 10 of 10: the single detection collapses Robin's belief
    assert np.mean(final[True]) < np.mean(final[False])


@pytest.mark.slow
def test_hexagon_every_robot_localizes_together(tmp_path):
    """§5.2.2 / Fig. 14: together all 8 robots localize in (nearly) every run; alone they do not."""
    from teamnav.experiments.sweep import sweep

    team = sweep("collab-mcl-hexagon", out_dir=tmp_path / "t", progress=False).rows()
    alone = sweep("collab-mcl-hexagon", name="alone", out_dir=tmp_path / "a", progress=False,
                  set={"robots.0.params.collaborate": False, "robots.1.params.collaborate": False}).rows()
    full_team = [r["metrics"]["loc_final_localized_fraction"] == 1.0 for r in team]
    full_alone = [r["metrics"]["loc_final_localized_fraction"] == 1.0 for r in alone]
    assert len(full_team) == 8 and sum(full_team) >= 7 and sum(full_alone) <= 1


@pytest.mark.slow
def test_hallway_collaboration_is_faster(tmp_path):
    """§5.2.1 must-show: collaborative time to localize below single-robot (8 runs each)."""
    from teamnav.experiments.sweep import sweep

    rows = sweep("collab-mcl-hallway", out_dir=tmp_path, progress=False).rows()
    ttl = {c: {r["seed"]: r["metrics"]["loc_time_to_localize_s"] for r in rows
               if r["params"]["robots.0.params.collaborate"] is c} for c in (False, True)}
    seeds = sorted(set(ttl[False]) & set(ttl[True]))
    assert len(seeds) >= 8
    # "clearly faster", as the report judges it: the same seed starts both conditions from the same
    # poses, so the paired reduction must lie beyond two standard errors (measured: -87 +- 19 s, 8/8)
    change = np.array([ttl[True][s] - ttl[False][s] for s in seeds])
    assert change.mean() + 2 * change.std(ddof=1) / np.sqrt(len(seeds)) < 0
    assert np.mean([ttl[True][s] for s in seeds]) < 0.7 * np.mean([ttl[False][s] for s in seeds])


@pytest.mark.slow
def test_report_section_quick_build(tmp_path):
    """The section builds in quick mode with a minimal report context (CI budget: about a minute)."""
    import time

    from teamnav.experiments.report.model import Comparison, Plot
    from teamnav.papers.collab_mcl.report.section import SECTION
    from teamnav.experiments.sweep import sweep

    class Ctx:
        quick, out_dir, progress = True, tmp_path, False

        def sweep(self, spec, **kw):
            name = kw.get("name") or (spec if isinstance(spec, str) else spec.sweep_name)
            return sweep(spec, out_dir=tmp_path / "sweeps" / name, workers=2, progress=False, **kw)

    t0 = time.perf_counter()
    blocks = SECTION.build(Ctx())
    assert time.perf_counter() - t0 < 120
    assert sum(isinstance(b, Comparison) for b in blocks) >= 3
    assert all(len(s.x) > 2 for b in blocks if isinstance(b, Plot) for s in b.series)
    # FIDELITY §2: the precondition and both columns' ledgers before the verdicts, a column on every comparison
    from teamnav.experiments.report.model import Ledger, Precondition

    kinds = [type(b) for b in blocks]
    first_comparison = kinds.index(Comparison)
    assert Precondition in kinds[:first_comparison] and kinds[:first_comparison].count(Ledger) == 2
    assert all(b.column in ("paper", "teamnav") for b in blocks if isinstance(b, Comparison))


def _hallway_rows(alone_s, team_s):
    rows = []
    for collaborate, times in ((False, alone_s), (True, team_s)):
        for seed, t in enumerate(times):
            rows.append({"status": "ok", "seed": seed, "params": {"robots.0.params.collaborate": collaborate},
                         "metrics": {"loc_time_to_localize_s": t, "loc_censored": 0,
                                     "loc_final_localized_fraction": 1.0}})
    return rows


@pytest.mark.parametrize("team_shift_s, holds", [(-60.0, True), (-5.0, False)])
def test_hallway_verdict_needs_a_paired_reduction_beyond_two_standard_errors(team_shift_s, holds, monkeypatch):
    from types import SimpleNamespace

    from teamnav.papers.collab_mcl.report import _collab_fidelity as fid
    from teamnav.papers.collab_mcl.report.section import _hallway

    monkeypatch.setitem(fid.HALLWAY_ALONE, "holds", True)  # the rule itself (rule 10's precondition aside)

    alone = [100.0, 300.0, 200.0, 400.0, 150.0, 250.0, 350.0, 180.0]       # a large run-to-run spread
    jitter = [10.0, -10.0, 5.0, -5.0, 8.0, -8.0, 3.0, -3.0]
    team = [a + team_shift_s + j for a, j in zip(alone, jitter)]           # lower mean either way
    rows = _hallway_rows(alone, team)
    res = SimpleNamespace(rows=lambda: rows, total=len(rows))
    comparison = _hallway(SimpleNamespace(quick=False, sweep=lambda *a, **k: res))[0]
    assert comparison.holds is holds and comparison.column == "paper"
    assert "faster together in" in comparison.ours
    # without §5.2.1's single-robot behaviour on tuning seeds the claim is not judged (rule 10)
    monkeypatch.setitem(fid.HALLWAY_ALONE, "holds", False)
    unmet = _hallway(SimpleNamespace(quick=False, sweep=lambda *a, **k: res))[0]
    assert unmet.holds is None and "precondition not met" in unmet.ours + unmet.differs


def test_claim_file_report_seeds_and_the_rules_changed_with_their_data():
    """The section's rules live in claims/collab-mcl.yaml, on >= 20 fresh judged seeds (>= 2000)
    in full mode; the two commits that tightened a rule after its data are in the history."""
    from teamnav.experiments.claims import load_claims

    cf = load_claims("collab-mcl")
    ids = {c.id for c in cf.claims}
    teamnav_only = ("fp-filter", "anon-assoc", "delayed-integration", "delayed-vs-drop")  # paper_rules refuses them
    assert {"hallway-faster", "hexagon-together", "single-detection", "fp-breaks", *teamnav_only} == ids
    for c in cf.claims:
        assert len(c.seed_list) >= 20 and min(c.seed_list) >= 2000 and c.history  # fresh judged seeds (2026-11-29)
        assert c.judged == ("teamnav" if c.id in teamnav_only else "paper_rules")
    after = {(c.id, h.commit) for c in cf.claims for h in c.history if not h.before_data}
    assert after == {("hallway-faster", "79674cc"), ("hexagon-together", "b81d177"), ("single-detection", "b81d177"),
                     ("delayed-integration", "349d51d"), ("delayed-vs-drop", "349d51d")}
    assert [(r.metric, r.op, r.threshold) for r in cf["single-detection"].rule] == [
        ("team_final_error_mean_m", "<", 1.5), ("alone_final_error_mean_m", ">=", 1.5), ("team_localized_frac", ">=", 0.9)]
