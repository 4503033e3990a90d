"""MCL runs stay bit for bit: the digest of the sample sets and weights of 50 filter steps is pinned.

The collaborative-MCL reproduction's numbers depend on every particle, weight and resampling
draw of its filters, so a speed-up of the filter (buffers, fused kernels, a faster ray caster)
must not move a single bit. This test replays 50 steps of a laser beam-model filter (with
augmented recovery, KLD-sampling and the estimate), of a sonar-cone filter, and of a
likelihood-field filter on the MIT basement map and compares a SHA-256 of everything the
filters hold with the digests of the implementation of 2026-11-29.

The digests are those of x86-64 Linux with numba 0.68.1 and NumPy's and LLVM's ``exp``/``log``
of that build: another libm may legitimately differ in the last bit. Regenerate them only for
such a platform change, never to make a code change pass.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest
from numba import njit

from teamnav.control.protocol import SensorInfo
from teamnav.localization import MCL, BeamModelParams, KLDParams, MCLParams
from teamnav.localization.beam_model import MAX_READING_TOL_M, BeamTable
from teamnav.world import load_map
from teamnav.world.raycast import RayCaster

MIT = Path(__file__).resolve().parents[1] / "src/teamnav/world/maps/mit/basement_hallways_5cm.yaml"
SEES = ("wall", "unknown", "foam")

#: SHA-256 of the replay of each case (see the module docstring).
DIGESTS = {
    "laser": "e098fbb6ff4499b7a5b3f9ad4dfc12dc23e2c24dbb2fb528523d0e4f52e699f3",
    "sonar": "ec8c70b74328ee459f520a871ba3c2dafebd72ef63d9478f5d6aa8418f6f276c",
    "likelihood_field": "474c9973cfec0d181825230224ceb9481c803d29e56a708d21e1f838c9255276",
}


def _replay(case: str) -> str:
    grid = load_map(MIT)
    if case == "sonar":
        angles = np.linspace(-np.pi, np.pi, 17)[:-1]
        sensor = SensorInfo("sonar", "sonar", angles, 5.0, 0.05)
        params = MCLParams(n_particles=400, beam_stride=1, sonar_rays_per_cone=5)
    else:
        angles = np.linspace(-np.pi / 2, np.pi / 2, 60)
        sensor = SensorInfo("laser", "laser", angles, 10.0, 0.02)
        if case == "laser":
            params = MCLParams(n_particles=1000, recovery="augmented", adaptive=True,
                               kld=KLDParams(min_particles=300, max_particles=1500))
        else:
            params = MCLParams(n_particles=800, sensor_model="likelihood_field")
    caster = RayCaster(grid, SEES, sensor.max_range_m)
    rng = np.random.default_rng(11)
    f = MCL(params, grid, sensor, np.random.default_rng(12))
    true = np.array([12.5, 20.1, 0.0])  # a corridor: 6 m of free space ahead
    f.init_pose(true + [0.3, -0.2, 0.1], np.diag([0.5, 0.5, 0.3]) ** 2)
    h = hashlib.sha256()
    for k in range(50):
        delta = np.array([0.12, 0.0, 0.03 * np.sin(k / 5.0)])
        c, s = np.cos(true[2]), np.sin(true[2])
        true = true + [c * delta[0], s * delta[0], delta[2]]
        scan = caster.cast(true[None], angles)[0] + rng.normal(0.0, 0.02, angles.shape[0])
        scan = np.clip(scan, 0.0, sensor.max_range_m)
        f.step(delta + rng.normal(0.0, [0.01, 0.01, 0.005]), scan)
        h.update(f.particles.tobytes())
        h.update(f.weights.tobytes())
        h.update(np.float64(f.last_log_mean_likelihood).tobytes())
        if k % 10 == 9:
            e = f.estimate()
            h.update(np.concatenate([e.pose, e.cov.ravel(), e.cluster_pose,
                                     [e.cluster_weight, e.n_clusters, e.ess, e.n_particles]]).tobytes())
    h.update(f.rng.bit_generator.state["state"]["state"].to_bytes(16, "little"))
    return h.hexdigest()


@pytest.mark.parametrize("case", sorted(DIGESTS))
def test_filter_replay_is_bit_identical(case):
    assert _replay(case) == DIGESTS[case]


@njit
def _every_term_table(z, grid, eta_hit, eta_short, z_hit, z_short, z_max, z_rand, sigma, lam, zmax, out):
    """The beam table as first written: every term of every entry evaluated, then its log."""
    inv_norm = 1.0 / (sigma * math.sqrt(2.0 * math.pi))
    for b in range(z.shape[0]):
        zb = z[b]
        is_max = zb >= zmax - MAX_READING_TOL_M
        if is_max:
            zb = zmax
        base = z_max if is_max else z_rand / zmax
        e_short = lam * math.exp(-lam * zb)
        for j in range(grid.shape[0]):
            ze = grid[j]
            d = (zb - ze) / sigma
            p = base
            if d * d < 1400.0:
                p += z_hit * eta_hit[j] * inv_norm * math.exp(-0.5 * d * d)
            if zb <= ze and ze > 0.0:
                p += z_short * eta_short[j] * e_short
            out[b, j] = math.log(p)
    return out


@pytest.mark.parametrize("mix", [(0.8, 0.1, 0.05, 0.05), (0.97, 0.0, 0.0, 0.03), (0.5, 0.3, 0.2, 1e-9),
                                 (0.2, 0.2, 0.1, 0.5), (1.0 - 1e-300, 0.0, 0.0, 1e-300)])
@pytest.mark.parametrize("sigma", [0.01, 0.1, 0.7])
def test_beam_table_skips_only_what_cannot_change_a_bit(mix, sigma):
    """The table skips the Gaussian where it is below the last bit of the rest: still the bits
    of evaluating every term (max-range readings, z_max = 0, a tiny z_rand included)."""
    z_hit, z_short, z_max, z_rand = mix
    params = BeamModelParams(z_hit=z_hit, z_short=z_short, z_max=z_max, z_rand=z_rand, sigma_hit_m=sigma,
                             table_step_m=0.02)
    zmax = 8.0
    bt = BeamTable(params, zmax)
    z = np.concatenate([np.random.default_rng(3).uniform(0.0, zmax, 40), [0.0, 1e-9, zmax, zmax - 1e-7, 0.5 * zmax]])
    got = bt(z)
    with np.errstate(divide="ignore"):
        want = _every_term_table(z, bt.grid, bt.eta_hit, bt.eta_short, z_hit, z_short, z_max, z_rand, sigma,
                                 params.lambda_short_per_m, zmax, np.empty_like(got))
    assert np.array_equal(got.view(np.uint64), want.view(np.uint64))


if __name__ == "__main__":  # prints the digests of the implementation at hand
    for c in sorted(DIGESTS):
        print(c, _replay(c))
