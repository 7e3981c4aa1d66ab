"""The range answers a study file stores with its scans (/scan/<name> `range_answer`:
stepbench computed each when it wrote the scan, as `advise --scan` prints it), read for
--markdown (docs/results.md). Nothing here computes an answer."""


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


