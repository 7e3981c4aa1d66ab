"""scripts/report [study.h5 | scan.h5] [--out results/report] [--problem P] [--hz H] [--tol X ...]
[--self-contained] [--jobs N] [--markdown FILE] [--readme FILE [--summary results/summary.json]]"""
import argparse
import os
import shlex
import shutil
import signal
import sys
import tempfile
import time
from dataclasses import replace

from . import study

# Written into every report folder; its presence is what allows a later run to replace it.
MARKER = ".stepbench-report"


def _positive_int(text):
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, not '{text}'")
    return value


def _positive(text):
    """A finite number > 0, or None."""
    try:
        value = float(text)
    except ValueError:
        return None
    return value if 0 < value < float("inf") else None


def _tolerances(text):
    """--tol 1e-3 or --tol 1e-2,1e-3: positive numbers."""
    out = [_positive(part) for part in text.split(",")]
    if None in out:
        raise argparse.ArgumentTypeError(f"must be positive numbers (1e-3, or 1e-2,1e-3), not '{text}'")
    return out


def _rate(text):
    value = _positive(text)
    if value is None:
        raise argparse.ArgumentTypeError(f"must be a positive rate in Hz, not '{text}'")
    return value


def _frame_choice(s, args):
    """--hz and --tol checked against what the study's verdict holds (the per-frame answers are
    the study's, never computed here): None, or 2 after one line on stderr."""
    asked = args.hz is not None or args.tol
    if not asked:
        return None
    if s.scan_only or s.verdict is None:
        what = "is a scan file (only /scan)" if s.scan_only else "has no /verdict group"
        print(f"report: error: --hz, --tol: '{args.study}' {what}: it holds no per-frame answers; nothing written",
              file=sys.stderr)
        return 2
    from . import verdict
    try:
        verdict.frame_choice(s.verdict, args.hz, args.tol)
    except verdict.ChoiceError as e:
        print(f"report: error: {e}; nothing written", file=sys.stderr)
        return 2
    return None


def _write_text(path, text):
    """Writes `text` to `path` through a temporary file renamed into place."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.tmp-", dir=folder)
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        if os.path.exists(path):
            os.chmod(tmp, os.stat(path).st_mode & 0o777)
        else:  # what open() would have made (mkstemp makes 0600)
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def _command(argv):
    """The command line as a reader would type it again."""
    return " ".join(["scripts/report"] + [shlex.quote(a) for a in argv])


def _readme_text(args, argv):
    """--readme: README.md with its block rendered from the summary (readme.py); the text, or
    None after one line on stderr."""
    from . import readme, verdict
    try:
        summary = readme.load(args.summary)
        with open(args.readme) as f:
            return verdict.rewrite_block(f.read(), readme.block(summary, _command(argv)))
    except readme.SummaryError as e:
        print(f"report: error: {e}; nothing written", file=sys.stderr)
    except OSError as e:
        print(f"report: error: cannot read '{args.readme}': {e.strerror}; nothing written", file=sys.stderr)
    except ValueError as e:
        print(f"report: error: '{args.readme}': {e}; nothing written", file=sys.stderr)
    return None


def _answers(s, args, argv, readme_text):
    """--markdown and --readme: the verdict as Markdown, the README's block; 0, or 1 with one
    line on stderr."""
    from . import render, verdict
    if args.markdown and s.verdict is None:
        print(f"report: error: '{args.study}' has no /verdict group (a study written before stepbench computed "
              "one): nothing to write; run the study again", file=sys.stderr)
        return 1
    if args.problem is not None and s is not None:
        s = replace(s, verdict=s.verdict.only(args.problem))
    command = _command(argv)
    try:
        if args.markdown:
            _write_text(args.markdown, render.markdown(verdict.results_doc(s, command)))
        if readme_text is not None:
            _write_text(args.readme, readme_text)
    except OSError as e:
        print(f"report: error: cannot write '{e.filename or args.markdown or args.readme}': {e.strerror}",
              file=sys.stderr)
        return 1
    except study.StudyError as e:  # the range answers, read from the file's /scan (range_answer.py)
        print(f"report: error: {e}", file=sys.stderr)
        return 1
    for path in (args.markdown, args.readme):
        if path:
            print(f"report: wrote {path}")
    return 0


def _scene_name(s, study_path, scene_file):
    """The name of the scene the study `s` ran from `scene_file` (its `scenes`: name, path
    as given to stepbench, FNV-1a 64 of the bytes), by the file's real path, or by its file
    name where one scene has it; None after a one-line error."""
    entries = s.attrs.get("scenes", [])
    if not entries:
        print(f"report: error: --scene {scene_file}: '{study_path}' ran no scene file", file=sys.stderr)
        return None
    want = os.path.realpath(scene_file)
    found = [e for e in entries if os.path.realpath(e["path"]) == want]
    if not found:
        found = [e for e in entries if os.path.basename(e["path"]) == os.path.basename(scene_file)]
    if len(found) != 1:
        ran = ", ".join(f"{e['name']} ({e['path']})" for e in entries)
        print(f"report: error: --scene {scene_file}: not one of the study's scene files ({ran})", file=sys.stderr)
        return None
    return found[0]["name"]


def main(argv=None, start=None):
    start = time.perf_counter() if start is None else start
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = argparse.ArgumentParser(
        prog="report",
        description="Turn a stepbench study file into a report folder, a small site that opens offline: "
                    "index.html (the answer a frame at --hz and each --tol first, then the verdict at equal error, "
                    "a line per problem), a page per problem (problems/*.html), a page per study-wide section, "
                    "about.html; REPORT.md (all of it in one document), summary.json and fig/*.png. The folder "
                    "is replaced whole: it is built beside the target and renamed into place. --markdown and --readme write only the verdict tables "
                    "(and the folder too when --out is given). A scan file (`stepbench scan --out`, `stepbench "
                    "merge`: /scan and no problems) gets a report of its scans alone.")
    ap.add_argument("study", nargs="?", default="results/study.h5",
                    help="study file, or scan file (default: %(default)s)")
    ap.add_argument("--out", default=None, help="report folder (default: results/report)")
    ap.add_argument("--problem", metavar="P", help="a report (or --markdown, --readme) of this problem only")
    ap.add_argument("--scene", metavar="FILE", help="a report of the scene this file declares only (as --problem "
                    "with its name: the study's `scenes` record which file each scene came from)")
    ap.add_argument("--hz", type=_rate, default=None, metavar="H",
                    help="the frame rate the index answers for, one the study ran (default: 60 where it ran it)")
    ap.add_argument("--tol", type=_tolerances, action="extend", default=None, metavar="X",
                    help="an error the index answers for, in the problem's unit, one of the study's targets; "
                         "repeat it or give a comma list (default: 1e-2, 1e-3 and 1e-4)")
    ap.add_argument("--self-contained", action="store_true",
                    help="every page carries its figures (data: URIs): no fig/ folder needed")
    ap.add_argument("--jobs", type=_positive_int, default=min(2, os.cpu_count() or 1),
                    help="processes drawing the figures, a positive integer (default: %(default)s)")
    ap.add_argument("--markdown", metavar="FILE", help="write the verdict tables, the findings and where the "
                    "study ran as Markdown to FILE (docs/results.md)")
    ap.add_argument("--readme", metavar="FILE", help="rewrite the block between <!-- results:begin --> and "
                    "<!-- results:end --> in FILE (README.md) with the answer table of the --summary file")
    ap.add_argument("--summary", metavar="FILE", default="results/summary.json",
                    help="the study's summary (`stepbench summary`) that --readme renders (default: %(default)s)")
    args = ap.parse_args(argv)
    readme_text = None
    if args.readme:
        readme_text = _readme_text(args, argv)
        if readme_text is None:
            return 1
        if not args.markdown and args.out is None:  # the block alone: the summary is all it reads
            return _answers(None, args, argv, readme_text)
    try:
        s = study.load(args.study)
    except study.StudyError as e:
        print(f"report: error: {e}", file=sys.stderr)
        return 1
    if args.scene is not None:
        if args.problem is not None:
            print("report: error: give --problem or --scene, not both", file=sys.stderr)
            return 2
        args.problem = _scene_name(s, args.study, args.scene)
        if args.problem is None:
            return 2
    if s.scan_only and args.markdown:
        print(f"report: error: '{args.study}' is a scan file (only /scan, no problems): --markdown writes the verdict "
              "tables of a study file; nothing written", file=sys.stderr)
        return 1
    if s.scan_only and args.problem is not None:
        print(f"report: error: --problem {args.problem}: '{args.study}' is a scan file (only /scan): it has no "
              "problem sections", file=sys.stderr)
        return 2
    if args.problem is not None and args.problem not in [p.name for p in s.problems]:
        print(f"report: error: unknown problem '{args.problem}' (the study has "
              f"{', '.join(p.name for p in s.problems)})", file=sys.stderr)
        return 2
    if (status := _frame_choice(s, args)) is not None:
        return status
    if args.markdown or args.readme:
        status = _answers(s, args, argv, readme_text)
        if status or args.out is None:
            return status
    if args.out is None:
        args.out = "results/report"
    if not args.out.strip():
        print("report: error: --out must name a folder", file=sys.stderr)
        return 1
    for gap in s.gaps:
        print(f"report: warning: incomplete study file: {gap}", file=sys.stderr)
    out = os.path.abspath(args.out)
    parent = os.path.dirname(out)
    # Only a folder this script wrote (it carries MARKER) or an empty one is ever replaced:
    # --out results, --out . or --out ~ must not wipe what is there.
    if os.path.isdir(out) and not os.path.islink(out) and os.listdir(out) and \
            not os.path.exists(os.path.join(out, MARKER)):
        print(f"report: error: '{args.out}' exists and is not a stepbench report folder (no {MARKER}); "
              "name a new or empty folder", file=sys.stderr)
        return 1
    try:
        os.makedirs(parent, exist_ok=True)
        tmp = tempfile.mkdtemp(prefix=f".{os.path.basename(out)}.tmp-", dir=parent)
    except OSError as e:
        print(f"report: error: cannot write report folder '{args.out}': {e.strerror}", file=sys.stderr)
        return 1
    # SIGTERM as well as SIGINT ends the run through the cleanup below, so an interrupted
    # report leaves the previous one in place and no temporary folder behind.
    def interrupted(signum, frame):
        raise KeyboardInterrupt(f"signal {signum}")
    signal.signal(signal.SIGTERM, interrupted)
    old = moved_aside = None
    try:
        # matplotlib is imported only now: a file the report refuses is refused at once.
        from . import report
        report.build(s, tmp, workers=args.jobs, problem=args.problem, self_contained=args.self_contained,
                     hz=args.hz, targets=args.tol)
        with open(os.path.join(tmp, MARKER), "w") as f:
            f.write("This folder is generated by scripts/report and is replaced whole on the next run.\n")
        os.chmod(tmp, 0o755)  # mkdtemp makes it 0700
        # Swap into place: the old folder moves aside first, so a failure above leaves it
        # untouched and a reader never sees a half-written REPORT.md.
        if os.path.lexists(out):
            if not os.path.isdir(out) or os.path.islink(out):
                raise OSError(f"'{args.out}' exists and is not a directory")
            old = tempfile.mkdtemp(prefix=f".{os.path.basename(out)}.old-", dir=parent)
            moved_aside = os.path.join(old, "report")
            os.rename(out, moved_aside)
        os.rename(tmp, out)
        moved_aside = None
        if old:
            shutil.rmtree(old, ignore_errors=True)
        # The new report is in place: the run has done its work, and a signal now would
        # only turn a success into an error status.
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except BaseException as e:  # one line, and nothing half-written left behind or lost
        # Nothing removes the temporary folder before the rename, so its absence means the
        # new report is in place (the signal came after the rename).
        swapped = not os.path.lexists(tmp)
        if moved_aside and not os.path.lexists(out):
            os.rename(moved_aside, out)  # interrupted between the two renames: the old report goes back
        shutil.rmtree(tmp, ignore_errors=True)
        if old:
            shutil.rmtree(old, ignore_errors=True)
        if isinstance(e, KeyboardInterrupt):
            print(f"report: error: interrupted after the new report was in place: '{args.out}' is complete"
                  if swapped else "report: error: interrupted; the previous report is unchanged", file=sys.stderr)
            return 130
        if os.environ.get("STEPBENCH_REPORT_DEBUG"):
            raise
        msg = str(e).splitlines()[0] if str(e) else type(e).__name__
        print(f"report: error: {msg}", file=sys.stderr)
        return 1
    elapsed = time.perf_counter() - start
    print(f"report written in {elapsed:.1f} s: {os.path.join(args.out, 'index.html')}, "
          f"{os.path.join(args.out, 'REPORT.md')}")
    return 0
