"""MCL (Fox et al. §3.1): motion model, beam model, likelihood field, resampling, KLD, tracking
and global localization. The test plays the simulator: it scripts a path, ray-casts the scans
with the world ray caster and hands the filter only noisy odometry steps and ranges."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy import integrate

from teamnav.control.protocol import SensorInfo
from teamnav.geometry.angles import wrap_angle
from teamnav.localization import MCL, BeamModelParams, KLDParams, MCLParams, MotionParams, pose_error, sample_error_m
from teamnav.localization.beam_model import (
    BeamTable, beam_density, beam_log_likelihood_reference, beam_log_table, beam_loglik_kernel, beam_probability,
)
from teamnav.localization.likelihood_field import lf_log_likelihood_reference
from teamnav.localization.motion import motion_kernel, sample_motion, sample_motion_reference
from teamnav.localization.resample import low_variance_indices, low_variance_kernel, low_variance_reference
from teamnav.world import MapBuilder, load_map
from teamnav.world.grid import OccupancyGrid
from teamnav.world.distance import distance_field
from teamnav.world.raycast import RayCaster

MIT = Path(__file__).resolve().parents[1] / "src/teamnav/world/maps/mit/basement_hallways_5cm.yaml"
LASER_SEES = ("wall", "unknown", "foam")


# ---------------------------------------------------------------------------- the test's "simulator"
def scripted_path(caster, start, n_steps, rng, step_m=0.15):
    """Forward ``step_m`` per step with a little heading jitter; turn in place when blocked ahead."""
    front = np.radians(np.linspace(-30, 30, 7))
    poses = [np.asarray(start, dtype=float)]
    for _ in range(n_steps):
        p = poses[-1]
        if caster.cast(p[None], front)[0].min() < 0.8:
            q = p + [0.0, 0.0, 0.4]
        else:
            q = p + [step_m * math.cos(p[2]), step_m * math.sin(p[2]), rng.normal(0.0, 0.05)]
        q[2] = wrap_angle(q[2])
        poses.append(q)
    return np.array(poses)


def noisy_odometry(poses, rng, alpha):
    """Odometry steps (previous body frame) of a path, corrupted by Table 5.6 with ``alpha``."""
    out = []
    for a, b in zip(poses[:-1], poses[1:]):
        c, s = math.cos(a[2]), math.sin(a[2])
        dx, dy = b[0] - a[0], b[1] - a[1]
        d = np.array([c * dx + s * dy, -s * dx + c * dy, wrap_angle(b[2] - a[2])])
        out.append(sample_motion_reference(np.zeros((1, 3)), d, alpha, rng.standard_normal((1, 3)))[0])
    return np.array(out)


@pytest.fixture(scope="module")
def mit():
    return load_map(MIT)


# ---------------------------------------------------------------------------- motion model
def test_motion_sample_mean_and_spread_match_table_5_6():
    rng = np.random.default_rng(0)
    a = (0.02, 0.03, 0.04, 0.01)
    n = 200_000
    p = np.zeros((n, 3))
    sample_motion(p, [1.0, 0.0, 0.0], MotionParams(alpha=a), rng)  # pure translation of 1 m
    # rot1 = rot2 = 0: std(rot) = sqrt(a2), std(trans) = sqrt(a3)
    assert abs(p[:, 0].mean() - math.exp(-a[1] / 2)) < 3e-3  # E[t cos(rot1)] = E[cos rot1]
    assert abs(np.std(p[:, 2]) - math.sqrt(2 * a[1])) < 5e-3  # theta = rot1 + rot2
    # x = t cos(rot1): spread dominated by the translation noise
    assert abs(np.std(p[:, 0]) - math.sqrt(a[2])) < 0.01
    assert abs(np.std(p[:, 1]) - math.sqrt(a[1])) < 0.01  # y = t sin(rot1) ~ rot1
    q = np.zeros((n, 3))
    sample_motion(q, [0.0, 0.0, 0.5], MotionParams(alpha=a), rng)  # pure rotation
    assert abs(q[:, 2].mean() - 0.5) < 2e-3
    assert abs(np.std(q[:, 2]) - math.sqrt(a[0]) * 0.5) < 3e-3
    assert abs(np.std(q[:, 0]) - math.sqrt(a[3]) * 0.5) < 3e-3  # translation noise from rotation


def test_motion_kernel_matches_reference_and_reverses():
    rng = np.random.default_rng(1)
    p = rng.normal(size=(500, 3))
    p[:, 2] = wrap_angle(p[:, 2])
    noise = rng.standard_normal((500, 3))
    for delta in ([0.3, 0.1, 0.2], [-0.4, 0.05, -0.1], [0.0, 0.0, 3.0]):
        ref = sample_motion_reference(p, delta, (0.1, 0.2, 0.3, 0.4), noise)
        got = p.copy()
        motion_kernel(got, *delta, np.array([0.1, 0.2, 0.3, 0.4]), noise)
        assert_allclose(got, ref, atol=1e-12)
    q = np.zeros((1, 3))
    motion_kernel(q, -1.0, 0.0, 0.0, np.zeros(4), np.zeros((1, 3)))
    assert_allclose(q, [[-1.0, 0.0, 0.0]], atol=1e-12)  # reversing keeps the heading


def test_motion_params_are_bounded():
    with pytest.raises(ValueError, match="alpha"):
        MotionParams(alpha=(0.1, -0.1, 0.0, 0.0))
    with pytest.raises(ValueError, match="extra"):
        MCLParams(n_particle=10)


# ---------------------------------------------------------------------------- beam model
@pytest.mark.parametrize("z_exp", [0.5, 3.0, 9.97])
def test_beam_mixture_integrates_to_one(z_exp):
    p = BeamModelParams(z_hit=0.7, z_short=0.15, z_max=0.05, z_rand=0.1, sigma_hit_m=0.1, lambda_short_per_m=0.8)
    f = lambda z: float(beam_density(z, z_exp, p, 10.0))  # noqa: E731
    pts = [z_exp - 0.5, z_exp, z_exp + 0.5]
    cont, _ = integrate.quad(f, 0.0, 10.0, points=[v for v in pts if 0 < v < 10], limit=400)
    assert abs(cont + p.z_max - 1.0) < 1e-3
    # a max-range reading carries the point mass
    assert beam_probability(10.0, z_exp, p, 10.0) >= p.z_max


def test_beam_params_must_sum_to_one():
    with pytest.raises(ValueError, match="must be 1"):
        BeamModelParams(z_hit=0.5, z_short=0.1, z_max=0.05, z_rand=0.05)
    with pytest.raises(ValueError):
        BeamModelParams(z_hit=0.95, z_short=0.05, z_max=0.0, z_rand=0.0)  # z_rand must be > 0


def test_tabulated_beam_kernel_matches_exact_mixture():
    rng = np.random.default_rng(2)
    params = BeamModelParams(z_hit=0.85, z_short=0.0, z_max=0.05, z_rand=0.1, sigma_hit_m=0.1)
    expected = rng.uniform(0.0, 10.0, (300, 20))
    measured = np.r_[rng.uniform(0.1, 9.9, 18), 10.0, 10.0]
    ref = beam_log_likelihood_reference(expected, measured, params, 10.0)
    table, step = beam_log_table(measured, params, 10.0)
    assert_allclose(BeamTable(params, 10.0)(measured), table, rtol=1e-9, atol=1e-9)  # compiled table
    got = beam_loglik_kernel(expected, 1, table, 1.0 / step, 1.0, np.empty(300))
    assert_allclose(got, ref, atol=20 * step**2 / (8 * 0.1**2) + 1e-9)
    # a sonar cone: expected distance is the minimum over its rays
    rays = np.repeat(expected, 3, axis=1)
    rays[:, 1::3] += 1.0
    got3 = beam_loglik_kernel(rays, 3, table, 1.0 / step, 1.0, np.empty(300))
    assert_allclose(got3, got, atol=1e-12)


def test_likelihood_field_kernel_matches_reference(mit):
    s = SensorInfo("laser", "laser", np.linspace(-np.pi / 2, np.pi / 2, 30), 10.0)
    f = MCL(MCLParams(n_particles=400, sensor_model="likelihood_field"), mit, s, np.random.default_rng(3))
    f.init_global()
    z = np.random.default_rng(4).uniform(0.2, 10.0, 30)
    z[3] = 10.0
    got = f.log_likelihood(z).copy()
    ref = lf_log_likelihood_reference(f.particles, z, s.angles_rad, f._lf_table, f._lf_free, mit.origin_xy_m,
                                      mit.resolution_m, f._lf_outside, f._lf_worst, 10.0)
    assert_allclose(got, ref, rtol=1e-6, atol=1e-5)


# ---------------------------------------------------------------------------- resampling
def test_low_variance_matches_reference_and_is_proportional():
    rng = np.random.default_rng(5)
    w = rng.random(1000) ** 4
    for r in (0.0, 0.37, 0.999):
        assert_allclose(low_variance_kernel(w, 777, r, np.empty(777, np.int64)), low_variance_reference(w, 777, r))
    idx = low_variance_indices(w, 10_000, rng)
    counts = np.bincount(idx, minlength=1000)
    assert np.all(np.abs(counts - 10_000 * w / w.sum()) <= 1.0 + 1e-9)
    with pytest.raises(ValueError, match="weights"):
        low_variance_indices(np.zeros(3), 2, rng)


# ---------------------------------------------------------------------------- tracking on the MIT map
@pytest.mark.parametrize("model", ["beam", "likelihood_field"])
def test_tracks_a_robot_on_the_mit_map(mit, model):
    rng = np.random.default_rng(10)
    caster = RayCaster(mit, LASER_SEES, 10.0)
    clear = np.argwhere(distance_field(mit) > 0.8)
    r, c = clear[rng.integers(len(clear))]
    start = np.array([(c + 0.5) * mit.resolution_m + mit.origin_xy_m[0], (r + 0.5) * mit.resolution_m + mit.origin_xy_m[1], 0.3])
    poses = scripted_path(caster, start, 50, rng)
    deltas = noisy_odometry(poses, rng, (0.01, 0.01, 0.01, 0.01))
    angles = np.linspace(-np.pi / 2, np.pi / 2, 60)
    scans = np.clip(caster.cast(poses, angles) + rng.normal(0, 0.02, (len(poses), 60)), 0.0, 10.0)
    sensor = SensorInfo("laser", "laser", angles, 10.0, 0.02)
    f = MCL(MCLParams(n_particles=500, sensor_model=model, beam_stride=2), mit, sensor, np.random.default_rng(11))
    f.init_pose(start + [0.2, -0.1, 0.05], np.diag([0.1, 0.1, 0.02]))
    errs = []
    for k in range(len(deltas)):
        f.step(deltas[k], scans[k + 1])
        errs.append(pose_error(f.estimate().pose, poses[k + 1]))
    errs = np.array(errs)
    # the bound: 0.25 m and 0.1 rad at every step after the first ten, 0.1 m at the end
    assert errs[10:, 0].max() < 0.25 and errs[10:, 1].max() < 0.1, errs.max(axis=0)
    assert errs[-1, 0] < 0.1
    assert sample_error_m(f.particles, f.weights, poses[-1]) < 0.3


# ---------------------------------------------------------------------------- global localization
def asymmetric_room():
    """8 m x 5 m room with a pillar, a box and a notch placed without symmetry."""
    b = MapBuilder(8.0, 5.0, 0.05).border(0.2)
    b.rect(2.0, 3.2, 2.6, 3.8)
    b.rect(5.2, 0.2, 6.6, 1.3)
    b.rect(7.0, 3.0, 7.8, 4.8)
    b.disc(4.0, 2.0, 0.25)
    return b.build("asymmetric-room")


def test_global_localization_converges_on_an_asymmetric_map():
    g = asymmetric_room()
    rng = np.random.default_rng(20)
    caster = RayCaster(g, LASER_SEES, 8.0)
    start = np.array([1.0, 1.0, 0.2])
    poses = scripted_path(caster, start, 25, rng, step_m=0.12)
    deltas = noisy_odometry(poses, rng, (0.01, 0.01, 0.01, 0.01))
    angles = np.linspace(-np.pi, np.pi, 61)[:-1]
    scans = np.clip(caster.cast(poses, angles) + rng.normal(0, 0.02, (len(poses), 60)), 0.0, 8.0)
    sensor = SensorInfo("laser", "laser", angles, 8.0, 0.02)
    params = MCLParams(n_particles=4000, beam_stride=3, likelihood_exponent=0.5, init_clearance_m=0.15,
                       beam=BeamModelParams(sigma_hit_m=0.1))
    f = MCL(params, g, sensor, np.random.default_rng(21))
    f.init_global()
    first = sample_error_m(f.particles, f.weights, poses[0])
    for k in range(len(deltas)):
        f.step(deltas[k], scans[k + 1])
    est = f.estimate()
    assert first > 1.0
    assert pose_error(est.cluster_pose, poses[-1])[0] < 0.3
    assert pose_error(est.cluster_pose, poses[-1])[1] < 0.2
    assert est.cluster_weight > 0.8


def test_kld_uses_many_samples_when_lost_and_few_when_tracking():
    g = asymmetric_room()
    s = SensorInfo("laser", "laser", np.linspace(-np.pi, np.pi, 37)[:-1], 8.0)
    params = MCLParams(adaptive=True, n_particles=500, kld=KLDParams(min_particles=50, max_particles=20_000))
    f = MCL(params, g, s, np.random.default_rng(30))
    f.init_global()
    f.resample()
    lost = f.n_particles
    f.init_pose([2.0, 2.0, 0.0], np.diag([0.01, 0.01, 0.001]))
    f.resample()
    tracking = f.n_particles
    assert lost > 5 * tracking and tracking >= 50, (lost, tracking)


def test_augmented_recovery_injects_samples_when_the_likelihood_drops():
    g = asymmetric_room()
    caster = RayCaster(g, LASER_SEES, 8.0)
    angles = np.linspace(-np.pi, np.pi, 37)[:-1]
    s = SensorInfo("laser", "laser", angles, 8.0)
    f = MCL(MCLParams(n_particles=300, recovery="augmented"), g, s, np.random.default_rng(31))
    here = np.array([2.0, 2.0, 0.0])
    f.init_pose(here, np.diag([1e-4, 1e-4, 1e-4]))
    for _ in range(5):
        f.step([0.0, 0.0, 0.0], caster.cast(here[None], angles)[0])
    assert f.random_sample_probability() == 0.0
    kidnapped = caster.cast(np.array([[6.0, 3.5, 2.0]]), angles)[0]
    for _ in range(30):  # w_fast decays by (1 - alpha_fast) a step in the linear domain
        f.step([0.0, 0.0, 0.0], kidnapped)
    assert f.random_sample_probability() > 0.1


def test_sonar_cones_and_bad_input():
    g = asymmetric_room()
    s = SensorInfo("sonar", "sonar", np.linspace(-np.pi, np.pi, 17)[:-1], 5.0)
    f = MCL(MCLParams(n_particles=50, sonar_rays_per_cone=4), g, s, np.random.default_rng(40))
    assert f._ray_angles.shape == (64,)
    with pytest.raises(ValueError, match="init_global"):
        f.predict([0.1, 0.0, 0.0])
    f.init_global()
    with pytest.raises(ValueError, match=r"scan_ranges must have shape \(16,\)"):
        f.update(np.ones(15))
    with pytest.raises(ValueError, match="odom_delta must hold finite"):
        f.predict([np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="factors must be >= 0"):
        f.multiply_weights(-np.ones(f.n_particles))
    assert not f.multiply_weights(np.zeros(f.n_particles))  # contradicting evidence is ignored
    with pytest.raises(ValueError, match="sensor.kind"):
        MCL(MCLParams(), g, SensorInfo("x", "radar", np.zeros(3), 5.0), np.random.default_rng(0))


# ---------------------------------------------------------------------------- serial twins
def test_serial_twins_agree_and_have_their_own_cache():
    """numba's on-disk cache keys an entry by bytecode + signature, not by ``parallel``: a serial
    twin built as ``njit(kernel.py_func)`` shared the threaded kernel's cache file and loaded its
    code (1k particles paid a thread launch per call, 20 ms instead of 5 on busy cores)."""
    from teamnav.localization import beam_model, likelihood_field, motion

    pairs = [(motion.motion_kernel, motion.motion_kernel_serial),
             (beam_model.beam_loglik_kernel, beam_model.beam_loglik_kernel_serial),
             (likelihood_field.lf_loglik_kernel, likelihood_field.lf_loglik_kernel_serial)]
    for par, ser in pairs:
        assert ser.py_func.__code__ is not par.py_func.__code__
        assert ser.targetoptions.get("parallel") in (None, False) and par.targetoptions["parallel"]
        assert ser._cache._cache_file._index_name != par._cache._cache_file._index_name
    rng = np.random.default_rng(7)
    p = rng.normal(size=(300, 3))
    noise = rng.standard_normal((300, 3))
    a, b = p.copy(), p.copy()
    motion.motion_kernel(a, 0.2, 0.05, 0.1, np.full(4, 0.1), noise)
    motion.motion_kernel_serial(b, 0.2, 0.05, 0.1, np.full(4, 0.1), noise)
    assert_allclose(a, b, atol=0)
    rays = rng.uniform(0.0, 10.0, (300, 40))
    table, step = beam_log_table(rng.uniform(0.1, 10.0, 20), BeamModelParams(), 10.0)
    assert_allclose(beam_model.beam_loglik_kernel_serial(rays, 2, table, 1 / step, 0.5, np.empty(300)),
                    beam_loglik_kernel(rays, 2, table, 1 / step, 0.5, np.empty(300)), atol=0)


# ---------------------------------------------------------------------------- estimate
def _reference_estimate(p, w, cell):
    """The NumPy + ``scipy.ndimage.label`` estimate the compiled one replaced."""
    from scipy import ndimage

    def wpose(q, v):
        s = v.sum()
        m = np.array([np.dot(v, q[:, 0]) / s, np.dot(v, q[:, 1]) / s,
                      math.atan2(np.dot(v, np.sin(q[:, 2])), np.dot(v, np.cos(q[:, 2])))])
        d = np.stack([q[:, 0] - m[0], q[:, 1] - m[1], wrap_angle(q[:, 2] - m[2])], axis=1)
        return m, (d * (v / s)[:, None]).T @ d

    mean, cov = wpose(p, w)
    ix = ((p[:, 0] - p[:, 0].min()) / cell).astype(np.int64)
    iy = ((p[:, 1] - p[:, 1].min()) / cell).astype(np.int64)
    occ = np.zeros((iy.max() + 1, ix.max() + 1), dtype=bool)
    occ[iy, ix] = True
    labels, k = ndimage.label(occ, structure=np.ones((3, 3), dtype=bool))
    lab = labels[iy, ix]
    cw = np.bincount(lab, weights=w, minlength=k + 1)
    best = int(np.argmax(cw))
    cmean, _ = wpose(p[lab == best], w[lab == best])
    return mean, cov, cmean, cw[best], k


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), k=st.integers(1, 6), n=st.integers(1, 1500),
       cell=st.sampled_from([0.2, 0.5, 1.0]), equal=st.booleans())
def test_estimate_matches_ndimage_clusters(seed, k, n, cell, equal):
    rng = np.random.default_rng(seed)
    g = OccupancyGrid.empty(40.0, 30.0, 0.1)
    f = MCL(MCLParams(n_particles=n, cluster_cell_m=cell), g, SensorInfo("laser", "laser", np.zeros(1), 5.0),
            np.random.default_rng(0))
    centres = rng.uniform(2, 38, (k, 2))
    xy = centres[rng.integers(0, k, n)] + rng.normal(0, rng.uniform(0.05, 2.0), (n, 2))
    f._particles = np.ascontiguousarray(np.c_[xy, wrap_angle(rng.normal(3.0, rng.uniform(0.1, 3.0), n))])
    w = np.full(n, 1.0 / n) if equal else rng.random(n) ** 3 + 1e-9  # equal weights: ties break as ndimage's
    f._weights = w / w.sum()
    est = f.estimate()
    mean, cov, cmean, cw, nc = _reference_estimate(f._particles, f._weights, cell)
    assert est.n_clusters == nc
    assert est.cluster_weight == pytest.approx(cw, abs=1e-12)
    assert_allclose(est.pose, mean, atol=1e-9)
    assert_allclose(est.cov, cov, atol=1e-9)
    assert_allclose(est.cluster_pose, cmean, atol=1e-9)
