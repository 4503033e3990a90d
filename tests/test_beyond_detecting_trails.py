"""Beyond the papers, combination 3: ``detecting-trails-v1`` (a map-less belief synced on detections) and its belief."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.beyond.brains.detecting import DetectingTrails, DetectingTrailsParams
from teamnav.control.check import check_brain
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Detection, Observation
from teamnav.experiments import runner
from teamnav.localization import BeliefSync, SyncParams
from teamnav.localization.detection_model import DetectionModel
from teamnav.localization.motion import MotionParams
from teamnav.localization.odometry_belief import OdometryBelief, OdometryBeliefParams

_QUIET = MotionParams(alpha=(0.0, 0.0, 0.0, 0.0))


def _belief(n=400, seed=0, **kw) -> OdometryBelief:
    return OdometryBelief(OdometryBeliefParams(n_particles=n, **kw), np.random.default_rng(seed))


def _spread(b: OdometryBelief) -> float:
    c = b.estimate().cov
    return math.sqrt(c[0, 0] + c[1, 1])


def test_prediction_only_spread_grows_with_distance():
    """No map, no sensor update: the only evidence is odometry, so the belief widens as the robot
    drives (Table 5.6 noise and the drift-rate prior), never narrows."""
    b = _belief(n=2000, heading_rate_std_deg_per_min=2.0)
    b.init_pose([0.0, 0.0, 0.0], np.diag([1e-4, 1e-4, 1e-4]))
    spreads = []
    for leg in range(4):
        for _ in range(50):  # 5 m at 0.4 m/s
            b.predict([0.1, 0.0, 0.0], 0.25)
        spreads.append(_spread(b))
    assert all(a < c for a, c in zip(spreads, spreads[1:])), spreads
    assert spreads[-1] > 3.0 * spreads[0]
    # 20 m in 50 s with 2 deg/min of rate spread: the lateral spread is ~ 20 m x (2 deg/min x 50 s / 2)
    # ~ 0.29 m plus the random part; well below a metre, well above the start's 1 cm
    assert 0.1 < spreads[-1] < 1.0


@settings(max_examples=40, deadline=None)
@given(dtheta=st.floats(-1.0, 1.0), dt=st.floats(0.0, 30.0), rate_sd=st.floats(0.1, 10.0))
def test_each_sample_takes_its_own_drift_rate_off_the_reported_rotation(dtheta, dt, rate_sd):
    """With the random part off, a sample's heading after a turn of ``dtheta`` in ``dt`` seconds is
    ``dtheta - b_i dt`` (the drift the simulator adds to the reported rotation, undone per sample)."""
    b = _belief(n=50, motion=_QUIET, heading_rate_std_deg_per_min=rate_sd)
    b.init_pose([1.0, 2.0, 0.0], np.zeros((3, 3)))
    b.predict([0.0, 0.0, dtheta], dt)
    want = np.angle(np.exp(1j * (dtheta - b.rates_radps * dt)))
    assert np.allclose(np.angle(np.exp(1j * (b.particles[:, 2] - want))), 0.0, atol=1e-9)
    assert np.allclose(b.particles[:, :2], [1.0, 2.0], atol=1e-12)
    assert np.std(b.rates_radps) * 60.0 == pytest.approx(math.radians(rate_sd), rel=0.5)


def test_a_detection_pulls_the_detected_robots_belief_to_the_observers_estimate():
    """Eq. 13-14 with an exact detector: the observer (tight belief at the origin, facing +x) sees
    the detected robot 2.0 m ahead; the detected robot believed itself at x = 2.5 +- 0.5 m. Eq. 14
    multiplies its belief by the observer's tree: the product of N(2.5, 0.5²) and a near-exact
    N(2.0, 0.05²) has its mean at 2.005 m and a spread of 0.05 m."""
    model = DetectionModel(range_std_m=0.05, bearing_std_rad=0.005)
    params = SyncParams(min_travel_m=0.0)
    m, n = _belief(n=3000, seed=1), _belief(n=3000, seed=2)
    m.init_pose([0.0, 0.0, 0.0], np.diag([1e-4, 1e-4, 1e-6]))
    n.init_pose([2.5, 0.0, 0.0], np.diag([0.25, 0.25, 0.01]))
    sm = BeliefSync(0, model, params, np.random.default_rng(3))
    sn = BeliefSync(1, model, params, np.random.default_rng(4))
    msgs = sm.on_detections(m, [Detection(robot_id=1, range_m=2.0, bearing_rad=0.0)], 1.0)
    assert len(msgs) == 1 and msgs[0].to == 1
    before = n.estimate().pose.copy()
    replies = sn.on_message(n, msgs[0], 1.0)
    after = n.estimate()
    assert before[0] == pytest.approx(2.5, abs=0.05)
    assert after.pose[0] == pytest.approx(2.0, abs=0.08) and after.pose[1] == pytest.approx(0.0, abs=0.08)
    assert math.sqrt(after.cov[0, 0] + after.cov[1, 1]) < 0.2  # 0.71 m before
    assert sn.applied["detection"] == 1
    # symmetric (§2.3): the detected robot answers with its own position tree, which the observer folds in
    # too; the observer's tight belief barely moves (its prior is 100x sharper than the answer)
    assert len(replies) == 1
    m_before = m.estimate().pose.copy()
    sm.on_message(m, replies[0], 1.0)
    assert sm.applied["inverse"] == 1
    assert np.hypot(*(m.estimate().pose[:2] - m_before[:2])) < 0.02


def test_resampling_after_a_detection_keeps_the_rates_with_their_samples():
    """Eq. 14 reweights samples; the next motion step resamples and each rate goes with its sample,
    so the rates that explain the detection survive (the belief learns its drift)."""
    b = _belief(n=1000, seed=5, motion=_QUIET, heading_rate_std_deg_per_min=4.0, heading_rate_jitter_deg_per_min=0.0)
    b.init_pose([0.0, 0.0, 0.0], np.zeros((3, 3)))
    f = (b.rates_radps > 0).astype(float)  # evidence that only positive rates fit
    assert b.multiply_weights(f)
    b.predict([0.0, 0.0, 0.0], 1.0)
    assert (b.rates_radps > 0).all()
    assert np.allclose(b.weights, 1.0 / 1000)


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="brain: expected a brain that reads odom_pose"):
        DetectingTrailsParams(brain="localized-v1")
    with pytest.raises(ValueError, match="n_particles"):
        OdometryBeliefParams(n_particles=1)
    b = _belief(n=10)
    with pytest.raises(ValueError, match="call init_pose"):
        b.predict([0.1, 0.0, 0.0], 0.1)
    b.init_pose([0.0, 0.0, 0.0], np.eye(3) * 0.01)
    with pytest.raises(ValueError, match="dt_s must be a finite number >= 0"):
        b.predict([0.1, 0.0, 0.0], -1.0)
    with pytest.raises(ValueError, match="cov must be a symmetric"):
        b.init_pose([0.0, 0.0, 0.0], -np.eye(3))


def test_passes_the_brain_check_without_a_map():
    check_brain("detecting-trails-v1", n_steps=30)


def _obs(t, pose, delta, detections=(), inbox=()):
    return Observation(robot_id=0, step=int(round(t * 10)), time_s=t, odom_pose=np.asarray(pose, float),
                       odom_delta=np.asarray(delta, float), detections=tuple(detections), inbox=tuple(inbox))


def test_the_inner_brain_drives_on_the_belief_and_a_detection_sends_a_tree():
    """The inner brain's odom_pose is the belief's estimate (no truth anywhere in the brain's
    input); a detection of teammate 1 becomes one eq.-13 message to robot 1; collaborate=False
    sends none."""
    info = RobotInfo(robot_id=0, team_size=2, radius_m=0.25, kinematics="unicycle", max_v_mps=0.5,
                     max_omega_radps=1.0, step_length_m=0.0, dt_s=0.1)
    seen = []

    for collaborate in (True, False):
        brain = DetectingTrails(DetectingTrailsParams(brain="idle-v1", collaborate=collaborate,
                                                      belief={"motion": {"alpha": [0, 0, 0, 0]},
                                                              "heading_rate_std_deg_per_min": 0.0}),
                                np.random.default_rng(0), info)
        inner_step = brain.inner.step
        brain.inner.step = lambda obs, f=inner_step: (seen.append(np.array(obs.odom_pose)), f(obs))[1]
        _, out = brain.step(_obs(0.0, [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]))
        for i in range(1, 11):
            _, out = brain.step(_obs(0.1 * i, [1.0 + 0.05 * i, 1.0, 0.0], [0.05, 0.0, 0.0],
                                     detections=[Detection(robot_id=1, range_m=2.0, bearing_rad=0.0)] if i == 10 else ()))
        sync = [m for m in out if m.kind == "mcl_sync"]
        assert len(sync) == (1 if collaborate else 0)
        assert seen[-1] == pytest.approx([1.5, 1.0, 0.0], abs=0.03)  # the belief tracks exact odometry
        assert "pts" in brain.log() and brain.log()["det_sent"] == len(sync)


def test_a_short_team_run_syncs_and_logs_samples(tmp_path):
    """The scenario runs: robots that start in a row facing east see each other at once, apply trees
    (loc_syncs > 0), and the localization metric scores their logged samples against the truth."""
    res = runner.run(runner.load_scenario("beyond-detecting-trails", duration_s=30.0), out_dir=tmp_path / "r",
                     progress=False)
    m = res.metrics
    assert m["loc_syncs"] > 0
    assert 0.0 < m["loc_mean_error_m"] < 1.0  # 30 s of exact odometry: the samples stay near the truth


def _fake_full(gain: float):
    """Full mode without running: one row per asked case and seed; the odometric team delivers
    68 - 8 k units per run, the detecting team ``gain`` more at k = 4 (the no-sync team 1 less)."""
    from _report_fakes import FakeFullContext

    def rows_for(spec, seeds):
        det = spec.sweep_name.startswith("beyond-")

        def units(case, s):
            k = float(case[1:].removesuffix("-nosync"))
            base = 68 - 8 * k + s % 2
            return base + (gain if k == 4 and det else 0) - (1 if case.endswith("-nosync") else 0)

        return [{"status": "ok", "seed": s, "params": {"case": c["case"]}, "units_total": units(c["case"], s) + (s % 3 - 1 if det else 0),
                 "breakdown_censored": 1, "loc_mean_error_m": 1.0 if det else None,
                 "loc_syncs": 400 if det and not c["case"].endswith("-nosync") else 0, "wall_time_s": 20.0}
                for c in spec.cases for s in seeds]

    return FakeFullContext(rows_for)


@pytest.mark.parametrize("gain, holds", [(3, True), (0, False)])
def test_full_mode_pairs_by_seed_and_judges_the_claim(gain, holds):
    from teamnav.experiments.report.model import Comparison, Table
    from teamnav.papers.beyond.report._beyond_detecting_trails import detecting_trails

    ctx = _fake_full(gain)
    blocks = detecting_trails(ctx)
    assert [(a[0], a[2]) for a in ctx.asked] == [("beyond-detecting-trails", 1800.0), ("blazing-drift", 1800.0)]
    assert ctx.asked[0][1] == list(range(10))
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert [r[0] for r in table.rows] == ["0", "0", "1", "1", "4", "4", "4"]
    (cmp,) = [b for b in blocks if isinstance(b, Comparison)]
    assert cmp.holds is holds
    # units differ by s % 3 within the detecting team: the paired gain's s.e. is not 0, and 0 gain is "no difference"
    (k4,) = [part for part in table.note.split("; ") if part.startswith("k = 4: detecting − odometric")]
    assert ("no difference beyond the seeds' spread" in k4.split(", detecting − no sync")[0]) is (gain == 0)
    assert k4.split(", detecting − no sync")[0].endswith("more") is (gain > 0)
    assert "cannot remove a drift they share" in cmp.differs


def test_claim_values_pair_only_common_seeds():
    from teamnav.papers.beyond.report._beyond_detecting_trails import claim_values

    sync = {4.0: [{"seed": s, "units_total": 10 + s} for s in range(5)]}
    odo = {4.0: [{"seed": s, "units_total": 8} for s in (0, 1, 2)]}
    v = claim_values(sync, {}, odo, 1800.0)
    assert v["units_k4_gain_mean"] == pytest.approx(2 * 3.0)  # per hour: (2, 3, 4) x 2
    assert v["units_k4_detecting_mean"] == pytest.approx(2 * 12.0)
    assert math.isnan(v["units_k4_nosync_mean"])


def test_quick_mode_asks_one_short_run_each_and_gives_no_verdict():
    from teamnav.experiments.report.model import Comparison
    from teamnav.papers.beyond.report._beyond_detecting_trails import detecting_trails

    ctx = _fake_full(3)
    ctx.quick = True
    blocks = detecting_trails(ctx)
    assert ctx.asked == [("beyond-detecting-trails", [0], 300.0), ("blazing-drift", [0], 300.0)]
    (cmp,) = [b for b in blocks if isinstance(b, Comparison)]
    assert cmp.holds is None and "quick mode" in cmp.ours


def test_the_sweep_pairs_with_blazing_drift_case_by_case():
    """x<k> of beyond-detecting-trails has blazing-drift x<k>'s drift on every robot; x<k>-nosync the
    same with the sync off on every robot (the block pairs them by case label and seed)."""
    from teamnav.experiments.sweep import load_sweep

    ours = {c["case"]: c for c in load_sweep("beyond-detecting-trails").cases}
    odo = {c["case"]: c for c in load_sweep("blazing-drift").cases}
    assert sorted(ours) == ["x0", "x0-nosync", "x1", "x1-nosync", "x4", "x4-nosync"]
    for lab, case in ours.items():
        k = lab.removesuffix("-nosync")
        drift = {key: v for key, v in case.items() if key.endswith("heading_drift_deg_per_min")}
        assert drift == {key: v for key, v in odo[k].items() if key.endswith("heading_drift_deg_per_min")}
        assert len(drift) == 4
        off = [case.get(f"robots.{i}.params.collaborate") for i in range(4)]
        assert off == ([False] * 4 if lab.endswith("-nosync") else [None] * 4)
