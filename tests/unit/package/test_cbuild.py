"""The cffi declarations come from the C headers (src/mobigrasp/cbuild.py)."""

import cffi
import pytest

from mobigrasp import cbuild


def test_header_declarations_keep_types_and_drop_inline_bodies(tmp_path):
    (tmp_path / "a.h").write_text(
        "#ifndef A_H\n#define A_H\n#include <stdint.h>\n#define N 4u\n"
        "typedef struct { uint8_t buf[N + 1u]; volatile uint8_t head; } ring_t;\n"
        "static inline uint8_t ring_head(const ring_t *r)\n"
        "{ if (r) { return r->head; } return 0; }\n"
        "enum { A_OK = 0, A_BAD = -1 };\n"
        "int32_t a_sum(const int32_t *v, int32_t n);\n#endif\n")
    (tmp_path / "b.h").write_text('#include "a.h"\n#include "a.h"\nvoid b_go(ring_t *r);\n')
    text = cbuild.header_cdef(("b.h",), [tmp_path])
    assert "ring_head" not in text and "return" not in text
    ffi = cffi.FFI()
    ffi.cdef(text)  # include guard kept it to one copy, and cffi parses it
    assert ffi.sizeof("ring_t") == 6
    assert "a_sum" in text and "b_go" in text


def test_a_header_that_does_not_preprocess_names_it(tmp_path):
    (tmp_path / "bad.h").write_text('#include "missing.h"\n')
    with pytest.raises(cbuild.CBuildError, match="bad.h"):
        cbuild.header_cdef(("bad.h",), [tmp_path])


def test_a_failed_compile_is_the_callers_error(tmp_path):
    class MyError(RuntimeError):
        pass

    def configure(ffi):
        ffi.cdef("int f(int);")
        ffi.set_source("_mg_broken", "int f(int x) { return x +; }")

    with pytest.raises(MyError, match="_mg_broken"):
        cbuild.compile_module("_mg_broken", tmp_path / "out", configure, MyError)
    assert not (tmp_path / "out").exists()
    assert list(tmp_path.iterdir()) == []  # the temporary build folder is gone too


def test_a_part_another_process_is_building_is_waited_for_and_not_built_again(tmp_path):
    """build_once asks again under the lock: a build that finished while this one waited for
    the lock is taken as it is (a parallel test run's workers start on a cold cache together)."""
    import fcntl
    import threading

    target = tmp_path / "part"
    asked, built = threading.Event(), []

    def ready() -> bool:
        now = target.is_dir()
        asked.set()
        return now

    with open(tmp_path / "part.lock", "ab") as held:  # the other process, building
        fcntl.flock(held.fileno(), fcntl.LOCK_EX)
        waiter = threading.Thread(target=cbuild.build_once,
                                  args=(target, ready, lambda: built.append(1)))
        waiter.start()
        assert asked.wait(timeout=60)  # not ready when it first looked
        assert not built  # and it cannot build while the lock is held
        target.mkdir()  # the other build is renamed into place, then lets go of the lock
    waiter.join(timeout=60)
    assert not waiter.is_alive() and built == []
    cbuild.build_once(tmp_path / "new", lambda: (tmp_path / "new").is_dir(),
                      lambda: built.append((tmp_path / "new").mkdir()))
    cbuild.build_once(tmp_path / "new", lambda: (tmp_path / "new").is_dir(),
                      lambda: built.append(2))
    assert built == [None]  # built once, then found
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new", "part"]  # no lock file left
