"""The C host's ARMv4T ELF (make hostc-arm): its self-test under an ARMv4T CPU prints what the
same C built natively prints, and its disassembly holds no instruction newer than ARMv4T."""

import os
import select
import shutil
import signal
import socket
import subprocess
import termios
import threading
from pathlib import Path

import pytest
from c_build_cache import built

from mobigrasp.calib import armhost

ROOT = Path(__file__).resolve().parents[3]
KERNELS = ("radial_symbol", "plus_candidates", "dual_plus", "spoke", "red_roi", "red_cylinder",
           "double_cross", "edge_q4", "sin_cos_q12", "atan2_mrad", "isqrt",
           "floordiv_divround", "ring_pair", "isqrt64_wide", "bezier000", "bezier001_coarse",
           "bezier001_fine", "sys")

needs_arm = pytest.mark.skipif(
    not (shutil.which("arm-none-eabi-gcc") and shutil.which("qemu-arm")),
    reason="arm-none-eabi-gcc and qemu-arm are needed (make arm-tools)")


@pytest.fixture(scope="module")
def elf() -> Path:
    return armhost.build_elf()


@pytest.fixture(scope="module")
def native_lines() -> list[str]:
    """The self-test built with the machine's gcc, on sys.h's libc implementation."""
    protocol = ROOT / "firmware" / "protocol"
    srcs = [str(p) for p in sorted((ROOT / "hostc").glob("*.c")) if p.name != "main.c"]
    command = ["gcc", "-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror",
               f"-I{ROOT / 'hostc'}", f"-I{protocol}", *srcs,
               *map(str, sorted(protocol.glob("*.c"))),
               str(ROOT / "hostc" / "arm" / "selftest_main.c")]
    # the executable of the same sources and compiler comes from the cache
    exe = built("selftest-native", ["gcc"], command, lambda folder: subprocess.run(
        [*command, "-o", str(folder / "selftest")], check=True)) / "selftest"
    done = subprocess.run([str(exe), "--self-test"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout.splitlines()


@needs_arm
def test_self_test_under_armv4t_cpu_equals_native(elf, native_lines):
    done = subprocess.run(["qemu-arm", "-cpu", "ti925t", str(elf), "--self-test"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines == native_lines
    names = [line.split()[0] for line in lines]
    for kernel in KERNELS:
        assert kernel in names
    assert lines[-1] == "failures 0 00000000"
    results = {line.split()[0]: int(line.split()[1]) for line in lines}
    # the drawn markers are found, so the detectors ran to their end
    for found in ("radial_symbol", "dual_plus", "spoke", "red_cylinder", "double_cross"):
        assert results[found] == 1, found
    assert results["bezier000"] >= 0 and results["bezier001_fine"] >= 0  # a curve passes


@needs_arm
def test_elf_usage_error_exits_2(elf):
    done = subprocess.run(["qemu-arm", "-cpu", "ti925t", str(elf), "--bogus"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.startswith("usage:")


@needs_arm
def test_elf_has_no_instruction_newer_than_armv4t(elf):
    dis = armhost.disassemble(elf)
    for sym in ("_start", "sys_poll", "memcpy", "__udivsi3", "__aeabi_ldivmod"):  # libgcc too
        assert f"<{sym}>:" in dis
    # the host's kernels are integer: no soft-float helper is linked
    assert "<__aeabi_dadd>:" not in dis and "<__aeabi_fadd>:" not in dis
    assert len(dis.splitlines()) > 10000
    assert armhost.not_v4t(dis) == []
    attrs = subprocess.run(["arm-none-eabi-readelf", "-A", str(elf)], capture_output=True,
                           text=True, check=True).stdout
    assert "Tag_CPU_arch: v4T" in attrs


@pytest.mark.parametrize("line", [
    "   1000c:\te12fff33 \tblx\tr3",
    "   10008:\te16f1f11 \tclz\tr1, r1",
    "   10010:\te1c040d0 \tldrd\tr4, [r0]",
    "   10010:\te1c040f0 \tstrdne\tr4, [r0]",
    "   1001c:\te1020051 \tqadd\tr0, r1, r2",
    "   1001c:\te1420051 \tqdadd\tr0, r1, r2",
    "   10014:\te1600281 \tsmulbb\tr0, r1, r2",
    "   10014:\te1000281 \tsmlabb\tr0, r1, r2, r0",
    "   10014:\te12002a1 \tsmulwb\tr0, r1, r2",
    "   10018:\tf5d0f000 \tpld\t[r0]",
    "   10018:\te1901f9f \tldrex\tr1, [r0]",
    "   10018:\te1802f91 \tstrex\tr2, r1, [r0]",
    "   10018:\te6bf0f30 \trev\tr0, r0",
    "   10018:\te3000000 \tmovw\tr0, #0",
    "   10018:\te320f000 \tnop\t{0}",
    "   10018:\t4770      \tbx\tlr",
])
def test_check_flags_v5_and_later(line):
    assert armhost.not_v4t(line) == [line.strip()]


@pytest.mark.parametrize("line", [
    "   10000:\te92d4030 \tpush\t{r4, r5, lr}",
    "   10000:\te0c20193 \tsmull\tr0, r2, r3, r1",
    "   10000:\t10ec3190 \tsmlalne\tr3, ip, r0, r1",
    "   10000:\te1d030f2 \tldrsh\tr3, [r0, #2]",
    "   10000:\t14c31001 \tstrbne\tr1, [r3], #1",
    "   10000:\t012fff1e \tbxeq\tlr",
    "   10000:\te1b00a00 \tlsls\tr0, r0, #20",
    "   10000:\tef000000 \tsvc\t0x00000000",
    "   10000:\te1a00000 \tnop\t\t\t@ (mov r0, r0)",
    "   10000:\t00010000 \t.word\t0x00010000",
    "   10000:\te8bd4030 \tpop\t{r4, r5, lr}",
])
def test_check_passes_armv4t(line):
    assert armhost.not_v4t(line) == []


@needs_arm
def test_services_with_peers_under_armv4t_cpu(elf, tmp_path):
    """A pty made raw, a Unix socket and a shared file mapping, through the ELF's own system
    calls: what the peers see and what the ELF reports."""
    master, slave = os.openpty()
    tty = os.ttyname(slave)
    before = termios.tcgetattr(slave)
    assert before[3] & termios.ICANON  # a fresh pty is cooked: the ELF must change that
    shared = tmp_path / "shared.bin"
    page = bytes((i * 7) & 0xFF for i in range(4096))
    shared.write_bytes(page)
    sock_path = str(tmp_path / "s")
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(sock_path)
    server.listen(1)
    server.settimeout(60)
    got = {}

    def serve():
        conn, _ = server.accept()
        with conn:
            conn.settimeout(60)
            got["unix"] = conn.recv(16)
            conn.sendall(got["unix"].upper())

    peer = threading.Thread(target=serve, daemon=True)
    peer.start()
    proc = subprocess.Popen(["qemu-arm", "-cpu", "ti925t", str(elf), "--self-test-io", tty,
                             sock_path, str(shared)], stdout=subprocess.PIPE, text=True)
    try:
        ready, _, _ = select.select([master], [], [], 60)
        assert ready, "no ping on the pty"
        got["tty"] = os.read(master, 16)
        os.write(master, b"pong")
        out, _ = proc.communicate(timeout=60)
        peer.join(60)
        raw = termios.tcgetattr(slave)
    finally:
        proc.kill()
        server.close()
        os.close(master)
        os.close(slave)
    assert proc.returncode == 0, out
    lines = out.splitlines()
    assert "tty_raw 0 00000000" in lines
    assert "tty_read pong" in lines
    assert got["tty"] == b"ping\n"  # OPOST off: no CR added
    iflag, oflag, cflag, lflag, ispeed, ospeed, cc = raw
    assert not lflag & (termios.ICANON | termios.ECHO | termios.ISIG | termios.IEXTEN)
    assert not iflag & (termios.ICRNL | termios.IXON) and not oflag & termios.OPOST
    assert cflag & termios.CSIZE == termios.CS8
    assert not cflag & (termios.PARENB | termios.CSTOPB | termios.CRTSCTS)
    assert ispeed == ospeed == termios.B115200
    assert cc[termios.VMIN] == 1 and cc[termios.VTIME] == 0
    assert got["unix"] == b"hello" and "unix_read HELLO" in lines
    assert f"mmap_sum {sum(page)} 00000000" in lines
    after = shared.read_bytes()
    assert after[100] == 0x5A and after[:100] == page[:100] and after[101:] == page[101:]
    assert lines[-1] == "failures 0 00000000"


@needs_arm
def test_both_checks_catch_an_armv5te_build():
    """The same sources built for the ARM926EJ-S (ARMv5TE): the disassembly check flags
    LDRD/STRD and CLZ, and the ARMv4T CPU stops the self-test on an undefined instruction."""
    flags = "ARM_CFLAGS=-mcpu=arm926ej-s -marm -O2 -std=c99 -ffreestanding"
    # the ELF of the same sources, Makefile and compiler comes from the cache
    elf = built("hostc-armv5te", ["arm-none-eabi-gcc"], ["make hostc-arm", flags],
                lambda folder: subprocess.run(["make", "-s", "-C", str(ROOT), "hostc-arm",
                                               f"HOSTC_OUT={folder}", flags],
                                              check=True, capture_output=True)) / armhost.ELF_NAME
    flagged = {line.split()[2] for line in armhost.not_v4t(armhost.disassemble(elf))}
    assert {"ldrd", "strd", "clz"} <= flagged
    v4t = subprocess.run(["qemu-arm", "-cpu", "ti925t", str(elf), "--self-test"],
                         capture_output=True, timeout=120)
    assert v4t.returncode == -signal.SIGILL or v4t.returncode == 128 + signal.SIGILL
    v5 = subprocess.run(["qemu-arm", "-cpu", "arm926", str(elf), "--self-test"],
                        capture_output=True, timeout=120)
    assert v5.returncode == 0


def test_the_elf_is_built_again_when_a_file_it_is_made_of_changes(tmp_path):
    """The cached ELF's key covers hostc/, the protocol codec it links (firmware/protocol/)
    and the Makefile: a change to any of them is a new key."""
    for part in ("hostc", "firmware/protocol"):
        shutil.copytree(ROOT / part, tmp_path / part)
    shutil.copy(ROOT / "Makefile", tmp_path / "Makefile")
    keys = {armhost.source_hash(tmp_path)}
    assert armhost.source_hash(tmp_path) in keys  # the same files, the same key
    for changed in ("hostc/app.c", "firmware/protocol/cobs.c", "Makefile"):
        with (tmp_path / changed).open("a") as f:
            f.write("\n")
        keys.add(armhost.source_hash(tmp_path))
    assert len(keys) == 4
