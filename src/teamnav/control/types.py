"""What a robot's brain receives and returns: the belief side of the truth/belief rule.

Everything here is in the robot's *own* frame: its odometry frame (which drifts away from
the world) or its body frame (x forward, y left). Nothing here carries a true pose. The
simulator (``teamnav.sim``) builds these from the truth through the sensor, odometry and
radio models; brains (``teamnav.control``, ``teamnav.localization``) read only these.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@functools.lru_cache(maxsize=256)
def _field_names(kind: type) -> tuple[str, ...]:
    """A dataclass type's field names, looked up once (``dataclasses.fields`` is slow per call)."""
    return tuple(f.name for f in dataclasses.fields(kind))


def payload_size_bytes(value: Any) -> int:
    """Bytes a value would take on the wire, for bandwidth accounting.

    float/int: 8 bytes, bool: 1, str: its UTF-8 length, ndarray: ``nbytes``, None: 0,
    sequences and mappings: the sum of their items, dataclasses: the sum of their fields.

    Dispatches on ``type(value)``: a fixed size per type (numbers, bools, None) or a sizer
    built once per type by :func:`_sizer_for` (a dataclass's fields read by name), the same
    rules in the same order as :func:`_payload_size_bytes_generic` (every rule there depends
    only on the value's type), so the byte counts are identical.

    Examples
    --------
    >>> payload_size_bytes((1, 2.0, True, None, "ab", {"k": [0.5]}))
    28
    """
    kind = type(value)
    size = _FIXED_SIZE.get(kind)
    if size is not None:
        return size
    sizer = _SIZER.get(kind)
    if sizer is None:
        sizer = _sizer_for(kind)
        if sizer is None:
            return _FIXED_SIZE[kind]
    return sizer(value)


#: type -> bytes, for types whose every value has the same size (filled on first sight)
_FIXED_SIZE: dict[type, int] = {float: 8, int: 8, bool: 1, type(None): 0}
#: type -> sizer(value) -> bytes, for the others (filled on first sight)
_SIZER: dict[type, Any] = {}


def _size_str(value: str) -> int:
    return len(value.encode())


def _size_bytes(value: bytes) -> int:
    return len(value)


def _size_array(value: np.ndarray) -> int:
    return int(value.nbytes)


def _size_mapping(value: dict) -> int:
    size = payload_size_bytes
    return sum(size(k) + size(v) for k, v in value.items())


def _size_collection(value) -> int:
    fixed = _FIXED_SIZE.get
    sizer = _SIZER.get
    total = 0
    for item in value:
        kind = type(item)
        size = fixed(kind)
        if size is None:
            size = (sizer(kind) or payload_size_bytes)(item)
        total += size
    return total


def _sizer_for(kind: type):
    """Register how values of type ``kind`` are sized; None when their size is fixed.

    The rules of :func:`_payload_size_bytes_generic`, in its order, on the type: ``isinstance``
    and ``dataclasses.is_dataclass`` of a value depend only on its type.
    """
    if kind is type(None):
        _FIXED_SIZE[kind] = 0
        return None
    if issubclass(kind, (bool, np.bool_)):
        _FIXED_SIZE[kind] = 1
        return None
    if issubclass(kind, (int, float, np.integer, np.floating)):
        _FIXED_SIZE[kind] = 8
        return None
    if issubclass(kind, str):
        sizer = _size_str
    elif issubclass(kind, bytes):
        sizer = _size_bytes
    elif issubclass(kind, np.ndarray):
        sizer = _size_array
    elif dataclasses.is_dataclass(kind) and not issubclass(kind, type):
        names = _field_names(kind)
        # one function per dataclass reading its fields by name (fields are identifiers);
        # a fixed-size field costs a dict look-up (None's 0 falls through to size(), also 0),
        # a known type one call
        lines = [f"    x = value.{name}\n    kind = type(x)\n    total += fixed(kind) or (known(kind) or size)(x)\n"
                 for name in names]
        namespace: dict[str, Any] = {"payload_size_bytes": payload_size_bytes, "_FIXED_SIZE": _FIXED_SIZE,
                                     "_SIZER": _SIZER}
        exec("def sizer(value, size=payload_size_bytes, fixed=_FIXED_SIZE.get, known=_SIZER.get):\n    total = 0\n"
             + "".join(lines) + "    return total\n", namespace)  # noqa: S102
        sizer = namespace["sizer"]
    elif issubclass(kind, dict):
        sizer = _size_mapping
    elif issubclass(kind, (list, tuple, set, frozenset)):
        sizer = _size_collection
    else:
        def sizer(value):
            raise TypeError(f"cannot size a message field of type {type(value).__name__}; use plain data")
    _SIZER[kind] = sizer
    return sizer


def register_payload_sizer(kind: type, sizer) -> None:
    """Size values of exactly type ``kind`` with ``sizer(value) -> bytes`` from now on.

    For a message type sent every step whose size has a closed form (the line-of-sight help
    message: a formula over its tuples' lengths instead of a walk over every field). The
    sizer must return :func:`_payload_size_bytes_generic`'s count for every value its
    producers build; its module's tests pin that (``tests/test_payload_size.py``).
    """
    _SIZER[kind] = sizer


def _payload_size_bytes_generic(value: Any) -> int:
    """:func:`payload_size_bytes` as a generic recursive walk (the rules written out once per
    value; kept as the reference the per-type sizers are tested against and benchmarked with)."""
    kind = type(value)
    if kind is float or kind is int:  # the common case first: most fields are plain numbers
        return 8
    if value is None:
        return 0
    if isinstance(value, (bool, np.bool_)):
        return 1
    if isinstance(value, (int, float, np.integer, np.floating)):
        return 8
    if isinstance(value, str):
        return len(value.encode())
    if isinstance(value, bytes):
        return len(value)
    if isinstance(value, np.ndarray):
        return int(value.nbytes)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return sum(_payload_size_bytes_generic(getattr(value, name)) for name in _field_names(kind))
    if isinstance(value, dict):
        return sum(_payload_size_bytes_generic(k) + _payload_size_bytes_generic(v) for k, v in value.items())
    if isinstance(value, (list, tuple, set, frozenset)):
        return sum(_payload_size_bytes_generic(v) for v in value)
    raise TypeError(f"cannot size a message field of type {type(value).__name__}; use plain data")


class _Factory:
    """"No argument": the field's default_factory is called (shown as dataclasses shows it)."""

    def __repr__(self) -> str:
        return "<factory>"


_FACTORY = _Factory()


def _fast_frozen_init(cls: type) -> type:
    """Give a frozen, slotted dataclass an ``__init__`` that stores through the slots' own
    descriptors (the generated one calls ``object.__setattr__`` per field: ~0.45 µs more per
    field; the simulator builds an Observation, RangeScan and Action per robot per step).

    Same parameters, order, defaults and default factories as the generated ``__init__``;
    the instance stays frozen (assignment still raises ``FrozenInstanceError``).
    """
    params = cls.__dataclass_params__
    if not (params.frozen and "__slots__" in cls.__dict__) or hasattr(cls, "__post_init__"):
        raise TypeError(f"{cls.__name__}: only frozen slotted dataclasses without __post_init__")
    namespace: dict[str, Any] = {"_FACTORY": _FACTORY}
    args, body = [], []
    for f in dataclasses.fields(cls):
        if not f.init or f.kw_only:
            raise TypeError(f"{cls.__name__}.{f.name}: init=False / kw_only fields are not supported")
        namespace[f"_set_{f.name}"] = cls.__dict__[f.name].__set__
        if f.default is not dataclasses.MISSING:
            namespace[f"_default_{f.name}"] = f.default
            args.append(f"{f.name}=_default_{f.name}")
            body.append(f"    _set_{f.name}(self, {f.name})")
        elif f.default_factory is not dataclasses.MISSING:
            namespace[f"_factory_{f.name}"] = f.default_factory
            args.append(f"{f.name}=_FACTORY")
            body.append(f"    _set_{f.name}(self, _factory_{f.name}() if {f.name} is _FACTORY else {f.name})")
        else:
            args.append(f.name)
            body.append(f"    _set_{f.name}(self, {f.name})")
    exec(f"def __init__(self, {', '.join(args)}):\n" + "\n".join(body) + "\n", namespace)  # noqa: S102
    init = namespace["__init__"]
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    init.__doc__ = cls.__init__.__doc__
    cls.__init__ = init
    return cls


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class Message:
    """A radio message: plain data, sized so bandwidth can be counted.

    Parameters
    ----------
    sender : int
        Id of the sending robot (a robot knows its own id).
    stamp_s : float
        Sender's clock when sent [s].
    body : Any
        Plain data: a frozen dataclass, numbers, strings, arrays, tuples, dicts.
    to : int or None
        Addressee id, or None to broadcast. The radio model still decides who hears it.
    kind : str
        A short label for logs and per-kind message counts.
    """

    sender: int
    stamp_s: float
    body: Any
    to: int | None = None
    kind: str = "msg"

    def size_bytes(self) -> int:
        """Header (sender, stamp, to: 8 bytes each) plus the body's size."""
        return 24 + payload_size_bytes(self.body)


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class Detection:
    """One robot seen by the robot detector, in the observer's body frame.

    ``robot_id`` is None when the detector does not report identities, and for false
    positives it is whatever the detector model reports (possibly a wrong id or None).
    """

    range_m: float
    bearing_rad: float
    robot_id: int | None = None


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class RangeScan:
    """One range sensor's reading.

    ``angles_rad[i]`` is beam i's direction in the body frame; ``ranges_m[i]`` its range,
    equal to ``max_range_m`` for "no return".
    """

    ranges_m: np.ndarray
    angles_rad: np.ndarray
    max_range_m: float


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class Observation:
    """Everything a robot knows at one step, with this step's values and arrays.

    The simulator hands a brain that kept nothing of its last observation (not the
    observation, its ``scans`` dict or a scan) the same objects again, refilled; a brain that
    keeps any of them gets new ones, and what it kept never changes.

    Attributes
    ----------
    robot_id : int
        This robot's id.
    step : int
        Step index (0 at start).
    time_s : float
        Time since start [s] (robots' clocks agree).
    odom_pose : ndarray of shape (3,)
        (x [m], y [m], theta [rad]) believed from odometry, in this robot's own odometry
        frame (the pose it started at is (0, 0, 0) unless the scenario aligns frames).
    odom_delta : ndarray of shape (3,)
        Odometry motion since the previous step, as (dx, dy, dtheta) in the previous
        body frame (what MCL's odometry motion model consumes).
    scans : dict of str to RangeScan
        Range sensors by name ("laser", "sonar", ...).
    detections : tuple of Detection
        Teammates (and false positives) seen by the robot detector this step.
    stalled : bool
        Bumper/stall flag: the last commanded motion was blocked (wall or robot).
    inbox : tuple of Message
        Messages the radio delivered this step.
    events : tuple of str
        Task events fired for this robot this step (e.g. "given_resource", "took_resource").
    """

    robot_id: int
    step: int
    time_s: float
    odom_pose: np.ndarray
    odom_delta: np.ndarray
    scans: dict[str, RangeScan] = field(default_factory=dict)
    detections: tuple[Detection, ...] = ()
    stalled: bool = False
    inbox: tuple[Message, ...] = ()
    events: tuple[str, ...] = ()


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class Action:
    """A motion command.

    Unicycle robots use ``v_mps`` (forward speed) and ``omega_radps`` (turn rate); the
    simulator clips both to the robot's limits. Holonomic fixed-step robots (Sgorbissa &
    Arkin count motion steps) use ``direction_rad``: the body-frame direction of one step of
    fixed length (the robot turns to face it and moves); None means stay.
    """

    v_mps: float = 0.0
    omega_radps: float = 0.0
    direction_rad: float | None = None

    @staticmethod
    def stop() -> "Action":
        return Action()


@dataclass(frozen=True, slots=True)
class BatchObservation:
    """Observations of every robot run by one batched controller, row by row.

    The same truth/belief rule as :class:`Observation`: each row is one robot's own data.

    Attributes
    ----------
    robot_ids : ndarray (n,) int64
    step : int
    time_s : float
    odom_pose : ndarray (n, 3) float64 — own odometry frame
    ranges_m : ndarray (n, B) float64 — the controller's chosen range sensor
    angles_rad : ndarray (B,) float64 — beam directions in the body frame
    max_range_m : float
    stalled : ndarray (n,) bool
    """

    robot_ids: np.ndarray
    step: int
    time_s: float
    odom_pose: np.ndarray
    ranges_m: np.ndarray
    angles_rad: np.ndarray
    max_range_m: float
    stalled: np.ndarray


@dataclass(frozen=True, slots=True)
class BatchAction:
    """Commands for every robot of a batched controller: ``v_mps`` and ``omega_radps`` (n,)."""

    v_mps: np.ndarray
    omega_radps: np.ndarray
