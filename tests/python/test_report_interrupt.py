"""An interrupted report ends: a signal that comes after the figure workers are forked
but before the executor's manager thread starts left nothing to tell the workers to stop,
and the report then waited for them forever at exit (seen once in tests/interrupt_test.sh,
a CI hang). The window is a few microseconds wide, so the test opens it for certain: the
manager thread's start raises KeyboardInterrupt, as cli.py's SIGTERM handler does."""
import os
import subprocess

from conftest import PYTHON, REPORT

INTERRUPT_AT_MANAGER_START = """
import runpy, sys
import concurrent.futures.process as cfp
def interrupted(self):
    raise KeyboardInterrupt("signal 15")
cfp._ExecutorManagerThread.start = interrupted
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


def test_an_interrupt_between_fork_and_manager_thread_ends_the_report(plain_study, tmp_path):
    out = tmp_path / "report"
    out.mkdir()
    (out / "REPORT.md").write_text("previous report\n")
    (out / ".stepbench-report").write_text("a previous report folder\n")
    p = subprocess.run([PYTHON, "-c", INTERRUPT_AT_MANAGER_START, REPORT, str(plain_study), "--out", str(out),
                        "--jobs", "2"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 130, p.stderr
    assert p.stderr.strip().splitlines()[-1] == "report: error: interrupted; the previous report is unchanged", \
        p.stderr
    # The previous report is kept whole, nothing temporary is left beside it.
    assert (out / "REPORT.md").read_text() == "previous report\n"
    assert sorted(os.listdir(tmp_path)) == ["report"]
