"""The suite's own order (tests/conftest.py): the long files it names first are files."""

from pathlib import Path

from conftest import LONG_FILES_FIRST

TESTS = Path(__file__).resolve().parents[1]


def test_the_long_files_run_first_are_test_files_of_the_suite():
    assert [n for n in LONG_FILES_FIRST if not (TESTS / n).is_file()] == []
    assert len(set(LONG_FILES_FIRST)) == len(LONG_FILES_FIRST)
