"""The paper column's fills and set-up (Fox, Burgard, Kruppa & Thrun; FIDELITY §1):

- the beam model's fill criterion (:mod:`teamnav.papers.collab_mcl.beam_fill`) on a small map;
- the likelihood-based sample count of Fox et al. (1999a): a lost robot's set grows;
- the modes and heaviest-mode measures the precondition and the hexagon counts use.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.localization import BeamModelParams, KLDParams, MCL, MCLParams
from teamnav.papers.collab_mcl.beam_fill import Criterion, FillCase, choose
from teamnav.papers.collab_mcl.metrics import belief_modes, heaviest_mode
from teamnav.sim.config import LaserConfig
from teamnav.sim.sensors.range_sensors import build_range_sensor
from teamnav.world.map_builder import MapBuilder

BEAM = BeamModelParams(z_hit=0.7, z_short=0.1, z_max=0.1, z_rand=0.1, sigma_hit_m=0.2)


def _room():
    """A 6 m x 4 m room with an off-centre box: no symmetry, so one scan can localize."""
    b = MapBuilder(6.0, 4.0, 0.1).fill("wall").clear_rect(0.2, 0.2, 5.8, 3.8)
    b.rect(4.0, 2.6, 5.0, 3.8)
    return b.build("room")


def test_fill_criterion_sees_a_sample_set_too_small_for_a_sharp_model():
    """The criterion's two halves on a small case: the grid posterior of a sharp model puts most of
    its mass near the true pose in an asymmetric room; 30 uniform samples cannot represent it (the
    gap |m_s - m_g| is large) while 20000 can for a broad model (the gap is small)."""
    g = _room()
    sensor = build_range_sensor(LaserConfig(n_beams=180, fov_deg=179, max_range_m=8.0, noise_std_m=0.05), g)
    pose = (1.5, 1.2, 0.3)
    few = Criterion(g, sensor, BEAM, [0.1, 1.6], [1, 9], n_samples=30)
    c = few.case(1000, pose=pose)
    assert c.m_g[0, 1] > 0.6  # sigma 0.1, 20 beams: the grid finds the pose
    assert abs(c.m_s[0, 1] - c.m_g[0, 1]) > 0.3  # 30 samples miss it
    many = Criterion(g, sensor, BEAM, [0.1, 1.6], [1, 9], n_samples=20000)
    c2 = many.case(1000, pose=pose)
    assert abs(c2.m_s[1, 1] - c2.m_g[1, 1]) < 0.1  # a broad model is represented by many samples
    # the rule picks a setting whose samples match the grid
    r = choose([c2], [0.1, 1.6], [1, 9], 180)
    assert r["mean_gap"] <= 0.1


@settings(max_examples=15, deadline=None)
@given(st.floats(0.5, 5.5), st.floats(0.5, 3.5), st.floats(-math.pi, math.pi), st.sampled_from([1, 2, 4]),
       st.sampled_from([0.1, 0.5, 2.0]))
def test_the_sonar_criterion_scores_a_pose_as_the_filter_does(x, y, th, stride, sigma):
    """Rule 8's criterion must weigh a pose by the filter's own sonar likelihood: each cone's
    expected range is the minimum over the rays the filter casts across it, and every
    ``stride``-th transducer is multiplied (Fox §5.2, ``localization.mcl``)."""
    from teamnav.localization.beam_model import BeamTable
    from teamnav.papers.collab_mcl.beam_fill import _ranges, _stride_sums
    from teamnav.sim.config import SonarConfig

    g = _room()
    sensor = build_range_sensor(SonarConfig(n_transducers=16, cone_deg=15, rays_per_cone=5, max_range_m=5.0,
                                            noise_std_m=0.05), g)
    crit = Criterion(g, sensor, BEAM, [sigma], [stride], n_samples=10, cone_deg=15.0, rays_per_cone=3)
    scan = np.minimum(sensor.sense(np.array([3.0]), np.array([1.0]), np.array([0.4]), np.random.default_rng(5))[0],
                      sensor.max_range_m)
    pose = np.array([[x, y, th]])
    beam = BEAM.model_copy(update={"sigma_hit_m": sigma})
    bt = BeamTable(beam.model_copy(update={"table_step_m": None}), sensor.max_range_m)
    ours = _stride_sums(_ranges(crit.caster, pose, crit.angles, offsets=crit.offsets), bt(scan), 1.0 / bt.step_m,
                        np.array([stride]), np.empty((1, 1)))[0, 0]
    p = MCLParams(n_particles=10, beam=beam, beam_stride=stride, sonar_cone_deg=15.0, sonar_rays_per_cone=3,
                  adaptive=False, recovery="none", parallel=False)
    mcl = MCL(p, g, sensor.info(), np.random.default_rng(0))
    mcl.init_global()
    theirs = mcl.pose_log_likelihood(pose, scan)[0]
    assert ours == pytest.approx(theirs, rel=1e-3, abs=1e-3)  # ranges kept as float32 by the criterion


def test_choose_prefers_fewer_beams_on_a_tie_and_rejects_a_grid_without_admissible_settings():
    a = FillCase(1000, (0, 0, 0), np.array([[0.50, 0.505, 0.2]]), np.array([[0.5, 0.5, 0.2]]))
    r = choose([a], [0.2], [1, 2, 4], 180)
    assert r["beam_stride"] == 2  # 0.505 vs 0.50: a tie within 0.01, 90 beams beat 180
    bad = FillCase(1000, (0, 0, 0), np.array([[0.0, 0.0]]), np.array([[0.5, 0.5]]))
    with pytest.raises(ValueError, match="no setting has a mean"):
        choose([bad], [0.2], [1, 2], 180)


def _filter(g, sensor, seed=0):
    p = MCLParams(n_particles=300, beam=BEAM, beam_stride=9, adaptive=True, adapt="likelihood",
                  likelihood_ref_per_beam=-0.2, recovery="none",
                  kld=KLDParams(min_particles=300, max_particles=20000), parallel=False)
    return MCL(p, g, sensor.info(), np.random.default_rng(seed))


def test_a_lost_robots_sample_set_grows_and_a_tracking_one_stays_small():
    """Fox et al. 1999a (cited in §3.1): "many samples ... if the position of the robot is lost"."""
    g = _room()
    sensor = build_range_sensor(LaserConfig(n_beams=180, fov_deg=179, max_range_m=8.0, noise_std_m=0.05), g)
    truth = np.array([1.5, 1.2, 0.3])
    rng = np.random.default_rng(3)
    scan = lambda: sensor.sense(truth[:1], truth[1:2], truth[2:3], rng)[0]  # noqa: E731
    cov = np.diag([0.05 ** 2, 0.05 ** 2, math.radians(2) ** 2])
    tracking, lost = _filter(g, sensor), _filter(g, sensor, 1)
    tracking.init_pose(truth, cov)
    lost.init_pose([4.5, 1.0, 2.5], cov)  # kidnapped: all its samples are elsewhere
    n_track, n_lost = [], []
    for _ in range(3):
        for f, ns in ((tracking, n_track), (lost, n_lost)):
            f.update(scan())
            f.resample()
            ns.append(f.particles.shape[0])
    assert n_lost[-1] >= 10 * n_track[-1]
    assert n_lost[-1] == 20000  # the cap
    assert n_track[-1] < 1500


def test_likelihood_adaptation_needs_its_reference():
    with pytest.raises(ValueError, match="likelihood_ref_per_beam"):
        MCLParams(adaptive=True, adapt="likelihood")


def test_modes_and_heaviest_mode_count_what_they_say():
    rng = np.random.default_rng(0)
    three = np.vstack([rng.normal(c, 0.2, (20, 2)) for c in ((0, 0), (5, 0), (0, 5))])
    assert belief_modes(three) == 3
    assert heaviest_mode(three) == pytest.approx(1 / 3, abs=0.02)
    one = rng.normal(0, 0.2, (64, 2))
    assert belief_modes(one) == 1 and heaviest_mode(one) == 1.0


@pytest.mark.parametrize("pose", [(12.0, 9.0, 2.5), (5.0, 10.0, -0.5)])
def test_hexagon_sonar_robots_cannot_tell_three_locations_apart_laser_robots_two(pose):
    """Fox §5.2.2: "robots using sonar sensors ... cannot distinguish between three possible robot
    locations ..., robots equipped with laser range-finders remain uncertain about two". The
    filter's own likelihood of a noise-free scan at the six turns of the pose about the hexagon's
    centre: as likely as the truth (within 1 nat) at three turns for a sonar robot, two for a laser
    robot (the paper column's models, the fills of rules 1 and 8: sonar 16 cones, sigma 0.8 m; laser 10
    beams, 0.8 m)."""
    from teamnav.sim.config import SonarConfig
    from teamnav.world.generators import builtin_map

    env = builtin_map("hexagon")
    g = env.grid
    cx, cy = env.places["centre"]
    x, y, th = pose
    turns = np.array([[cx + (x - cx) * math.cos(a) - (y - cy) * math.sin(a),
                       cy + (x - cx) * math.sin(a) + (y - cy) * math.cos(a), th + a]
                      for a in np.arange(6) * math.pi / 3])
    kinds = {
        "sonar": (SonarConfig(n_transducers=16, fov_deg=360, cone_deg=15, rays_per_cone=5, max_range_m=5.0,
                              noise_std_m=0.05, p_specular=0.0), BEAM.model_copy(update={"sigma_hit_m": 0.8}), 1, 3),
        "laser": (LaserConfig(n_beams=180, fov_deg=179, max_range_m=8.0, noise_std_m=0.05),
                  BEAM.model_copy(update={"sigma_hit_m": 0.8}), 18, 2),
    }
    for kind, (cfg, beam, stride, expect) in kinds.items():
        s = build_range_sensor(cfg, g)
        f = MCL(MCLParams(beam=beam, beam_stride=stride, parallel=False), g, s.info(), np.random.default_rng(0))
        z = s.true_ranges(np.array([x]), np.array([y]), np.array([th]))[0]
        ll = f.pose_log_likelihood(turns, z)
        assert int((ll >= ll[0] - 1.0).sum()) == expect, (kind, np.round(ll - ll[0], 1))


# ---------------------------------------------------------------------------- the section's fidelity blocks
def test_ledger_has_both_columns_with_a_source_and_a_ref_for_the_fills():
    from teamnav.experiments.report.model import LEDGER_SOURCES
    from teamnav.papers.collab_mcl.report._collab_fidelity import ledger_blocks

    paper, teamnav = ledger_blocks()
    assert {r.column for r in paper.rows} == {"paper"} and {r.column for r in teamnav.rows} == {"teamnav"}
    rows = {r.name: r for r in paper.rows}
    # the fills the 2026-11-29 rules chose, with their rule and tuning seeds
    stride = rows["collab-mcl-detection / robin: beam_stride"]
    assert stride.value == 18 and stride.source == "fill" and "1000-1009" in stride.ref
    assert rows["collab-mcl-hexagon / laser: beam.sigma_hit_m"].value == 0.8
    assert rows["collab-mcl-hallway / sonar: adapt_ref_loglik_per_beam"].source == "fill"
    # the paper's rules, stated, and the hardware the paper gives
    assert rows["collab-mcl-hallway / sonar: adapt"].value == "likelihood"
    assert rows["collab-mcl-hallway / sonar: likelihood_exponent"].source == "stated"
    assert rows["collab-mcl-detection / robin: laser"].source == "stated" and '"n_beams": 180' in \
        rows["collab-mcl-detection / robin: laser"].value
    # settings the paper's rules make inert are not listed as the paper's
    assert not any(": inject_heading" in n for n in rows)
    # teamnav's in-sample choices say so
    lost = [r for r in teamnav.rows if r.name.endswith("inject_fraction")]
    assert lost and all("sensor resetting" in r.ref for r in lost)
    assert all(r.source in LEDGER_SOURCES and r.ref.strip() for r in paper.rows + teamnav.rows)


def test_a_claim_that_needs_an_unmet_precondition_reads_precondition_not_met(monkeypatch):
    from teamnav.experiments.claims import load_claims
    from teamnav.papers.collab_mcl.report import _collab_fidelity as fid

    claims = load_claims("collab-mcl")
    good = {"team_final_error_mean_m": 0.3, "alone_final_error_mean_m": 9.0, "team_localized_frac": 1.0}
    monkeypatch.setitem(fid.PRECONDITION, "holds", False)
    h, text = fid.gated_judge(claims["single-detection"], good)
    assert h is None and text.startswith("precondition not met")
    monkeypatch.setitem(fid.PRECONDITION, "holds", True)
    assert fid.gated_judge(claims["single-detection"], good)[0] is True
    # a claim that does not need it is judged as the claim file says either way
    monkeypatch.setitem(fid.PRECONDITION, "holds", False)
    monkeypatch.setitem(fid.HALLWAY_ALONE, "holds", True)
    hv = {"together_ttl_mean_s": 100.0, "alone_ttl_mean_s": 200.0, "together_final_localized": 1.0,
          "alone_final_localized": 1.0, "paired_change_upper_s": -10.0, "n_pairs": 8.0}
    assert fid.gated_judge(claims["hallway-faster"], hv)[0] is True
    block = fid.precondition_block()
    assert block.holds is False and set(block.claims) == {"single-detection", "fp-breaks"}
    assert block.record()["seeds"] == "1000-1009"
    # rule 10: hallway-faster rests on §5.2.1's single robots, hexagon-together on §5.2.2's
    monkeypatch.setitem(fid.HALLWAY_ALONE, "holds", False)
    h, text = fid.gated_judge(claims["hallway-faster"], hv)
    assert h is None and text.startswith("precondition not met (§5.2.1") and "the rule would read: " in text
    blocks = {b.claims[0]: b for b in fid.precondition_blocks()}
    assert set(blocks) == {"single-detection", "hallway-faster", "hexagon-together"}
    hexv = {"together_min_localized": 1.0, "alone_best_localized": 0.4, "together_all_runs_frac": 1.0}
    monkeypatch.setitem(fid.HEXAGON_ALONE, "holds", True)
    assert fid.gated_judge(claims["hexagon-together"], hexv)[0] is True
    monkeypatch.setitem(fid.HEXAGON_ALONE, "holds", False)
    assert fid.gated_judge(claims["hexagon-together"], hexv)[0] is None
