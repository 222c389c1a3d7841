"""A child Python process that runs functions for its parent: pickled calls over its standard input,
pickled results over its standard output.

It is started with ``python -c``, not with :mod:`multiprocessing`, whose "spawn" start method
imports the parent's main module again in the child: a user's script without an
``if __name__ == "__main__"`` guard would run a second time. It serves the P2 model of an analysis
and the render worker (:class:`rvfem.outputs.render.RenderWorker`).
"""

from __future__ import annotations

import contextlib
import logging
import os
import pickle
import struct
import subprocess
import sys
import tempfile
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

log = logging.getLogger(__name__)

HEADER = struct.Struct("<Q")
"""Length prefix of a message (little-endian unsigned 64-bit)."""


def usable_cores() -> int:
    """The cores this process may run on (its affinity where the system says, else the count)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def frame(message) -> bytes:
    """One message pickled and prefixed with its length (what :func:`receive` reads)."""
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    return HEADER.pack(len(data)) + data


def send(stream, message, lock: threading.Lock | None = None) -> None:
    """Write one pickled, length-prefixed message to a binary stream and flush it."""
    data = frame(message)
    with lock if lock is not None else contextlib.nullcontext():
        stream.write(data)
        stream.flush()


def write_quietly(stream, data: bytes) -> None:
    """Write and flush ``data`` to a child's input; a child that is gone (or a closed pipe) is
    left to the reader of its output, which reports how it ended."""
    try:
        stream.write(data)
        stream.flush()
    except (OSError, ValueError, AttributeError):
        pass


def claim_stdout():
    """In a child process: its standard output as a binary stream for the messages to the
    parent, with file descriptor 1 pointed at standard error, so that any other output (of a
    library) cannot corrupt the messages."""
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    return out


def receive(stream):
    """The next message of a stream of :func:`send`, or None at its end."""
    header = stream.read(HEADER.size)
    if len(header) < HEADER.size:
        return None
    (n,) = HEADER.unpack(header)
    data = stream.read(n)
    if len(data) < n:
        return None
    return pickle.loads(data)


def picklable(exc: BaseException, fallback: type[Exception] = RuntimeError) -> BaseException:
    """``exc`` if it survives pickling, else a ``fallback`` exception with its type and message."""
    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:
        return fallback(f"{type(exc).__name__}: {exc}")


_PROGRAM = r"""
import sys
sys.path.insert(0, {root!r})
from rvfem._child import _serve
_serve({niceness!r}, {forward_logs!r})
"""


class ChildProcessEnded(RuntimeError):
    """The child process of a :class:`ChildProcess` ended before it answered a call.

    Attributes
    ----------
    returncode : int or None
        The child's exit code (negative: the signal that ended it).
    stderr : str
        The end of the child's standard error (up to 20 000 characters).
    """

    def __init__(self, message: str, returncode: int | None = None, stderr: str = ""):
        super().__init__(message)
        self.returncode = returncode
        self.stderr = stderr

    def __reduce__(self):
        return type(self), (str(self), self.returncode, self.stderr)


def call_with_keywords(function: Callable, args: tuple, kwargs: dict):
    """``function(*args, **kwargs)``: a call with keyword arguments through :meth:`ChildProcess.call`,
    which passes positional arguments only."""
    return function(*args, **kwargs)


class ChildProcess:
    """A Python child process that runs module-level functions for this one, one call after the
    other, each returning a :class:`concurrent.futures.Future`.

    Parameters
    ----------
    name : str
        What the process is for (in error messages).
    niceness : int
        Added to the child's niceness (Unix ``nice``) before it imports anything: background
        work that should leave the processor to this process where the two compete.
    env : dict, optional
        The child's environment (default: this process's), e.g. a variable a library reads when
        it is imported.
    forward_logs : bool
        Log the child's records of the ``rvfem`` loggers (INFO and above) again in this process,
        under their logger's name; else they go to the child's standard error (kept for the
        message of :class:`ChildProcessEnded`).

    Notes
    -----
    The functions must be importable by name; their arguments and results are pickled. The calls
    are written to the child by a thread of their own, so that :meth:`call` returns at once even
    while the child is still starting. A call made with ``background=True`` runs in a second
    thread of the child, beside the others (the background calls one after the other). An exception of a call is raised by its future's
    ``result()``; once the child has ended, every call not answered raises
    :class:`ChildProcessEnded` with the end of its standard error.
    """

    def __init__(self, name: str, niceness: int = 0, *, env: dict[str, str] | None = None,
                 forward_logs: bool = False):
        self.name = name
        self._stderr = tempfile.TemporaryFile()
        root = str(Path(__file__).resolve().parents[1])
        program = _PROGRAM.format(root=root, niceness=int(niceness), forward_logs=bool(forward_logs))
        try:   # the name as the program's argument: what the process is shows in its command line
            self._proc = subprocess.Popen([sys.executable, "-c", program, name], stdin=subprocess.PIPE,
                                          stdout=subprocess.PIPE, stderr=self._stderr, env=env)
        except BaseException:
            self._stderr.close()
            raise
        self._pending: dict[int, Future] = {}
        self._lock = threading.Lock()
        self._count = 0
        self._ended: ChildProcessEnded | None = None
        self._writer = ThreadPoolExecutor(1, thread_name_prefix=f"rvfem-{name}-writer")
        self._reader = threading.Thread(target=self._read, name=f"rvfem-{name}", daemon=True)
        self._reader.start()

    def call(self, function: Callable, *args, background: bool = False) -> Future:
        """Run ``function(*args)`` in the child process: after the calls before it, or with
        ``background=True`` in the child's second thread (after the background calls before it,
        meanwhile the others)."""
        future: Future = Future()
        with self._lock:
            number = self._count
            data = frame((number, function, args, bool(background)))  # may raise
            if self._ended is not None:
                future.set_exception(self._ended)
                return future
            self._count += 1
            self._pending[number] = future
            self._writer.submit(self._write, data)
        return future

    def _write(self, data: bytes) -> None:
        write_quietly(self._proc.stdin, data)     # a child that is gone: the reader fails the calls

    def _read(self) -> None:
        stream = self._proc.stdout
        try:
            while (message := receive(stream)) is not None:
                kind, number, value = message
                if kind == "log":
                    level, logger, text = value
                    logging.getLogger(logger).log(level, "%s", text)
                    continue
                with self._lock:
                    future = self._pending.pop(number)
                if kind == "ok":
                    future.set_result(value)
                else:
                    future.set_exception(value)
        except Exception as exc:  # pragma: no cover - a message that does not unpickle
            log.error("the %s process sent what cannot be read: %s", self.name, exc)
        finally:
            try:
                self._proc.wait(timeout=5.0)
            except subprocess.TimeoutExpired:  # pragma: no cover - output closed, process alive
                self._proc.kill()
                self._proc.wait()
            self._stderr.seek(0)
            text = self._stderr.read().decode(errors="replace").strip()
            tail = text.splitlines()[-5:]
            ended = ChildProcessEnded(f"the {self.name} process ended (exit code {self._proc.returncode})"
                                      + (": " + " | ".join(tail) if tail else ""),
                                      self._proc.returncode, text[-20000:])
            with self._lock:
                self._ended = ended
                pending, self._pending = list(self._pending.values()), {}
            for future in pending:
                future.set_exception(ended)

    def close(self) -> None:
        """End the child process: at once if it is still running a call (whose future then fails)."""
        self._writer.shutdown(wait=False, cancel_futures=True)   # a write under way finishes
        try:
            if self._proc.stdin is not None:   # always: the child is started with stdin=PIPE
                self._proc.stdin.close()
        except OSError:
            pass
        try:
            self._proc.wait(timeout=0.5)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
        self._reader.join(timeout=10.0)
        if self._proc.stdout is not None:      # always: stdout=PIPE
            self._proc.stdout.close()
        self._stderr.close()

    def __enter__(self) -> ChildProcess:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class SharedWork:
    """Items worked on from both ends: a child process from the front, as soon as they are given,
    and this process from the back once it comes to them (:meth:`finish`), until the two meet.

    For work that a child can start on while this process is busy with something else and that
    this process can help finish: whichever is faster does more, and neither waits for the other
    longer than one item.

    Parameters
    ----------
    items : sequence
        The work, each item independent of the others.
    submit : callable
        ``submit(item)`` → a :class:`concurrent.futures.Future` of its result, computed by the
        child (e.g. ``lambda item: child.call(function, item)``).
    in_flight : int
        Items handed to the child at a time (the next one waits in its pipe while it works).

    Notes
    -----
    An item the child fails (or a child that has ended) is computed by :meth:`finish` in this
    process, and the child is given no more; the reason is logged at INFO level.
    """

    def __init__(self, items, submit: Callable, in_flight: int = 2):
        self._items = list(items)
        self._submit = submit
        self._results: list = [None] * len(self._items)
        self._lock = threading.Lock()
        self._front, self._back = 0, len(self._items)   # the child's next item; one past this process's next
        self._in_flight = 0
        self._idle = threading.Event()
        self._failed: list[int] = []
        self._broken = False
        for _ in range(max(1, in_flight)):
            self._send()

    def _send(self) -> None:
        with self._lock:
            if self._front >= self._back or self._broken:
                if self._in_flight == 0:
                    self._idle.set()
                return
            i = self._front
            self._front += 1
            self._in_flight += 1
        try:
            future = self._submit(self._items[i])
        except Exception as exc:   # noqa: BLE001 - e.g. an item that does not pickle: done here
            future = Future()
            future.set_exception(exc)
        future.add_done_callback(lambda f, i=i: self._received(f, i))

    def _received(self, future: Future, i: int) -> None:
        try:
            self._results[i] = future.result()
        except Exception as exc:   # noqa: BLE001 - computed here instead, the reason logged
            log.info("a child process did not compute its share (%s): this process does", exc)
            with self._lock:
                self._broken = True
                self._failed.append(i)
        with self._lock:
            self._in_flight -= 1
        self._send()

    @property
    def child_count(self) -> int:
        """Items the child was given so far."""
        return self._front

    def finish(self, here: Callable) -> list:
        """The results of every item, in their order: ``here(item)`` on the items the child has not
        taken yet, from the last one backwards, then waiting for the child's last ones."""
        while True:
            with self._lock:
                if self._back <= self._front:
                    break
                self._back -= 1
                i = self._back
            self._results[i] = here(self._items[i])
        with self._lock:
            if self._in_flight == 0:
                self._idle.set()
        self._idle.wait()
        for i in self._failed:
            self._results[i] = here(self._items[i])
        return list(self._results)


class _ForwardLog(logging.Handler):
    """In the child: sends its log records to the parent (:class:`ChildProcess` logs them again)."""

    def __init__(self, stream, lock: threading.Lock):
        super().__init__(logging.INFO)
        self._stream, self._lock = stream, lock

    def emit(self, record: logging.LogRecord) -> None:
        try:
            send(self._stream, ("log", None, (record.levelno, record.name, record.getMessage())), self._lock)
        except Exception:  # pragma: no cover - the parent is gone
            pass


def _serve(niceness: int = 0, forward_logs: bool = False) -> None:
    """The child's loop: run each call received (a background one in a second thread), send its
    result or its exception, until the parent closes the pipe."""
    if niceness and hasattr(os, "nice"):
        os.nice(niceness)
    out = claim_stdout()
    lock = threading.Lock()
    if forward_logs:
        logger = logging.getLogger("rvfem")
        logger.addHandler(_ForwardLog(out, lock))
        logger.setLevel(logging.INFO)
    stream = sys.stdin.buffer
    background = ThreadPoolExecutor(1, thread_name_prefix="rvfem-child-background")

    def run(number: int, function: Callable, args: tuple) -> None:
        try:
            reply = ("ok", number, function(*args))
        except BaseException as exc:  # noqa: BLE001 - every failure goes back to the parent
            reply = ("error", number, picklable(exc))
        try:
            send(out, reply, lock)
        except Exception as exc:  # the result does not pickle
            send(out, ("error", number, RuntimeError(f"the result of {function.__name__} cannot be sent: {exc}")),
                 lock)

    while (message := receive(stream)) is not None:
        number, function, args, in_background = message
        if in_background:
            background.submit(run, number, function, args)
        else:
            run(number, function, args)
    background.shutdown(wait=True)
