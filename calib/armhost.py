"""The C host as a static ARMv4T Linux ELF (``make hostc-arm``), built into the cache, and the
check that no instruction in it is newer than the ARM920T's ARMv4T.

``build_elf()`` runs the Makefile's ``hostc-arm`` target with its output in the cache of the C
parts (``$MOBIGRASP_CACHE_DIR/hostc-arm/<hash of hostc/ and the Makefile>``), so the flags live
in one place. ``not_v4t(disassembly)`` lists the lines of ``arm-none-eabi-objdump -d`` whose
mnemonic is not an ARMv4T ARM-state instruction: an allow-list (ARM DDI 0100E, the ARMv4T
instruction set: data processing, MUL/MLA and the long multiplies, LDR/STR with the byte,
halfword and signed forms, LDM/STM, SWP, B/BL/BX, SWI, MRS/MSR, the coprocessor instructions),
so BLX, CLZ, LDRD/STRD, the saturating and DSP multiplies, PLD, LDREX/STREX and every later
addition are flagged without being named one by one.
"""

from __future__ import annotations

import hashlib
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

from mobigrasp import cbuild
from mobigrasp.calib.arm import ToolchainError
from mobigrasp.provenance import source_checkout

# built by the clone's Makefile (make hostc-arm): the checkout the package is imported from
ROOT = source_checkout() or Path.cwd()
HOSTC = ROOT / "hostc"
ELF_NAME = "mobigrasp-host-arm920t.elf"
OBJDUMP = "arm-none-eabi-objdump"

_COND = r"(?:eq|ne|cs|hs|cc|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?"
# ARMv4T ARM-state mnemonics as objdump spells them (unified syntax), without the condition
_V4T = (
    r"(?:and|eor|sub|rsb|add|adc|sbc|rsc|orr|mov|bic|mvn|lsl|lsr|asr|ror|rrx|mul|mla"
    r"|umull|umlal|smull|smlal)s?"
    r"|tst|teq|cmp|cmn|adr"
    r"|(?:ldr|str)(?:b|h|sb|sh|t|bt)?"
    r"|(?:ldm|stm)(?:ia|ib|da|db|fd|ed|fa|ea)?|push|pop"
    r"|swpb?|b|bl|bx|svc|swi|mrs|msr|cdp|ldcl?|stcl?|mcr|mrc"
)
_ALLOWED = re.compile(rf"(?:{_V4T}){_COND}")
# Data in the text (literal pools) and the permanently undefined instruction, which gcc puts
# where a path is undefined behaviour (__builtin_trap): undefined on every ARM, v4T included.
_DATA = {".word", ".short", ".byte", "udf"}
_INSN = re.compile(r"^\s*[0-9a-f]+:\s+([0-9a-f]{8}|[0-9a-f]{4})\s+(\S+)")
NOP_WORD = "e1a00000"  # mov r0, r0, which objdump prints as nop


def not_v4t(disassembly: str) -> list[str]:
    """The instruction lines of ``disassembly`` that are not ARMv4T ARM-state instructions."""
    bad = []
    for line in disassembly.splitlines():
        m = _INSN.match(line)
        if not m:
            continue
        word, mnemonic = m.group(1), m.group(2).lower()
        if mnemonic in _DATA or (mnemonic == "nop" and word == NOP_WORD):
            continue
        if len(word) != 8 or not _ALLOWED.fullmatch(mnemonic):
            bad.append(line.strip())
    return bad


def source_hash(root: Path = ROOT) -> str:
    """Hash of every file under hostc/ and firmware/protocol/ (the codec the ELF links) and of
    the Makefile in ``root`` (the ELF's cache key)."""
    h = hashlib.sha256()
    for top in (root / "hostc", root / "firmware" / "protocol"):
        for p in sorted(q for q in top.rglob("*") if q.is_file()):
            h.update(str(p.relative_to(root)).encode() + b"\0" + p.read_bytes())
    h.update((root / "Makefile").read_bytes())
    return h.hexdigest()[:16]


def build_elf(keep: tuple[str, ...] = ()) -> Path:
    """The ELF of ``make hostc-arm`` for the current sources, built into the cache first;
    ``keep``: functions the program never calls kept in it (``HOSTC_ARM_KEEP``: the
    calibration's entries), an ELF of its own."""
    key = source_hash() if not keep else hashlib.sha256(
        (source_hash() + " ".join(keep)).encode()).hexdigest()[:16]
    target = cbuild.cache_root() / ("hostc-arm" if not keep else "hostc-arm-keep") / key
    elf = target / ELF_NAME
    cbuild.build_once(target, elf.is_file, lambda: _make_elf(target, keep))
    return elf


def _make_elf(target: Path, keep: tuple[str, ...]) -> None:
    if shutil.which("make") is None:
        raise ToolchainError("make not found: the ARM host is built by make hostc-arm")
    tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
    try:
        done = subprocess.run(["make", "-s", "-C", str(ROOT), "hostc-arm", f"HOSTC_OUT={tmp}",
                               f"HOSTC_ARM_KEEP={' '.join(keep)}"],
                              capture_output=True, text=True, check=False)
        if done.returncode != 0 or not (tmp / ELF_NAME).is_file():
            last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
            raise ToolchainError(f"make hostc-arm failed: {last}")
        cbuild.rename_into_place(tmp, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def disassemble(elf: Path) -> str:
    """``arm-none-eabi-objdump -d`` of ``elf``."""
    if shutil.which(OBJDUMP) is None:
        raise ToolchainError(f"{OBJDUMP} not found (make arm-tools)")
    return subprocess.run([OBJDUMP, "-d", str(elf)], capture_output=True, text=True,
                          check=True).stdout
