"""The report's readers read a study file in a child process whose CPU time and memory
are bounded (child_read.read_in_child): a damaged file that makes HDF5 loop, allocate what a
damaged length says or crash ends in one StudyError line naming the file. The reads here
stand in for HDF5's: a loop, an allocation, a crash."""
import os
import resource
import signal
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))

from stepbench_report import child_read  # noqa: E402

LIMITS = (resource.RLIMIT_CPU, resource.RLIMIT_AS, resource.RLIMIT_CORE)


def spin():
    while True:
        pass


def allocate():
    return bytearray(1 << 30)


def crash():
    os.kill(os.getpid(), signal.SIGSEGV)


@pytest.mark.parametrize("read, says", [
    (spin, "damaged: reading it did not end within 1 s of CPU time (HDF5 looping on it)"),
    (allocate, "damaged: reading it needs more than 0.25 GiB of memory"),
    (crash, "damaged: reading it crashes the HDF5 library (SIGSEGV)"),
])
def test_a_read_past_its_bounds_is_one_line_naming_the_file(monkeypatch, read, says):
    monkeypatch.setattr(child_read, "READ_CPU_SECONDS", 1)
    monkeypatch.setattr(child_read, "READ_MEMORY", 256 << 20)
    with pytest.raises(child_read.StudyError) as e:
        child_read.read_in_child("damaged.h5", read)
    assert str(e.value) == f"cannot read study file 'damaged.h5': {says}"


def test_what_the_read_returns_or_raises_comes_back():
    assert child_read.read_in_child("any.h5", lambda: {"rows": [1, 2]}) == {"rows": [1, 2]}
    assert child_read.read_in_child("any.h5", lambda: None) is None  # scan.load of a study without /scan
    with pytest.raises(KeyError, match="scan"):
        child_read.read_in_child("any.h5", lambda: {}["scan"])


def test_the_bounds_are_the_childs_alone():
    before = [resource.getrlimit(r) for r in LIMITS]
    limits = child_read.read_in_child("any.h5", lambda: [resource.getrlimit(r) for r in LIMITS])
    assert limits[0] == (child_read.READ_CPU_SECONDS, child_read.READ_CPU_SECONDS + 1)
    assert limits[1][0] >= child_read.READ_MEMORY and limits[1][0] != resource.RLIM_INFINITY
    assert limits[2][0] == 0
    assert [resource.getrlimit(r) for r in LIMITS] == before
