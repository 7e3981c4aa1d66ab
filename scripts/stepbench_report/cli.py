"""scripts/report [study.h5] [--out results/report]"""
import argparse
import os
import shutil
import sys
import tempfile
import time

from . import report, study


def main(argv=None, start=None):
    start = time.perf_counter() if start is None else start
    ap = argparse.ArgumentParser(
        prog="report",
        description="Turn a stepbench study file into a report folder: index.html (opens offline), REPORT.md and "
                    "fig/*.png. The folder is replaced whole: it is built beside the target and renamed into place.")
    ap.add_argument("study", nargs="?", default="results/study.h5", help="study file (default: %(default)s)")
    ap.add_argument("--out", default="results/report", help="report folder (default: %(default)s)")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                    help="processes drawing the figures (default: %(default)s)")
    args = ap.parse_args(argv)
    try:
        s = study.load(args.study)
    except study.StudyError as e:
        print(f"report: error: {e}", file=sys.stderr)
        return 1

    out = os.path.abspath(args.out)
    parent = os.path.dirname(out)
    try:
        os.makedirs(parent, exist_ok=True)
        tmp = tempfile.mkdtemp(prefix=f".{os.path.basename(out)}.tmp-", dir=parent)
    except OSError as e:
        print(f"report: error: cannot write report folder '{args.out}': {e.strerror}", file=sys.stderr)
        return 1
    try:
        report.build(s, tmp, workers=max(1, args.jobs))
        os.chmod(tmp, 0o755)  # mkdtemp makes it 0700
        # Swap into place: the old folder moves aside first, so a failure above leaves it
        # untouched and a reader never sees a half-written REPORT.md.
        old = None
        if os.path.lexists(out):
            if not os.path.isdir(out) or os.path.islink(out):
                raise OSError(f"'{args.out}' exists and is not a directory")
            old = tempfile.mkdtemp(prefix=f".{os.path.basename(out)}.old-", dir=parent)
            os.rename(out, os.path.join(old, "report"))
        os.rename(tmp, out)
        if old:
            shutil.rmtree(old, ignore_errors=True)
    except Exception as e:  # one line, and no half-written folder left behind
        shutil.rmtree(tmp, ignore_errors=True)
        if os.environ.get("STEPBENCH_REPORT_DEBUG"):
            raise
        msg = str(e).splitlines()[0] if str(e) else type(e).__name__
        print(f"report: error: {msg}", file=sys.stderr)
        return 1
    elapsed = time.perf_counter() - start
    print(f"report written in {elapsed:.1f} s: {os.path.join(args.out, 'index.html')}, "
          f"{os.path.join(args.out, 'REPORT.md')}")
    return 0
