"""The rig's frames without copies: the grant's pixels are a read-only view of the plant's frame
(cosim/rig.py _pixels; WorldPlant.capture hands out its read-only clean image): the same
pixels, messages and host arrays as the copies they replace."""

import numpy as np
import pytest
from rig_fakes import FakeMcu

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.frame_ring import FrameRing, FrameRingReader
from mobigrasp.cosim.rig import Rig, RigConfig, _pixels
from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.services.run_job import resolve_scenario


@pytest.fixture(scope="module")
def plant():
    _, scenario = resolve_scenario("paper000-exp1")
    return WorldPlant(scenario, 3)


def test_pixels_view_equals_the_bytes_everywhere(tmp_path):
    rgb = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    view = _pixels(rgb)
    assert view == rgb.tobytes()
    assert view.readonly and len(view) == rgb.nbytes
    as_host = np.frombuffer(view, np.uint8).reshape(4, 6, 3)  # drivers/lockstep.py
    assert np.array_equal(as_host, rgb) and not as_host.flags.writeable
    odd = rgb[:, ::2]  # not contiguous: copied
    assert _pixels(odd) == odd.tobytes() and isinstance(_pixels(odd), bytes)

    def grant(pixels):
        blob = ls.FrameBlob(seq=1, capture_us=0, arrival_us=5_000, width=6, height=4,
                            channels=3, pixels=pixels)
        return ls.Grant(start_us=5_000, until_us=10_000, uart=((4_000, 3),), frames=(blob,))

    assert grant(view) == grant(rgb.tobytes())
    assert ls.encode(grant(view)) == ls.encode(grant(rgb.tobytes()))  # in the message
    ring, reader = FrameRing(slots=2, directory=str(tmp_path)), FrameRingReader()
    try:
        wire = ls.encode(grant(view), frame_sink=ring.put)  # through the frame ring
        kind, meta_len, _ = ls.decode_header(wire[:ls.HEADER.size])
        meta = wire[ls.HEADER.size:ls.HEADER.size + meta_len]
        back = ls.decode_body(kind, meta, b"", frame_source=reader)
        assert back == grant(rgb.tobytes())
        assert "shared" in wire.decode("latin-1")  # the pixels went through the ring
    finally:
        reader.close()
        ring.close()


def test_rig_grants_the_plants_frame_without_copying_it(plant):
    rig = Rig(FakeMcu(), plant, port=None, config=RigConfig(quantum_us=5_000, couple_us=1_000))
    rig._capture(0)
    g = rig.grant()
    (blob,) = g.frames
    frame = plant.capture(0)
    assert blob.pixels == frame.tobytes() and blob.pixels.readonly
    assert np.shares_memory(np.frombuffer(blob.pixels, np.uint8), frame)
