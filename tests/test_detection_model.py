"""Detection model (Fox et al. §4.2): ML fit recovers the simulated noise and rates; JSON I/O
with clear errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from teamnav.geometry.angles import wrap_angle
from teamnav.localization import DetectionModel, DetectionSamples, fit_detection_model


def synthetic(rng, n, r_bias, r_std, b_bias, b_std, p_fn, p_fp):
    """Frames: half with a robot in view, detected unless missed; half empty, with phantoms."""
    in_view = rng.random(n) < 0.5
    det = np.where(in_view, rng.random(n) >= p_fn, rng.random(n) < p_fp)
    ref_r = np.where(in_view, rng.uniform(0.5, 8.0, n), np.nan)
    ref_b = np.where(in_view, rng.uniform(-np.pi, np.pi, n), np.nan)
    det_r = np.where(det, np.where(in_view, ref_r + r_bias + rng.normal(0, r_std, n), rng.uniform(0, 8, n)), np.nan)
    det_b = np.where(det, np.where(in_view, wrap_angle(ref_b + b_bias + rng.normal(0, b_std, n)),
                                   rng.uniform(-np.pi, np.pi, n)), np.nan)
    return DetectionSamples(in_view, det, ref_r, ref_b, det_r, det_b)


def test_fit_recovers_the_simulated_parameters():
    # the paper's numbers: 48.3 cm, 2.2 deg, 6.7 % missed, 3.5 % phantoms
    s = synthetic(np.random.default_rng(0), 20_000, 0.05, 0.483, math.radians(0.5), math.radians(2.2), 0.067, 0.035)
    m = fit_detection_model(s)
    assert abs(m.range_bias_m - 0.05) < 0.02
    assert abs(m.range_std_m - 0.483) < 0.015
    assert abs(m.bearing_bias_rad - math.radians(0.5)) < math.radians(0.1)
    assert abs(m.bearing_std_rad - math.radians(2.2)) < math.radians(0.1)
    assert abs(m.p_false_negative - 0.067) < 0.01
    assert abs(m.p_false_positive - 0.035) < 0.01
    assert m.n_frames == 20_000 and m.n_detections == int((s.in_view & s.detected).sum())


def test_sampled_positions_follow_the_model():
    m = DetectionModel(range_std_m=0.2, bearing_std_rad=0.05)
    pts = m.sample_positions(np.tile([1.0, 2.0, np.pi / 2], (20_000, 1)), 3.0, 0.0, np.random.default_rng(1))
    assert abs(pts[:, 0].mean() - 1.0) < 0.01 and abs(pts[:, 1].mean() - 5.0) < 0.01
    assert abs(pts[:, 1].std() - 0.2) < 0.01 and abs(pts[:, 0].std() - 3.0 * 0.05) < 0.01


def test_save_load_roundtrip_and_errors(tmp_path):
    m = DetectionModel(range_bias_m=0.1, range_std_m=0.4, p_false_negative=0.07, p_false_positive=0.03)
    p = tmp_path / "det.json"
    m.save(p)
    assert DetectionModel.load(p) == m
    data = json.loads(p.read_text())
    data["range_std_m"] = -1.0
    p.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=r"det\.json: field 'range_std_m'.*greater than or equal to 0"):
        DetectionModel.load(p)
    data["range_std_m"] = 0.4
    data["colour"] = "red"
    p.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="field 'colour'"):
        DetectionModel.load(p)
    p.write_text("{not json")
    with pytest.raises(ValueError, match="not valid JSON"):
        DetectionModel.load(p)
    p.write_text(json.dumps({"range_std_m": 0.1}))
    with pytest.raises(ValueError, match="field 'format'"):
        DetectionModel.load(p)
    with pytest.raises(ValueError, match="cannot read"):
        DetectionModel.load(tmp_path / "missing.json")


def test_fit_rejects_malformed_samples():
    s = synthetic(np.random.default_rng(2), 100, 0, 0.1, 0, 0.1, 0.0, 0.0)
    bad = DetectionSamples(s.in_view, s.detected, s.reference_range_m[:50], s.reference_bearing_rad,
                           s.detected_range_m, s.detected_bearing_rad)
    with pytest.raises(ValueError, match=r"samples.reference_range_m must have shape \(100,\)"):
        fit_detection_model(bad)
    r = s.detected_range_m.copy()
    r[np.argmax(s.in_view & s.detected)] = np.nan
    with pytest.raises(ValueError, match="detected_range_m must be a number"):
        fit_detection_model(DetectionSamples(s.in_view, s.detected, s.reference_range_m, s.reference_bearing_rad,
                                             r, s.detected_bearing_rad))
    none_out = DetectionSamples(np.ones(10, bool), np.ones(10, bool), np.ones(10), np.zeros(10), np.ones(10),
                                np.zeros(10))
    with pytest.raises(ValueError, match="without"):
        fit_detection_model(none_out)


def test_documented_training_command_reproduces_the_shipped_model(tmp_path):
    """Commit 882fcf3 (2026-11-27): the command in detection_training's docstring, with its defaults, writes the
    shipped detection-default.json byte for byte (it needed --duration 1200 before)."""
    from teamnav.papers.collab_mcl.brains.localizing import MODEL_DIR
    from teamnav.papers.collab_mcl.detection_training import main

    out = tmp_path / "detection-default.json"
    main(["--out", str(out)])
    assert out.read_bytes() == (MODEL_DIR / "detection-default.json").read_bytes()
