"""The one shortcut for frozen dataclasses (mobigrasp.protocol.frozen.built) gives what the
constructor gives, on every class the hot paths use it on."""

import dataclasses

import pytest

from mobigrasp.cosim import lockstep as ls
from mobigrasp.host.planning.bezier import Curve
from mobigrasp.host.task.machine import TaskInputs
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import Frame
from mobigrasp.protocol.frozen import built

CASES = [
    (ls.Grant, dict(start_us=10, until_us=5000, uart=((20, 1),), frames=())),
    (ls.Done, dict(until_us=5000, writes=((100, 2),), events=(),
                   load={"state": "S", "windows": {}})),
    (TaskInputs, dict(joints_mrad=(0, 1, 2, 3, 4, 5), x_mm=1, y_mm=-2, heading_mrad=3,
                      v_mmps=4, sonar_mm=(100,) * 5, detections={}, grasp_closed=False)),
    (Curve, dict(ctrl=((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (2.0, 1.0, 0.0), (3.0, 1.0, 0.0)))),
    (Frame, dict(version=1, seq=7, msg_type=0x10, payload=b"\x01\x02")),
]
TRUSTED = [cls for cls in m.ALL_MESSAGES if cls._TRUSTED_DECODE]


def _fields_of(cls):
    return [f.name for f in dataclasses.fields(cls)]


@pytest.mark.parametrize("cls, fields", CASES, ids=lambda c: getattr(c, "__name__", ""))
def test_built_equals_the_constructor(cls, fields):
    assert sorted(fields) == sorted(_fields_of(cls))  # every field given
    fast, slow = built(cls, **fields), cls(**fields)
    assert type(fast) is cls and fast == slow and vars(fast) == vars(slow)
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(fast, _fields_of(cls)[0], None)


@pytest.mark.parametrize("cls", TRUSTED, ids=lambda c: c.__name__)
def test_built_from_pairs_equals_the_decoder_of_each_trusted_message(cls):
    payload = bytes(cls._STRUCT.size)
    raw = cls._STRUCT.unpack_from(payload)
    fast = built(cls, zip(cls._NAMES, map(raw.__getitem__, cls._INDEX), strict=True))
    assert fast == cls.decode(payload) and vars(fast) == vars(cls.decode(payload))
    # the constructor accepts those values too: the shortcut skipped no check that would fail
    assert cls(**vars(fast)) == fast
