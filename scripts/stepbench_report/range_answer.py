"""The range answers a study file stores with its scans (/scan/<name> `range_answer`:
stepbench computed each when it wrote the scan, as `advise --scan` prints it), read for
--markdown and --readme. Nothing here computes an answer: the README's cut drops lines."""


def _text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def range_answers(path):
    """(name, range answer) of each /scan/<name> that stores one (`range_answer`, written by
    stepbench with the scan), in the file's order; [] without /scan. Read in a child
    process bounded as study.load's are (child_read.py): a damaged file can make HDF5 loop
    or crash; that is a StudyError."""
    from . import child_read
    return child_read.read_in_child(path, lambda: _read_file(path))


def _read_file(path):
    import h5py
    with h5py.File(path, "r") as f:
        if "scan" not in f:
            return []
        return [(name, _text(g.attrs["range_answer"])) for name, g in f["scan"].items()
                if "range_answer" in g.attrs]


def brief_answer(text, hz=60.0):
    """The README's cut of a range answer: its first line, the choice at every rate and,
    of the lines at one step a frame, those at `hz` only (the other rates are in the report)."""
    out = []
    for line in text.rstrip("\n").split("\n"):
        words = line.split()
        one_step = len(words) > 2 and line.startswith("  ") and words[1] == "Hz" and not words[0].endswith(":")
        if one_step and float(words[0]) != hz:
            continue
        if line == "At one step a frame:":
            line = f"At one step a {hz:g} Hz frame (the other rates in the report):"
        out.append(line)
    return "\n".join(out)

