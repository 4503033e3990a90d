"""Bandwidth accounting: ``payload_size_bytes`` counts what a message would take on the wire."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from teamnav.control.types import payload_size_bytes


@dataclass(frozen=True)
class _Inner:
    x: float
    flag: bool


@dataclass(frozen=True)
class _Report:
    goal: tuple
    ident: int
    label: str
    inner: _Inner
    extra: None = None


def test_nested_dataclass_is_the_sum_of_its_fields() -> None:
    report = _Report(goal=(1.0, 2.0), ident=3, label="abc", inner=_Inner(0.5, True))
    # 2 floats + 1 int + 3 UTF-8 bytes + (float + bool) + None
    assert payload_size_bytes(report) == 16 + 8 + 3 + 9 + 0
    # the cached field lookup must not mix up two types
    assert payload_size_bytes(_Inner(1.0, False)) == 9


def test_numpy_scalars_arrays_and_bools() -> None:
    assert payload_size_bytes(np.float32(1.0)) == 8
    assert payload_size_bytes(np.bool_(True)) == 1
    assert payload_size_bytes(True) == 1  # a bool is not counted as an 8-byte int
    assert payload_size_bytes(np.zeros((3, 4), dtype=np.float32)) == 48


@given(st.lists(st.one_of(st.floats(allow_nan=False), st.integers(-(2**62), 2**62)), max_size=30))
def test_a_list_of_numbers_is_eight_bytes_each(values: list) -> None:
    assert payload_size_bytes(values) == 8 * len(values)
    assert payload_size_bytes({i: v for i, v in enumerate(values)}) == 16 * len(values)


def test_unsized_type_is_refused_by_name() -> None:
    with pytest.raises(TypeError, match="cannot size a message field of type object"):
        payload_size_bytes([1.0, object()])
