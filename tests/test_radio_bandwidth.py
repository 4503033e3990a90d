"""The radio's bandwidth cap (ours): a token bucket per sender, over-cap messages dropped
at the sender and counted; no cap (the papers' rule) leaves the radio bit-identical."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from teamnav.control.types import Message
from teamnav.sim.config import RadioConfig
from teamnav.sim.radio import Radio
from teamnav.world.grid import OccupancyGrid

N = 3
XS = np.array([0.5, 1.5, 2.5])
YS = np.array([1.0, 1.0, 1.0])


def _grid():
    return OccupancyGrid.empty(40, 20, 0.1)


def _radio(cap, dt_s=0.1, **kw):
    return Radio(RadioConfig(bandwidth_bps=cap, **kw), _grid(), N, np.random.default_rng(0), dt_s=dt_s)


def _msg(s, body_bytes):
    return Message(s, 0.0, "x" * body_bytes)  # 24 header bytes + the body's


def test_bucket_arithmetic_on_a_worked_example():
    # 100 B/s, dt 0.1 s: 10 B per step, burst 100 B; each message is 26 B
    r = _radio(100.0)
    m = _msg(0, 2)
    assert m.size_bytes() == 26
    r.send([(0, m)] * 5, XS, YS, step=0)  # 100 B: 3 fit (78 B), 2 over; 22 B left
    assert [len(b) for b in r.collect()] == [0, 3, 3]
    r.send([(0, m)] * 2, XS, YS, step=1)  # 22 + 10 = 32 B: 1 fits, 6 B left
    assert [len(b) for b in r.collect()] == [0, 1, 1]
    r.send([(0, m)] * 4, XS, YS, step=10)  # 6 + 9 x 10 = 96 B: 3 fit, 18 B left
    assert [len(b) for b in r.collect()] == [0, 3, 3]
    r.send([(0, m)] * 4, XS, YS, step=1000)  # refill stops at the burst (100 B): 3 fit
    r.collect()
    c = r.counts()
    assert c["per_robot"]["messages_sent"] == [10, 0, 0] and c["per_robot"]["bytes_sent"] == [260, 0, 0]
    oc = c["over_cap"]
    assert oc["messages"] == 5 and oc["bytes"] == 130 and oc["bandwidth_bps"] == 100.0
    assert oc["per_robot"] == {"messages": [5, 0, 0], "bytes": [130, 0, 0]}
    assert c["messages_delivered"] == 20 and c["deliveries_lost"] == 0


def test_a_small_message_still_goes_after_a_big_one_is_dropped_and_senders_have_their_own_buckets():
    r = _radio(100.0)
    r.send([(0, _msg(0, 200)), (0, _msg(0, 10)), (1, _msg(1, 60))], XS, YS, step=0)
    assert [[len(str(m.body)) for m in box] for box in r.collect()] == [[60], [10], [10, 60]]
    assert r.counts()["over_cap"]["per_robot"]["messages"] == [1, 0, 0]


def test_a_message_larger_than_the_burst_never_goes_out_and_a_longer_burst_lets_it():
    big = _msg(0, 76)  # 100 B
    for burst_s, sent in ((1.0, 0), (2.0, 5)):  # 50 B/s: a 50-B bucket, or a 100-B one refilled in 2 s
        r = _radio(50.0, bandwidth_burst_s=burst_s)
        for k in range(0, 100, 10):  # one offer a second for 10 s
            r.send([(0, big)], XS, YS, step=k)
        assert r.counts()["messages_sent"] == sent and r.counts()["over_cap"]["messages"] == 10 - sent
        assert r.counts()["over_cap"]["burst_bytes"] == 50.0 * burst_s


@settings(max_examples=60, deadline=None)
@given(cap=st.floats(20.0, 5000.0), dt_s=st.sampled_from([0.05, 0.1, 0.25, 1.0]), burst_s=st.floats(0.1, 10.0),
       plan=st.lists(st.tuples(st.integers(0, 3), st.lists(st.tuples(st.integers(0, N - 1), st.integers(0, 300)),
                                                            max_size=8)), min_size=1, max_size=40))
def test_transmitted_bytes_per_sender_never_exceed_cap_times_window_plus_burst(cap, dt_s, burst_s, plan):
    """Over any window of steps a..b, the bytes each sender got out (delivered to a listener that
    hears everything, no loss) are at most ``burst + cap * dt_s * (b - a)``; every message offered
    is either sent or counted over the cap."""
    r = _radio(cap, dt_s, bandwidth_burst_s=burst_s)
    step, offered = 0, [[0, 0] for _ in range(N)]
    got: dict[int, np.ndarray] = {}  # step -> bytes from each sender, delivered to its neighbour
    for gap, msgs in plan:
        step += gap
        out = [(s, _msg(s, b)) for s, b in msgs]
        for s, m in out:
            offered[s][0] += 1
            offered[s][1] += m.size_bytes()
        r.send(out, XS, YS, step=step)
        row = got.setdefault(step, np.zeros(N))
        for rcv, box in enumerate(r.collect()):
            for m in box:
                if rcv == (m.sender + 1) % N:
                    row[m.sender] += m.size_bytes()
    steps = sorted(got)
    per_step = np.array([got[k] for k in steps])
    burst = cap * burst_s
    for i, a in enumerate(steps):
        window = np.cumsum(per_step[i:], axis=0)
        bound = burst + cap * dt_s * (np.array(steps[i:]) - a)
        assert np.all(window <= bound[:, None] + 1e-6 * (1.0 + bound[:, None]))
    c = r.counts()
    for s in range(N):
        assert c["per_robot"]["messages_sent"][s] + c["over_cap"]["per_robot"]["messages"][s] == offered[s][0]
        assert c["per_robot"]["bytes_sent"][s] + c["over_cap"]["per_robot"]["bytes"][s] == offered[s][1]


def test_without_a_cap_nothing_changes():
    cfg = RadioConfig(p_loss=0.3)
    for dump in (cfg.model_dump(), cfg.model_dump(mode="json")):
        assert "bandwidth_bps" not in dump and "bandwidth_burst_s" not in dump
    assert RadioConfig.model_validate(cfg.model_dump()) == cfg
    r = Radio(cfg, _grid(), N, np.random.default_rng(0))  # no dt_s needed
    r.send([(0, _msg(0, 10**5))] * 3, XS, YS)  # no step needed
    r.collect()
    assert "over_cap" not in r.counts() and r.over_cap()["messages"] == 0


def test_a_cap_that_never_binds_changes_no_delivery_and_no_loss_draw():
    def trace(cap):
        r = Radio(RadioConfig(p_loss=0.4, bandwidth_bps=cap), _grid(), N, np.random.default_rng(3), dt_s=0.1)
        out = []
        for k in range(30):
            r.send([(k % N, _msg(k % N, k)), ((k + 1) % N, _msg((k + 1) % N, 3))], XS, YS, step=k)
            out.append([[m.body for m in b] for b in r.collect()])
        return out, r.counts()

    (a, ca), (b, cb) = trace(None), trace(1e9)
    assert a == b
    cb.pop("over_cap")
    assert ca == cb


@pytest.mark.parametrize("field,value", [("bandwidth_bps", 0.0), ("bandwidth_bps", -5.0), ("bandwidth_bps", float("nan")),
                                         ("bandwidth_bps", float("inf")), ("bandwidth_bps", "fast"), ("bandwidth_bps", 1e13),
                                         ("bandwidth_burst_s", 0.0), ("bandwidth_burst_s", None), ("bandwidth_burst_s", 1e6)])
def test_a_bad_cap_is_refused_naming_the_field(field, value):
    with pytest.raises(ValidationError, match=field):
        RadioConfig(**{field: value})


def test_a_bad_cap_in_a_scenario_names_the_dotted_field():
    from teamnav import load_scenario

    with pytest.raises(Exception, match=r"radio.*bandwidth_bps"):
        load_scenario("demo", duration_s=1.0, overrides=["radio.bandwidth_bps=-1"])


def test_the_cap_needs_the_step_and_dt():
    with pytest.raises(ValueError, match="dt_s"):
        Radio(RadioConfig(bandwidth_bps=100.0), _grid(), N, np.random.default_rng(0))
    r = _radio(100.0)
    with pytest.raises(ValueError, match="step"):
        r.send([(0, _msg(0, 1))], XS, YS)
    r.send([(0, _msg(0, 1))], XS, YS, step=5)
    with pytest.raises(ValueError, match="step"):
        r.send([(0, _msg(0, 1))], XS, YS, step=4)


def test_a_capped_scenario_runs_and_its_counts_show_what_the_cap_dropped(tmp_path):
    from teamnav import load_scenario, run
    from teamnav.experiments.sweep import config_hash
    from teamnav.sim.recorder import load

    name, dur = "try-to-see-it-my-way", 30.0  # each robot broadcasts a 100-B trail every 2 s
    plain = load_scenario(name, duration_s=dur)
    assert config_hash(plain) == config_hash(load_scenario(name, duration_s=dur, overrides=["radio.bandwidth_bps=null"]))
    counts = {}
    for cap in (None, 1e9, 20.0):  # unlimited, never binding, a quarter of one robot's 50 B/s over 5 s bursts
        over = [] if cap is None else [f"radio.bandwidth_bps={cap}", "radio.bandwidth_burst_s=5"]
        scn = load_scenario(name, duration_s=dur, overrides=over)
        run(scn, out_dir=tmp_path / str(cap), progress=False)
        counts[cap] = load(tmp_path / str(cap)).comm
    free, never, capped = counts[None], counts[1e9], counts[20.0]
    assert never["over_cap"]["messages"] == 0 and never["messages_sent"] == free["messages_sent"] > 20
    oc = capped["over_cap"]
    assert oc["messages"] > 0 and oc["burst_bytes"] == 100.0
    for s, sent in enumerate(capped["per_robot"]["bytes_sent"]):  # 100 B burst + 20 B/s x 30 s
        assert sent <= 100.0 + 20.0 * dur


def test_faults_come_first_what_they_stop_takes_nothing_from_the_bucket():
    r = _radio(100.0)  # 100-B bucket, 26-B messages
    m = _msg(0, 2)
    r.send([(0, m)] * 3, XS, YS, blocked=True, step=0)  # a blackout: not sent, bucket untouched
    r.send([(0, m)] * 3, XS, YS, muted=np.array([True, False, False]), step=0)  # sender muted: the same
    r.send([(0, m)] * 3, XS, YS, step=0)
    assert [len(b) for b in r.collect()] == [0, 3, 3]
    c = r.counts()
    assert c["faults"]["messages_not_sent"] == 6 and c["over_cap"]["messages"] == 0
