"""``payload_size_bytes``'s per-type sizers give exactly the generic walk's byte counts (H7a-2).

The radio counts every message's bytes (``Message.size_bytes``); the per-type dispatch of
:func:`teamnav.control.types.payload_size_bytes` must agree with the generic recursive walk it
replaced (kept as ``_payload_size_bytes_generic``) on every payload type of the code base:
the los-help messages, trails, crumbs, localization sync (density trees) and generic nested
numbers, strings, arrays, tuples, lists, sets and dicts, including subclasses and errors.
"""

from __future__ import annotations

import dataclasses
import enum
from collections import namedtuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.trails.brains.crumbs import CrumbBatch
from teamnav.papers.los_help.brains.messages import (
    GoalShare,
    LosHelpMsg,
    Sighting,
    VisReport,
    _payload_size_bytes,
    message_size_bytes,
)
from teamnav.papers.trails.brains.trails import TrailMessage
from teamnav.control.types import Message, _payload_size_bytes_generic, payload_size_bytes
from teamnav.localization.density_tree import DensityTree
from teamnav.localization.sync import SyncMessage

FAST = settings(max_examples=40, deadline=None)


class Level(enum.IntEnum):
    LOW = 1


class Name(str):
    pass


Pair = namedtuple("Pair", "a b")


@dataclasses.dataclass
class Empty:
    pass


@dataclasses.dataclass
class Nested:
    head: object
    tail: object = None


numbers = st.one_of(
    st.integers(-(2**40), 2**40), st.floats(allow_nan=True), st.booleans(), st.none(),
    st.builds(np.bool_, st.booleans()), st.builds(np.int32, st.integers(-100, 100)),
    st.builds(np.float32, st.floats(-1e3, 1e3)), st.builds(np.float64, st.floats(-1e3, 1e3)),
    st.just(Level.LOW),
)
texts = st.one_of(st.text(max_size=6), st.binary(max_size=6), st.builds(Name, st.text(max_size=4)))
arrays = st.builds(lambda n, dt: np.zeros(n, dtype=dt), st.integers(0, 5),
                   st.sampled_from([np.float64, np.float32, np.int8, np.int32, np.bool_]))
flt = st.floats(-50.0, 50.0)
sightings = st.builds(Sighting, st.integers(0, 9), flt, flt)
goals = st.builds(GoalShare, st.integers(0, 9), st.integers(-40, 40), flt, flt)
reports = st.builds(VisReport, st.integers(0, 9), st.integers(-40, 40), flt, st.none() | flt, st.none() | flt,
                    st.none() | flt)
# as the brain sends them: a report carries its via point whole or not at all
sent_reports = st.builds(VisReport, st.integers(0, 9), st.integers(-40, 40), flt) | st.builds(
    VisReport, st.integers(0, 9), st.integers(-40, 40), flt, flt, flt, flt)


def _los_msgs(report):
    return st.builds(LosHelpMsg, st.integers(0, 10**6), st.lists(sightings, max_size=4).map(tuple),
                     st.lists(goals, max_size=5).map(tuple), st.lists(report, max_size=5).map(tuple),
                     st.none() | st.booleans())


los_msgs = _los_msgs(reports)


def _tree(k: int) -> DensityTree:
    m = 2 * k + 1
    return DensityTree(np.zeros(2), np.ones(2), np.zeros(2, bool), np.full(m, -1, np.int8), np.zeros(m, np.float32),
                       np.full(m, -1, np.int32), np.ones(m, np.float32))


def _trail(names: tuple, k: int) -> TrailMessage:
    return TrailMessage(names, np.zeros((len(names), 2)), tuple(names[:1]) * k, np.zeros((k, 2)), np.zeros(k),
                        np.zeros(k))


names = st.lists(st.text(max_size=5), min_size=1, max_size=3, unique=True).map(tuple)
bodies = st.one_of(
    los_msgs,
    st.builds(_trail, names, st.integers(0, 4)),
    st.builds(lambda n: CrumbBatch(np.zeros((n, 2)), np.zeros(n)), st.integers(0, 5)),
    st.builds(SyncMessage, st.sampled_from(["detection", "inverse"]), st.integers(0, 3), st.integers(0, 3), flt, flt,
              st.floats(0, 1), st.builds(_tree, st.integers(0, 4)),
              st.lists(st.tuples(st.integers(0, 3), flt), max_size=3).map(tuple)),
    st.builds(Empty),
)
payloads = st.recursive(
    st.one_of(numbers, texts, arrays, bodies),
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.lists(inner, max_size=4).map(tuple),
        st.frozensets(st.integers(0, 50) | st.text(max_size=3), max_size=4), st.sets(st.floats(-5, 5), max_size=3),
        st.dictionaries(st.text(max_size=3) | st.integers(0, 9), inner, max_size=3),
        st.builds(Pair, inner, inner), st.builds(Nested, inner, inner),
    ),
    max_leaves=12,
)


@given(payloads)
@FAST
def test_per_type_sizers_equal_the_generic_walk(value):
    assert payload_size_bytes(value) == _payload_size_bytes_generic(value)
    assert Message(0, 0.0, value).size_bytes() == 24 + _payload_size_bytes_generic(value)


@given(_los_msgs(sent_reports))
@FAST
def test_los_help_messages_match_the_formula_and_the_walk(body):
    size = Message(1, 2.0, body, kind="los_help").size_bytes()
    assert size == message_size_bytes(body) == 24 + _payload_size_bytes_generic(body)


@given(st.builds(LosHelpMsg, st.integers(0, 10**6), st.lists(sightings, max_size=4).map(tuple),
                 st.lists(goals, max_size=5).map(tuple), st.lists(reports, max_size=5).map(tuple),
                 st.none() | st.booleans() | st.builds(np.bool_, st.booleans()),
                 st.none() | st.tuples(flt, flt, flt), st.none() | st.tuples(*[flt] * 6)))
@FAST
def test_los_help_formula_sizer_is_the_walk(body):
    """The radio sizes a los-help message by formula (registered for its type): the walk's count
    for any mix of via fields present, Tr bits and the beyond section's pose and covariance."""
    assert _payload_size_bytes(body) == _payload_size_bytes_generic(body)
    assert payload_size_bytes(body) == _payload_size_bytes_generic(body)  # the registered sizer is the formula
    assert payload_size_bytes((body, [body])) == 2 * _payload_size_bytes_generic(body)  # nested, as any field


def test_sizes_by_hand():
    # int 8, float 8, bool 1, None 0, "ab" 2, {"k": [0.5]}: 1 + 8
    assert payload_size_bytes((1, 2.0, True, None, "ab", {"k": [0.5]})) == 28
    assert payload_size_bytes(Sighting(1, 0.5, 2.0)) == 24
    assert payload_size_bytes(VisReport(1, 4, 3.0)) == 24  # None via point: 0 bytes
    assert payload_size_bytes(np.zeros((3, 2), np.float32)) == 24
    assert payload_size_bytes(Level.LOW) == 8 and payload_size_bytes(np.bool_(True)) == 1
    assert payload_size_bytes("é") == 2  # UTF-8 length, not characters
    assert payload_size_bytes(Empty()) == 0


@pytest.mark.parametrize("value", [object(), Empty, Nested, [1, object()], {"k": 1 + 2j}, Nested(1, object())])
def test_unsizable_values_raise_the_same_error(value):
    with pytest.raises(TypeError) as want:
        _payload_size_bytes_generic(value)
    for _ in range(2):  # the sizer is built on first sight, then reused
        with pytest.raises(TypeError) as got:
            payload_size_bytes(value)
        assert str(got.value) == str(want.value)
        assert "cannot size a message field of type" in str(got.value)


# ------------------------------------------------------------------ fast frozen __init__
def test_fast_init_keeps_the_dataclass_contract():
    import inspect
    import pickle

    from teamnav.control.types import Action, Detection, Observation, RangeScan

    pose = np.zeros(3)
    a, b = Observation(1, 2, 0.1, pose, pose), Observation(1, 2, 0.1, pose, pose)
    assert a.scans == {} and a.scans is not b.scans  # default_factory called per instance
    assert (a.detections, a.stalled, a.inbox, a.events) == ((), False, (), ())
    assert str(inspect.signature(Observation)).endswith("scans=<factory>, detections=(), stalled=False, inbox=(), events=())")
    assert Action() == Action(0.0, 0.0, None) and Detection(1.0, 0.5).robot_id is None
    m = Message(3, 1.5, (1, 2.0), kind="k")
    assert (m.sender, m.stamp_s, m.body, m.to, m.kind) == (3, 1.5, (1, 2.0), None, "k")
    assert pickle.loads(pickle.dumps(m)) == m and dataclasses.replace(m, to=2).to == 2
    assert repr(RangeScan(1, 2, 3.0)) == "RangeScan(ranges_m=1, angles_rad=2, max_range_m=3.0)"
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.to = 1
    with pytest.raises(TypeError, match="missing 2 required positional arguments: 'stamp_s' and 'body'"):
        Message(1)
    with pytest.raises(TypeError, match="unexpected keyword argument 'speed'"):
        Action(speed=1.0)
