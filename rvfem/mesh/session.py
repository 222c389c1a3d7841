"""The Gmsh session: the only place where Gmsh's global state is touched, and the options of the
files it writes."""

from __future__ import annotations

import contextlib
import ctypes
import logging
import signal
import threading

import gmsh

from rvfem.errors import MeshError

log = logging.getLogger(__name__)

def _ignore_sigpipe_again() -> None:
    """Undo what ``gmsh.initialize`` does to SIGPIPE when Python ignores it (its default).

    Gmsh sets the signal back to its default action, which ends the process: a write to a pipe
    whose reader is gone (a child process that has ended) would then kill the run instead of
    raising ``BrokenPipeError``. Python's choice is put back for the whole process (from the main
    thread by ``signal``, from another thread by the C library's ``signal``).
    """
    if not hasattr(signal, "SIGPIPE") or signal.getsignal(signal.SIGPIPE) is not signal.SIG_IGN:
        return
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)
        return

    try:
        ctypes.CDLL(None).signal(int(signal.SIGPIPE), ctypes.c_void_p(1))          # SIG_IGN
    except (OSError, AttributeError):  # pragma: no cover - no C library to ask
        log.debug("SIGPIPE left as Gmsh set it")


@contextlib.contextmanager
def gmsh_session(model: str = "disc"):
    """The only place where Gmsh is initialised: yields the ``gmsh`` module with a fresh model.

    Gmsh prints nothing (``General.Terminal = 0``); its messages are collected by its logger and
    appended to any :class:`~rvfem.errors.MeshError` raised inside the block. Gmsh is always
    finalised on leaving, also on errors. Sessions cannot nest (Gmsh has one global state).
    """
    if gmsh.isInitialized():
        raise MeshError("a Gmsh session is already open; Gmsh sessions cannot nest")
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    _ignore_sigpipe_again()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.model.add(model)
        try:
            yield gmsh
        except MeshError:
            raise
        except Exception as exc:  # Gmsh raises plain Exceptions
            log = [m for m in gmsh.logger.get() if m.startswith(("Error", "Warning"))][-5:]
            raise MeshError(f"Gmsh failed: {exc}" + ("\n  " + "\n  ".join(log) if log else "")) from exc
    finally:
        try:
            gmsh.logger.stop()
        finally:
            gmsh.finalize()


def _file_options(g) -> None:
    g.option.setNumber("Mesh.MshFileVersion", 4.1)
    g.option.setNumber("Mesh.Binary", 1)            # exact coordinates on read-back
