"""Damaged scene files never crash stepbench.

The example scenes (examples/scenes/*.toml) are copied COPIES times with a fixed seed,
each copy damaged one way: random bytes changed, the file cut short, a line dropped or
doubled, a number replaced (by nan, inf, a negative, zero, a huge value, a string, an
array), a key misspelt, a table header changed, or binary noise appended. Each copy is
checked (`stepbench scene check FILE`), and the copies it accepts with every eighth it
refuses are run (`stepbench run --scene FILE --method semi_implicit_euler` over 5 ms; the
references only within a work budget, as a scan's, so that a copy made absurdly stiff is
judged on stability alone instead of keeping them busy for a minute). Each must end with
an exit status it documents (0 done, 1 a run or file failure, 2 a bad file), never a signal, with at most
one line on stderr for a refusal, and within a timeout (a hang is a failure).

usage: scene_fuzz_test.py path/to/stepbench path/to/examples/scenes COPIES
"""
import os
import random
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

SEED = 33
TIMEOUT = 120  # s: a run that reaches it is stuck
WORKERS = min(2, os.cpu_count() or 1)
ALLOWED = (0, 1, 2)
REPLACEMENTS = ["nan", "inf", "-inf", "-1.0", "0", "0.0", "1e308", "-1e308", "1e-320", "9223372036854775807",
                "\"text\"", "[]", "[1.0, 2.0, 3.0, 4.0]", "true", "{}"]
KEY_TYPOS = [("stiffness", "stifness"), ("position", "positon"), ("mass", "mas"), ("between", "betwen"),
             ("horizon", "horizn"), ("damping", "dampin"), ("fixed", "fixd"), ("dim", "dims")]


def damage(text, rng):
    """One damaged copy of a scene's text, as bytes."""
    data = bytearray(text.encode())
    kind = rng.randrange(9)
    lines = text.split("\n")
    if kind == 0:  # random bytes changed
        for _ in range(rng.randint(1, 16)):
            data[rng.randrange(len(data))] = rng.randrange(256)
        return bytes(data)
    if kind == 1:  # cut short
        return bytes(data[:rng.randrange(len(data))])
    if kind == 2:  # a line dropped
        del lines[rng.randrange(len(lines))]
    elif kind == 3:  # a line doubled
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
    elif kind in (4, 5):  # a value replaced
        candidates = [i for i, line in enumerate(lines) if "=" in line and not line.lstrip().startswith("#")]
        if candidates:
            i = rng.choice(candidates)
            key = lines[i].split("=", 1)[0]
            lines[i] = key + "= " + rng.choice(REPLACEMENTS)
    elif kind == 6:  # a key misspelt
        good, bad = rng.choice(KEY_TYPOS)
        lines = [line.replace(good, bad, 1) if rng.random() < 0.5 else line for line in lines]
    elif kind == 7:  # a table header changed
        headers = [i for i, line in enumerate(lines) if line.startswith("[")]
        if headers:
            i = rng.choice(headers)
            lines[i] = rng.choice(["[[mass]]", "[[spring]]", "[drag]", "[attraction]", "[[plane]]", "[mass]", "[[dim]]"])
    else:  # binary noise appended
        return bytes(data) + bytes(rng.randrange(256) for _ in range(rng.randint(1, 64)))
    return "\n".join(lines).encode()


def run(cmd):
    """(what went wrong or None, the exit status)."""
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return f"hung (over {TIMEOUT} s): {' '.join(cmd)}", None
    if p.returncode < 0:
        return f"signal {-p.returncode}: {' '.join(cmd)}\n{p.stderr.decode(errors='replace')[-2000:]}", p.returncode
    if p.returncode not in ALLOWED:
        return f"exit {p.returncode}: {' '.join(cmd)}\n{p.stderr.decode(errors='replace')[-2000:]}", p.returncode
    err = p.stderr.decode(errors="replace").strip().splitlines()
    if p.returncode == 2 and len(err) != 1:
        return f"a refusal in {len(err)} lines: {' '.join(cmd)}\n" + "\n".join(err[:5]), p.returncode
    return None, p.returncode


def main():
    stepbench, scenes, copies = sys.argv[1], sys.argv[2], int(sys.argv[3])
    sources = sorted(os.path.join(scenes, f) for f in os.listdir(scenes) if f.endswith(".toml"))
    rng = random.Random(SEED)
    failures, refused = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for k in range(copies):
            with open(rng.choice(sources)) as f:
                text = f.read()
            path = os.path.join(tmp, f"copy{k:03d}.toml")
            with open(path, "wb") as f:
                f.write(damage(text, rng))
            paths.append(path)
        with ThreadPoolExecutor(WORKERS) as pool:
            checks = list(pool.map(run, [[stepbench, "scene", "check", path] for path in paths]))
            # Each copy the check accepted is run; of those it refused (the same reader
            # refuses them in `run`), every eighth, for the refusal through --scene.
            runs = [[stepbench, "run", "--scene", path, "--method", "semi_implicit_euler", "--dt", "1e-3",
                     "--horizon", "0.005", "--reference-budget", "1e6"] for k, (path, (_, status)) in enumerate(zip(paths, checks))
                    if status != 2 or k % 8 == 0]
            for outcome, status in checks + list(pool.map(run, runs)):
                if outcome:
                    failures.append(outcome)
            # How many copies the check refused: the damage reached the reader.
            refused = sum(status == 2 for _, status in checks)
    print(f"{copies} damaged scene files: {refused} refused by scene check, {len(failures)} failures")
    for f in failures[:20]:
        print(f)
    # The damage must reach the reader: most copies are refused (a dropped comment line or
    # a doubled blank one leaves a valid scene).
    if refused < copies // 2:
        print(f"only {refused} of {copies} copies were refused: the damage does not reach the reader")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
