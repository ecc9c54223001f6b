"""The rig's frames without copies: WorldPlant.capture_shared (read-only, the clean image itself)
and the grant's pixels as a read-only view of the frame (mcu_sim/rig.py _pixels): the same
pixels, messages and host arrays as the copies they replace."""

import numpy as np
import pytest
from rig_fakes import FakeMcu, FakePlant

from link import lockstep as ls
from link.frame_ring import FrameRing, FrameRingReader
from mcu_sim.faults.injectors import RunFaults
from mcu_sim.faults.plan import FaultPlan
from mcu_sim.faults.wrappers import FaultedPlant
from mcu_sim.rig import Rig, RigConfig, _pixels
from mcu_sim.rig_plant import WorldPlant
from mcu_sim.world.camera import CameraOptions
from tools.run_job import resolve_scenario


@pytest.fixture(scope="module")
def plant():
    _, scenario = resolve_scenario("paper000-exp1")
    return WorldPlant(scenario, 3)


def test_capture_shared_is_the_capture_read_only(plant):
    shared = plant.capture_shared(0)
    own = plant.capture(0)
    assert np.array_equal(shared, own)
    assert not shared.flags.writeable and own.flags.writeable
    assert not np.shares_memory(shared, own)  # capture's frame is still the caller's
    with pytest.raises(ValueError):
        shared[0, 0, 0] = 1
    assert plant.capture_shared(66_666) is shared  # same pose: the same image, no copy
    # with image options the frame is a new array either way
    plant.options = CameraOptions(noise_std=3.0)
    try:
        noisy = plant.capture_shared(133_333)
        assert noisy.flags.writeable and not np.shares_memory(noisy, shared)
        assert np.array_equal(noisy, plant.capture(133_333))
    finally:
        plant.options = CameraOptions()


def test_faulted_plant_capture_shared(plant):
    quiet = FaultedPlant(plant, RunFaults(FaultPlan(), 1))
    assert quiet.capture_shared(0) is plant.capture_shared(0)
    noisy = FaultedPlant(plant, RunFaults(FaultPlan(camera_noise_std=5.0), 1))
    got = noisy.capture_shared(0)
    assert np.array_equal(got, noisy.capture(0)) and got.flags.writeable
    # a plant without the read-only variant: its own capture
    fake = FakePlant()
    assert np.array_equal(FaultedPlant(fake, RunFaults(FaultPlan(), 1)).capture_shared(0),
                          fake.capture(0))


def test_pixels_view_equals_the_bytes_everywhere(tmp_path):
    rgb = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    view = _pixels(rgb)
    assert view == rgb.tobytes()
    assert view.readonly and len(view) == rgb.nbytes
    as_host = np.frombuffer(view, np.uint8).reshape(4, 6, 3)  # host/lockstep_client.py
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
    frame = plant.capture_shared(0)
    assert blob.pixels == frame.tobytes() and blob.pixels.readonly
    assert np.shares_memory(np.frombuffer(blob.pixels, np.uint8), frame)
