"""tools/heap_tuning: glibc keeps frame-sized blocks in the heap during a run."""

import ctypes

from mobigrasp.cosim import heap_tuning as ht


class _FakeLibc:
    def __init__(self, accept: set[int]) -> None:
        self.calls: list[tuple[int, int]] = []
        self.accept = accept

    def mallopt(self, param, value):
        self.calls.append((param.value, value.value))
        return 1 if param.value in self.accept else 0


def test_every_setting_goes_to_mallopt_and_only_accepted_ones_are_reported():
    libc = _FakeLibc(accept={ht.M_MMAP_THRESHOLD, ht.M_TRIM_THRESHOLD})
    done = ht.keep_freed_memory(libc)
    assert sorted(libc.calls) == sorted(ht.RUN_SETTINGS.items())
    assert done == {ht.M_MMAP_THRESHOLD: 8 << 20, ht.M_TRIM_THRESHOLD: 128 << 20}


def test_a_c_library_without_mallopt_is_left_alone():
    assert ht.keep_freed_memory(object()) == {}


_PROBE = """
import ctypes, sys
from mobigrasp.cosim import heap_tuning as ht
class MallInfo2(ctypes.Structure):
    _fields_ = [(n, ctypes.c_size_t) for n in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks",
                 "uordblks", "fordblks", "keepcost")]
libc = ctypes.CDLL(None)
libc.mallinfo2.restype = MallInfo2
if sys.argv[1] == "tuned":
    assert ht.keep_freed_memory() == ht.RUN_SETTINGS
before = libc.mallinfo2().hblks
frame = bytearray(4 * 320 * 240 * 3)  # four frames' worth
print(libc.mallinfo2().hblks - before)
"""


def test_glibc_serves_frame_sized_blocks_from_the_heap_once_tuned():
    """In a fresh process a 0.9 MB block is an mmap of its own (mallinfo2's hblks counts
    them); after keep_freed_memory it comes from the heap."""
    import subprocess
    import sys
    from pathlib import Path

    assert 4 * 320 * 240 * 3 < ht.RUN_SETTINGS[ht.M_MMAP_THRESHOLD]
    if getattr(ctypes.CDLL(None), "mallinfo2", None) is None:  # not glibc: nothing applied
        assert ht.keep_freed_memory() == {}
        return
    root = Path(__file__).resolve().parents[3]
    out = {mode: subprocess.run([sys.executable, "-c", _PROBE, mode], cwd=root, text=True,
                                capture_output=True, check=True).stdout.strip()
           for mode in ("default", "tuned")}
    assert out == {"default": "1", "tuned": "0"}
