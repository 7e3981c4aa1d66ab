"""Reading a study file in a child process bounded in CPU time and memory, the way every
reader of the report opens one (study.load, scan.load, range_answer.range_answers).

HDF5 1.10 trusts sizes stored in the file where h5py cannot check them first (a global
heap object's length, an attribute message's size): a damaged file can crash it, make it
loop (a damaged B-tree) or make it allocate what a damaged length says. So the reading
runs in a forked child, which hands back what it read (or the exception) pickled down a
pipe; a child that crashed or ran out of its bounds is a damaged file: a StudyError of
one line naming the file, not a dead or hung report. The bounds are the C++ reader's
(store/study_reader.cpp): a whole study reads in about a second of CPU time and a few
hundred MB, so past them the file is damaged.

A leaf of the package: the modules that read a file import it, it imports none of them.
"""
import faulthandler
import fcntl
import os
import pickle
import resource
import signal

READ_CPU_SECONDS = 20
# Address space the child may map beyond what it was forked with (a bound relative to the
# parent's, so that a large parent, a notebook holding other data, still reads a good file).
READ_MEMORY = 3 << 30  # bytes


class StudyError(Exception):
    """The file is missing, not HDF5, damaged, of another format_version, or lacks
    something the format requires. The message is one line and names the file."""


def error(path, what):
    return StudyError(f"cannot read study file '{path}': {what}")


def read_in_child(path, read):
    """`read()`, which reads the file at `path`, run in a bounded child (start); what it
    returned, or what it raised, or a StudyError (one line, naming the file) when the
    child crashed or ran out of its bounds."""
    result = finish(path, *start(path, read))
    if isinstance(result, Exception):
        raise result
    return result


def start(path, read):
    """Forks a child that calls `read()` on the file `path` within READ_CPU_SECONDS of CPU
    time and READ_MEMORY more address space, and sends what it returned (or the exception
    it raised) pickled down a pipe; (its pid, the pipe). Several may run at once."""
    readable, writable = os.pipe()
    try:  # a full study in a few writes, not the 90 of a pipe's default 64 KiB
        fcntl.fcntl(writable, fcntl.F_SETPIPE_SZ, 1 << 20)
    except (AttributeError, OSError):  # not Linux, or above its /proc/sys/fs/pipe-max-size
        pass
    pid = os.fork()
    if pid == 0:
        status = 1  # whatever happens here, the child ends here and never returns into its parent's code
        try:
            try:
                os.close(readable)
                os.dup2(os.open(os.devnull, os.O_WRONLY), 2)  # HDF5's own diagnostics: the error says it
                faulthandler.disable()  # nor Python's traceback of a crash (pytest's, PYTHONFAULTHANDLER's)
                _bound_this_process()
                # A file `read` opened stays open: the child ends by os._exit, so HDF5 need not
                # spend ~12 ms closing it (freeing every cached object header) before the
                # parent has the study.
                result = read()
            except MemoryError:  # past READ_MEMORY: an allocation of a size the damaged file gave
                result = error(path, f"damaged: reading it needs more than {READ_MEMORY / (1 << 30):g} GiB of memory")
            except Exception as e:  # noqa: BLE001 -- raised again in the parent
                result = e
            with os.fdopen(writable, "wb") as out:
                pickle.dump(result, out, protocol=pickle.HIGHEST_PROTOCOL)
            status = 0
        finally:
            os._exit(status)
    os.close(writable)
    return pid, readable


def finish(path, pid, readable):
    """What the child `pid` (start) sent down `readable`, once it has ended: what `read`
    returned (None too) or raised; a StudyError if it ended before sending it whole: out
    of CPU time (SIGXCPU, or the SIGKILL a second after it), or crashed."""
    with os.fdopen(readable, "rb") as inp:
        try:  # unpickled as it arrives, while the child is still pickling
            result, received = pickle.load(inp), True
        except (EOFError, pickle.UnpicklingError):  # nothing, or not all of it
            result, received = None, False
    status, usage = os.wait4(pid, 0)[1:]
    if os.WIFSIGNALED(status) and (os.WTERMSIG(status) == signal.SIGXCPU or (
            os.WTERMSIG(status) == signal.SIGKILL and usage.ru_utime + usage.ru_stime >= READ_CPU_SECONDS)):
        return error(path, f"damaged: reading it did not end within {READ_CPU_SECONDS} s of CPU time "
                           "(HDF5 looping on it)")
    if os.WIFSIGNALED(status) or not received:
        end = signal.Signals(os.WTERMSIG(status)).name if os.WIFSIGNALED(status) else f"exit {status >> 8}"
        return error(path, f"damaged: reading it crashes the HDF5 library ({end})")
    return result


def _bound_this_process():
    """READ_CPU_SECONDS of CPU time (a forked child starts at none), then SIGXCPU, which
    ends it; READ_MEMORY more address space than it has, past which allocations fail; no
    core file of a child so ended. Lower bounds it inherited are kept."""
    signal.signal(signal.SIGXCPU, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGXCPU})
    # SIGKILL a second later: at a hard limit equal to the soft one Linux sends SIGKILL, not SIGXCPU.
    _lower_limit(resource.RLIMIT_CPU, READ_CPU_SECONDS, READ_CPU_SECONDS + 1)
    try:
        with open("/proc/self/statm") as statm:
            mapped = int(statm.read().split()[0]) * resource.getpagesize()
    except OSError:  # not Linux: no bound on memory
        mapped = None
    if mapped is not None:
        _lower_limit(resource.RLIMIT_AS, mapped + READ_MEMORY, mapped + READ_MEMORY)
    _lower_limit(resource.RLIMIT_CORE, 0, None)


def _lower_limit(which, soft, hard):
    """setrlimit(which) to (soft, hard), or to what it is where that is lower; hard None:
    kept as it is."""
    old_soft, old_hard = resource.getrlimit(which)
    hard = old_hard if hard is None or (old_hard != resource.RLIM_INFINITY and old_hard < hard) else hard
    soft = min(soft, hard) if hard != resource.RLIM_INFINITY else soft
    if old_soft != resource.RLIM_INFINITY:
        soft = min(soft, old_soft)
    resource.setrlimit(which, (soft, hard))
