"""The avr-gcc build: `make firmware` gives an ELF without a warning that fits the ATmega128
(flash <= 128 KB; .data + .bss + worst-case stack <= 4096 bytes), and its figures are exactly
those mcu_sim/firmware/sram.py declares (python -m mobigrasp.tools.firmware_budget --write
updates that file from the build)."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from mobigrasp.mcu_sim.firmware import sram
from mobigrasp.tools import firmware_budget as fb

ROOT = Path(__file__).resolve().parents[3]


def _avr_toolchain() -> None:
    if shutil.which("avr-gcc") and shutil.which("avr-size"):
        return
    if os.geteuid() != 0 or shutil.which("apt-get") is None:
        pytest.skip("avr-gcc is missing and apt-get cannot run here to install gcc-avr avr-libc")
    res = subprocess.run(["make", "-C", str(ROOT), "firmware"], capture_output=True, text=True)
    if res.returncode != 0 or not shutil.which("avr-gcc"):
        pytest.skip(f"apt-get could not install gcc-avr avr-libc: {res.stderr.strip()[-200:]}")


@pytest.fixture(scope="module")
def build(tmp_path_factory):
    _avr_toolchain()
    out = tmp_path_factory.mktemp("avr-build")
    res = subprocess.run(["make", "-s", "-C", str(ROOT / "firmware"), f"BUILD={out}"],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert "warning" not in res.stderr.lower(), res.stderr
    assert "Program:" in res.stdout and "Data:" in res.stdout  # avr-size -C printed
    return out


def test_elf_fits_the_part(build):
    b = fb.analyse(build)
    assert (build / "mobigrasp-avr.hex").is_file()
    assert b.flash_bytes <= 128 * 1024
    assert b.sram_bytes == b.data_bytes + b.bss_bytes + b.main_stack_bytes + b.isr_stack_bytes
    assert b.sram_bytes <= 4096


def test_sram_py_is_the_build(build):
    b = fb.analyse(build)
    assert b.symbols == sram.SRAM_LAYOUT, "run python -m mobigrasp.tools.firmware_budget --write"
    assert b.data_bytes + b.bss_bytes == sram.DATA_BSS_BYTES
    assert (b.main_stack_bytes, b.isr_stack_bytes) == (sram.STACK_MAIN_BYTES,
                                                       sram.STACK_ISR_BYTES)
    assert b.flash_bytes == sram.FLASH_BYTES_USED
    assert fb.doc_table(b) in fb.DOC.read_text()


def test_stack_analysis_refuses_recursion_and_indirect_calls():
    dis = ("00000010 <a>:\n  10:\t0e 94 10 00 \tcall\t0x20\t; 0x20 <b>\n"
           "00000020 <b>:\n  20:\t0e 94 08 00 \tcall\t0x10\t; 0x10 <a>\n")
    graph = fb.call_graph(dis)
    with pytest.raises(fb.BudgetError, match="recursion"):
        fb.worst_stack("a", graph, {"a": 4, "b": 4}, {})
    with pytest.raises(fb.BudgetError, match="indirect"):
        fb.call_graph("00000010 <f>:\n  10:\t09 95       \ticall\n")


def test_stack_is_the_deepest_chain_plus_the_deepest_handler():
    dis = ("00000010 <main>:\n  10:\t0e 94 10 00 \tcall\t0x20\t; 0x20 <deep>\n"
           "  14:\t0e 94 10 00 \tcall\t0x30\t; 0x30 <shallow>\n"
           "00000020 <deep>:\n  20:\t0e 94 10 00 \tcall\t0x40\t; 0x40 <__mulsi3>\n"
           "00000030 <shallow>:\n  30:\t08 95       \tret\n")
    graph = fb.call_graph(dis)
    frames = {"main": 2, "deep": 30, "shallow": 50}
    assert fb.worst_stack("main", graph, frames, {}) == 2 + max(30 + fb.LIBRARY_FRAME_BYTES, 50)
