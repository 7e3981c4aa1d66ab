"""Damaged study files never crash a reader.

A small study (`stepbench sweep --quick`, one problem) is copied COPIES times with a
fixed seed, each copy with 1 to 64 random bytes changed or (one in eight) cut short;
every reading command (advise, compare both ways, ratios) reads each copy and must
end by an exit status it documents, never by a signal, with at most one line on
stderr. The report's reader (scripts/stepbench_report/study.py) loads every copy in one
child process, which must end normally too.

usage: fuzz_read_test.py path/to/stepbench COPIES
"""
import os
import random
import signal
import subprocess
import sys
import tempfile

SEED = 16
PROBLEM = "damped_spring"
# What each command may answer with: advise 3 is "no method meets the tolerance", which a
# changed error column can make true.
ALLOWED = {"advise": (0, 1, 2, 3), "compare": (0, 1, 2), "ratios": (0, 1, 2)}
SCRIPTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts")

REPORT_READER = """
import resource, sys
# A damaged string length makes HDF5 allocate what it says: a bound turns that into an
# error instead of gigabytes taken from a shared machine.
resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
sys.path.insert(0, sys.argv[1])
from stepbench_report.study import StudyError, load
for path in sys.argv[2:]:
    print(path, flush=True)
    try:
        load(path)
    except StudyError as e:
        assert "\\n" not in str(e), repr(str(e))
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


def outcome(returncode):
    return f"signal {signal.Signals(-returncode).name}" if returncode < 0 else f"exit {returncode}"


def main():
    stepbench, copies = sys.argv[1], int(sys.argv[2])
    failures = []
    with tempfile.TemporaryDirectory() as work:
        base = os.path.join(work, "base.h5")
        subprocess.run([stepbench, "sweep", "--quick", "--quiet", "--problem", PROBLEM, "--out", base],
                       check=True, stdout=subprocess.DEVNULL)
        with open(base, "rb") as f:
            data = f.read()
        rng = random.Random(SEED)
        paths = []
        for k in range(copies):
            path = os.path.join(work, f"copy{k:03d}.h5")
            with open(path, "wb") as f:
                f.write(mutate(data, rng))
            paths.append(path)
        # In the Sanitize build: HDF5 leaks what it decoded of a damaged object when it
        # refuses it; that is HDF5's to mend, and LeakSanitizer's report of it is not ours.
        suppressions = os.path.join(work, "lsan.supp")
        with open(suppressions, "w") as f:
            f.write("leak:libhdf5\n")
        env = dict(os.environ, LSAN_OPTIONS=f"suppressions={suppressions}:print_suppressions=0")
        counts = {}
        for path in paths:
            for name, args in (("advise", ["advise", "--problem", PROBLEM, "--tol", "1e-6", "--study", path]),
                               ("compare", ["compare", base, path]), ("compare", ["compare", path, base]),
                               ("ratios", ["ratios", "--study", path])):
                run = subprocess.run([stepbench] + args, capture_output=True, text=True, errors="replace", env=env)
                counts[(name, run.returncode)] = counts.get((name, run.returncode), 0) + 1
                lines = run.stderr.splitlines()
                if run.returncode not in ALLOWED[name] or len(lines) > 1:
                    failures.append(f"{' '.join(args)}: {outcome(run.returncode)}, stderr: {run.stderr.strip()!r}")
        report = subprocess.run([sys.executable, "-c", REPORT_READER, SCRIPTS] + paths, capture_output=True,
                                text=True)
        if report.returncode != 0:
            last = report.stdout.split()[-1:] or ["(before the first copy)"]
            failures.append(f"report reader: {outcome(report.returncode)} at {last[0]}: "
                            f"{report.stderr.strip().splitlines()[-1:]}")
        print(f"{copies} damaged copies of a {len(data)}-byte study (seed {SEED}):")
        for (name, code), n in sorted(counts.items()):
            print(f"  {name:8} exit {code}: {n}")
        print(f"  report reader: {outcome(report.returncode)}")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
