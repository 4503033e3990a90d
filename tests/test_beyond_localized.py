"""Beyond the papers, combination 1: ``localized-v1`` (MCL pose under any brain) and the beyond section's claim."""

from __future__ import annotations

import numpy as np
import pytest

from _report_fakes import FakeFullContext
from teamnav.papers.beyond.brains.localized import Localized, LocalizedParams, _child_rng
from teamnav.control.check import check_brain
from teamnav.experiments import runner


def test_the_filter_stream_leaves_the_inner_brains_stream_alone():
    rng = np.random.default_rng(7)
    child = _child_rng(rng)
    assert rng.random() == np.random.default_rng(7).random()  # spawning drew nothing from it
    assert child.random() != np.random.default_rng(7).random()


def test_bad_parameters_are_named():
    with pytest.raises(ValueError, match="brain: expected the brain to localize"):
        LocalizedParams(brain="localized-v1")
    with pytest.raises(ValueError, match="particles"):
        LocalizedParams(particles=1)


def test_needs_a_map_and_passes_the_brain_check():
    from teamnav.control.protocol import RobotInfo

    info = RobotInfo(robot_id=0, team_size=1, radius_m=0.25, kinematics="unicycle", max_v_mps=0.5,
                     max_omega_radps=1.0, step_length_m=0.0, dt_s=0.1)
    with pytest.raises(ValueError, match="give_map: true"):
        Localized(LocalizedParams(), np.random.default_rng(0), info)
    check_brain("localized-v1", n_steps=30)


def test_an_unknown_inner_brain_gets_a_hint(tmp_path):
    scn = runner.load_scenario("beyond-localized-trails", duration_s=1.0,
                               overrides={"robots.0.params": {"brain": "blazing-trail-v2"}})
    with pytest.raises(Exception, match="blazing-trail-v1"):
        runner.run(scn, out_dir=tmp_path / "r", progress=False)


def test_localized_pose_stays_on_the_truth_while_odometry_drifts(tmp_path):
    """Under 16 deg/min of heading drift (k = 8 for Fly) odometry is metres off after 2 min; the
    filter's samples stay within decimetres of the true position (the localization metric reads
    the brain's logged samples against the recorder's truth; the brain never sees it)."""
    ov = {f"robots.{i}.odometry.heading_drift_deg_per_min": 8.0 * r for i, r in enumerate([-1.0, 1.0, 2.0, 0.35])}
    res = runner.run(runner.load_scenario("beyond-localized-trails", duration_s=120.0, overrides=ov),
                     out_dir=tmp_path / "r", progress=False)
    m = res.metrics
    assert m["loc_mean_error_m"] < 0.3 and m["loc_final_error_m"] < 0.3
    data = np.load(tmp_path / "r" / "trajectories.npz")
    odo_err = np.hypot(*(data["odom_pose"][-1, :, :2] - data["true_pose"][-1, :, :2]).T)
    assert odo_err.max() > 1.0  # the drift is real: odometry alone would lay crumbs metres off


def test_beyond_claim_values_and_verdict():
    from teamnav.experiments.claims import judge, load_claims
    from teamnav.papers.beyond.report.section import localized_values

    def rows(*units):
        return [{"units_total": u} for u in units]

    claim = load_claims("beyond")["localized-trails-drift"]
    vals = localized_values({0.0: rows(20, 22), 4.0: rows(19, 21)}, {4.0: rows(8, 10)}, 3600.0)
    assert vals == {"units_k0_localized_mean": 21.0, "units_k4_localized_mean": 20.0, "units_k4_odometry_mean": 9.0}
    assert judge(claim, vals, 3600.0)[0] is True
    worse = localized_values({0.0: rows(20, 22), 4.0: rows(15, 16)}, {4.0: rows(8, 10)}, 3600.0)
    assert judge(claim, worse, 3600.0)[0] is False  # 15.5 < 0.9 x 21
    assert judge(claim, vals, 300.0)[0] is None  # 5-min runs are not judged


def test_cheapest_particle_count_without_breakdown():
    from teamnav.papers.beyond.report.section import cheapest_without_breakdown, particle_count

    def row(n, censored):
        return {"params": {"case": f"p{n}"}, "breakdown_censored": censored}

    rows = [row(25, 0), row(25, 1), row(50, 1), row(50, 1), row(100, 1), row(500, 0)]
    assert particle_count(rows[0]) == 25 and particle_count({"params": {"case": "x4"}}) is None
    assert cheapest_without_breakdown(rows) == 50
    assert cheapest_without_breakdown([row(25, 0), row(50, 0)]) is None


def test_paired_gain_says_when_there_is_no_difference():
    from teamnav.papers.beyond.report.section import paired_gain_text

    ours = [{"seed": s, "units_total": u} for s, u in enumerate([10, 12, 11, 13])]
    same = [{"seed": s, "units_total": u} for s, u in enumerate([11, 11, 12, 12])]
    worse = [{"seed": s, "units_total": u} for s, u in enumerate([5, 6, 5, 7])]
    assert "no difference beyond the seeds' spread" in paired_gain_text(ours, same, 3600.0)
    text = paired_gain_text(ours, worse, 1800.0)  # units per hour: twice the units of a 30-min run
    assert text.startswith("+11.5 ± ") and "delivers more" in text and "4 paired seeds" in text
    assert paired_gain_text(ours[:1], same, 3600.0) == "too few paired seeds to compare"


def _fake_full():
    """Full mode without running: each asked sweep gets one row per case and seed; the
    localized team keeps 68 units/h at every k, the odometric ones lose 8 per unit of k."""

    def rows_for(spec, seeds):
        local = spec.sweep_name.startswith("beyond-")

        def units(case):
            k = float(case[1:]) if case.startswith("x") else 4.0
            return 68 if local else 68 - 8 * k

        return [{"status": "ok", "seed": s, "params": {"case": c["case"]}, "units_total": units(c["case"]) + s % 2,
                 "breakdown_censored": 1, "loc_mean_error_m": 0.07 if local else None, "wall_time_s": 20.0}
                for c in spec.cases for s in seeds]

    return FakeFullContext(rows_for)


def test_full_mode_draws_the_parts_the_particle_counts_and_the_verdict():
    from teamnav.experiments.report.model import Comparison, Table
    from teamnav.papers.beyond.report.section import _localized_trails

    ctx = _fake_full()
    blocks = _localized_trails(ctx)
    assert [a[0] for a in ctx.asked] == ["beyond-localized-trails", "blazing-drift", "try-drift", "beyond-localized-particles"]
    main, parts = [b for b in blocks if isinstance(b, Table)]
    assert [r[0] for r in main.rows] == ["0", "0", "0", "1", "1", "1", "4", "4", "4"]
    assert [r[0] for r in parts.rows] == ["25", "50", "100", "200", "500"]
    assert "cheapest count with no breakdown in any run: 25" in parts.note and "odometric blazing team at k = 4" in parts.note
    (cmp,) = [b for b in blocks if isinstance(b, Comparison)]
    assert cmp.holds is True and "no difference beyond the seeds' spread" in cmp.differs  # k = 0: equal units
