"""Damaged study files never crash a reader.

A small study (`stepbench sweep --quick`, one problem) is copied COPIES times with a
fixed seed, each copy with 1 to 64 random bytes changed or (one in eight) cut short;
the reading commands (advise, compare, ratios) read the copies in turn, and each must
end by an exit status it documents, never by a signal, with at most one line on
stderr; so must `advise --scan` on as many damaged copies of a small scan file
(seed SEED + 1), and `merge` of a quarter as many damaged copies of a study shard with
the other, intact shard (seed SEED + 2; a merge it made prints its summary). The
report's readers (scripts/stepbench_report: study.load, and on a copy it accepts
scan.load and the range answers, as the report reads them) read every copy in one child
process, which must end normally too, each refusal one line naming the copy.
No run may hang: each has a timeout, past which it is a failure. The runs go two at a
time (WORKERS).

usage: fuzz_read_test.py path/to/stepbench COPIES
"""
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

SEED = 16
PROBLEM = "damped_spring"
# What each command may answer with: advise 3 is "no method meets the tolerance", which a
# changed error column can make true.
ALLOWED = {"advise": (0, 1, 2, 3), "compare": (0, 1, 2), "ratios": (0, 1, 2), "advise --scan": (0, 1, 2, 3),
           "merge": (0, 1, 2)}
SCAN = ["--problem", "stiff_spring", "--param", "stiff_spring.k_s=1e1:1e3:3:log", "--hz", "60", "--substeps", "1"]
SCRIPTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts")

# Runs at once: the commands of different copies and the report's reader. Each reads a
# copy in well under a second, so two keep two cores busy; more only share them.
WORKERS = min(2, os.cpu_count() or 1)
# Wall-clock bounds past which a run is a hang. Each reader bounds its own reading of a
# file to 20 s of CPU time (the report's reader here to REPORT_CPU_SECONDS), so a run that
# reaches these is stuck where no bound reaches it.
COMMAND_TIMEOUT = 120  # s
REPORT_TIMEOUT_PER_COPY = 3  # s, beside REPORT_TIMEOUT_BASE
REPORT_TIMEOUT_BASE = 60  # s
# The report reader's bounds in this test (child_read.READ_CPU_SECONDS, READ_MEMORY):
# tighter than a user's 20 s and 3 GiB, the same code paths. The copies are of a 1.5 MB
# study that reads in 0.1 s and under 100 MB, and a copy that makes HDF5 allocate up to
# 3 GiB spends 10 to 15 s doing it (three such among 200 copies at seed 16).
REPORT_CPU_SECONDS = 5
REPORT_MEMORY = 512 << 20  # bytes

REPORT_READER = """
import sys
sys.path.insert(0, sys.argv[1])
cpu_seconds, memory = int(sys.argv[2]), int(sys.argv[3])
from stepbench_report import child_read, range_answer, scan, study
child_read.READ_CPU_SECONDS, child_read.READ_MEMORY = cpu_seconds, memory
for path in sys.argv[4:]:
    print(path, flush=True)
    try:
        study.load(path)
        # What the report reads beside the study once study.load accepted the file:
        # /scan, and for --markdown and --readme the range answers (which verdict.py
        # reads as none on OSError and KeyError).
        scan.load(path)
        try:
            range_answer.range_answers(path)
        except (OSError, KeyError):
            pass
    except study.StudyError as e:
        assert "\\n" not in str(e) and f"'{path}'" in str(e), repr(str(e))
"""


def mutate(data, rng):
    """A copy of `data` with 1 to 64 random bytes changed, or cut short."""
    if rng.random() < 1 / 8:
        return data[:rng.randrange(len(data))]
    out = bytearray(data)
    for _ in range(rng.randint(1, 64)):
        i = rng.randrange(len(out))
        out[i] = (out[i] + rng.randint(1, 255)) % 256
    return bytes(out)


def run(command, timeout, env=None):
    """The finished `command` (stdout and stderr as text); returncode None when it did not
    end within `timeout` seconds (it is killed)."""
    try:
        return subprocess.run(command, capture_output=True, text=True, errors="replace", env=env, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        text = [b.decode(errors="replace") if isinstance(b, bytes) else b or "" for b in (e.stdout, e.stderr)]
        return subprocess.CompletedProcess(command, None, *text)


def outcome(done, timeout):
    if done.returncode is None:
        return f"no end within {timeout} s (a hang)"
    return f"signal {signal.Signals(-done.returncode).name}" if done.returncode < 0 else f"exit {done.returncode}"


def main():
    stepbench, copies = sys.argv[1], int(sys.argv[2])
    failures = []
    with tempfile.TemporaryDirectory() as work:
        base = os.path.join(work, "base.h5")
        subprocess.run([stepbench, "sweep", "--quick", "--quiet", "--problem", PROBLEM, "--out", base],
                       check=True, stdout=subprocess.DEVNULL)
        scan_base = os.path.join(work, "scan.h5")
        subprocess.run([stepbench, "scan", *SCAN, "--quiet", "--out", scan_base], check=True, stdout=subprocess.DEVNULL)
        # The two shards of a two-problem study: merge reads a damaged copy of the first
        # with the second.
        shards = [os.path.join(work, f"shard{k}.h5") for k in (1, 2)]
        for k, shard in enumerate(shards, 1):
            subprocess.run([stepbench, "sweep", "--quick", "--quiet", "--problem", PROBLEM, "--problem", "projectile",
                            "--shard", f"{k}/2", "--out", shard], check=True, stdout=subprocess.DEVNULL)
        with open(base, "rb") as f:
            data = f.read()
        with open(scan_base, "rb") as f:
            scan_data = f.read()
        with open(shards[0], "rb") as f:
            shard_data = f.read()
        # One random stream a file, so that the study's copies are those of the seed alone.
        paths, scan_paths, shard_paths = [], [], []
        for name, original, into, seed, n in (("copy", data, paths, SEED, copies),
                                              ("scan", scan_data, scan_paths, SEED + 1, copies),
                                              ("shard", shard_data, shard_paths, SEED + 2, copies // 4)):
            rng = random.Random(seed)
            for k in range(n):
                path = os.path.join(work, f"{name}{k:03d}.h5")
                with open(path, "wb") as f:
                    f.write(mutate(original, rng))
                into.append(path)
        # In the Sanitize build: HDF5 leaks what it decoded of a damaged object when it
        # refuses it; that is HDF5's to mend, and LeakSanitizer's report of it is not ours.
        suppressions = os.path.join(work, "lsan.supp")
        with open(suppressions, "w") as f:
            f.write("leak:libhdf5\n")
        # And the child's memory bound, which the reader cannot set under AddressSanitizer
        # (it reserves terabytes of address space): an allocation HDF5 sizes from a damaged
        # length fails past 1 GiB, as it would past the Release build's bound, instead of
        # taking gigabytes (4.55 GB, CI's largest process, with the scan copies).
        env = dict(os.environ, LSAN_OPTIONS=f"suppressions={suppressions}:print_suppressions=0",
                   ASAN_OPTIONS="allocator_may_return_null=1:max_allocation_size_mb=1024")
        # The three commands read a study with the one reader (read_studies), so each copy
        # is read by one of them in turn, and the reader reads every copy; compare reads
        # it as the new study or (every other time) as the base. (Every command on every
        # copy was three times the runs for the same reads: 159 s of CI's 32 min.)
        def study_command(k, path):
            if k % 3 == 0:
                return "advise", ["advise", "--problem", PROBLEM, "--tol", "1e-6", "--study", path]
            if k % 3 == 1:
                return "compare", ["compare", base, path] if k % 2 == 0 else ["compare", path, base]
            return "ratios", ["ratios", "--study", path]
        commands = [study_command(k, path) for k, path in enumerate(paths)] + \
            [("advise --scan", ["advise", "--scan", path, "--tol", "1e-3"]) for path in scan_paths] + \
            [("merge", ["merge", *((path, shards[1]) if k % 2 == 0 else (shards[1], path)), "-o",
                        os.path.join(work, "merged.h5")]) for k, path in enumerate(shard_paths)]
        report_timeout = REPORT_TIMEOUT_BASE + REPORT_TIMEOUT_PER_COPY * copies
        start = time.monotonic()
        with ThreadPoolExecutor(WORKERS) as pool:
            # The report reader first: the longest run, the commands fill the other worker.
            report = pool.submit(run, [sys.executable, "-c", REPORT_READER, SCRIPTS, str(REPORT_CPU_SECONDS),
                                       str(REPORT_MEMORY)] + paths, report_timeout)
            runs = pool.map(lambda command: run([stepbench] + command[1], COMMAND_TIMEOUT, env), commands)
            counts = {}
            for (name, args), done in zip(commands, runs):
                key = (name, outcome(done, COMMAND_TIMEOUT))
                counts[key] = counts.get(key, 0) + 1
                # One line on stderr, but for merge's summary of a merge it made.
                lines = len(done.stderr.splitlines())
                if done.returncode not in ALLOWED[name] or (lines > 1 and (done.returncode != 0 or name != "merge")):
                    failures.append(f"{' '.join(args)}: {outcome(done, COMMAND_TIMEOUT)}, "
                                    f"stderr: {done.stderr.strip()!r}")
            report = report.result()
        if report.returncode != 0:
            last = report.stdout.split()[-1:] or ["(before the first copy)"]
            failures.append(f"report reader: {outcome(report, report_timeout)} at {last[0]}: "
                            f"{report.stderr.strip().splitlines()[-1:]}")
        print(f"{copies} damaged copies of a {len(data)}-byte study and of a {len(scan_data)}-byte scan file, "
              f"{len(shard_paths)} of a {len(shard_data)}-byte study shard (seed {SEED}), read in "
              f"{time.monotonic() - start:.0f} s by {WORKERS} workers:")
        for (name, end), n in sorted(counts.items()):
            print(f"  {name:13} {end}: {n}")
        print(f"  report reader: {outcome(report, report_timeout)}")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
