"""The P2 model of the stress section, built beside the load cycle: in a child process
(:class:`rvfem._child.ChildProcess`) or on the analysis's background thread, the executor choices
of :func:`rvfem.app.analysis.analyse` for the structural peak's re-solve on P2."""

from __future__ import annotations

import dataclasses
import importlib
import logging
from typing import NamedTuple

import numpy as np

from rvfem._arrays import release_freed_memory
from rvfem._child import ChildProcess, ChildProcessEnded
from rvfem.app.stages import timed as _timed
from rvfem.evaluate import postprocess
from rvfem.solve import models
from rvfem.solve.cycle import AngleLoads, build_system

log = logging.getLogger("rvfem.app.analysis")

__all__ = ["P2_CHILD_NICENESS", "P2Model", "models_in_package", "recover_structural_peak", "start_p2_child"]

def _p2_system(system, mesh):
    """The P2 model of the cycle's disc (same mesh, models and geometry), assembled and factorised."""
    return _build_p2(system.case, mesh, system.bearing_model, system.pin_model, system.geometry)


def _build_p2(case, mesh, bearing_model, pin_model, geometry=None):
    """The P2 model of a case's disc, assembled and factorised; the heap its temporaries leave
    behind is given back (:func:`rvfem._arrays.release_freed_memory`)."""

    system_p2 = build_system(case, mesh, order=2, bearing_model=bearing_model, geometry=geometry,
                             pin_model=pin_model)
    release_freed_memory()
    return system_p2


class _CycleLoads(NamedTuple):
    """The part of a load cycle the P2 recovery reads (:func:`rvfem.evaluate.postprocess.recover_peak`):
    the crank angles and, for the angles it re-solves, their :class:`rvfem.solve.cycle.AngleLoads`."""

    theta: np.ndarray
    solutions: dict


#: The P2 model of the child process of :class:`P2Model` (one per child).
_CHILD_P2: list = []


def _p2_child_build(case, mesh, bearing_model, pin_model, geometry) -> float:
    """In the child process of :class:`P2Model`: build the P2 model; its wall time, s."""
    system_p2, seconds = _timed(_build_p2, case, mesh, bearing_model, pin_model, geometry)
    _CHILD_P2[:] = [system_p2]
    return seconds


def _p2_child_recover(cycle_loads, angles, points, boundaries, band, away, setup):
    """In the child process of :class:`P2Model`: the recovered peak (without its P1 value)."""

    return postprocess.recover_peak(_CHILD_P2[0], cycle_loads, angles, points, boundaries, exclude=band,
                                    p1_peak=away, setup_seconds=setup)


def models_in_package(case) -> bool:
    """Whether the case's bearing and pin models are rvfem's own, which a child process knows too
    (a model registered at run time, by a notebook or a test module, exists in this process only:
    its P2 model is then built on a thread here)."""
    try:
        classes = (models.bearing_model(case.crank_bearing.model), models.pin_model(case.pins.model))
    except KeyError:
        return False
    return all(c.__module__.split(".")[0] == "rvfem" for c in classes)


def start_p2_child():
    """A child process for :class:`P2Model`, already importing what it needs; None where no
    child process can be started (the P2 model is then built on a thread)."""

    try:
        child = ChildProcess("P2 model", niceness=P2_CHILD_NICENESS)
    except OSError as exc:
        log.info("the P2 model is built on a thread (%s)", exc)
        return None
    child.call(_p2_child_imports)
    return child


def _p2_child_imports() -> None:
    """In the child process of :class:`P2Model`: import the modules of the P2 model."""

    for name in ("rvfem.solve.cycle", "rvfem.evaluate.postprocess"):
        importlib.import_module(name)


#: Niceness added to the P2 model's child process (Unix ``nice``): where the two compete for the
#: processor, the mesh, the model and the load cycle go first (the P2 model has the whole cycle's
#: time to be ready).
P2_CHILD_NICENESS = 10


class P2Model:
    """The P2 model of a P1 cycle's disc (same mesh and models), built beside the load cycle.

    It is built in a child process (:class:`rvfem._child.ChildProcess`): its assembly and
    factorisation would otherwise take turns with the load cycle in this interpreter (CHOLMOD
    through cholespy holds it), and its few hundred MB stay out of this process. The angles to
    re-solve go there as :class:`rvfem.solve.cycle.AngleLoads`, the recovered peak comes back. Without a
    ``child`` (none could be started), the model is built on the ``background`` thread from
    :meth:`start` and used here.
    """

    def __init__(self, system, mesh, background, child=None):
        self._child = child
        self._pending = None
        if child is not None:
            self._built = child.call(_p2_child_build, system.case, mesh, system.bearing_model, system.pin_model,
                                     system.geometry)     # one message: the geometry's case is the case
        else:
            self._built, self._pending = None, (background, system, mesh)

    def start(self) -> None:
        """Start the build on the background thread (without a child; once). Called when the cycle
        has solved its first angle: its compliance columns are computed by then, and the two would
        only take turns in this interpreter (cholespy holds it)."""
        if self._pending is not None:
            background, system, mesh = self._pending
            self._pending = None
            self._built = background.submit(_timed, _p2_system, system, mesh)

    def recover_in_child(self, system, cycle, angles, mesh, band, away):
        """:func:`rvfem.evaluate.postprocess.recover_peak` made in the child process, with the P1 value at
        the peak added here; None without a child, or when it has ended (e.g. ended by the system
        for want of memory: the P2 model is then built here, :meth:`model`)."""

        if self._child is None:
            return None
        try:
            setup = self._built.result()
            ks = {postprocess.nearest_index(cycle.theta, float(a)) for a in angles}
            roots: dict = {}
            loads = _CycleLoads(np.asarray(cycle.theta), {k: AngleLoads.of(cycle.solutions[k], roots) for k in ks})
            recovered = self._child.call(_p2_child_recover, loads, angles, mesh.points, mesh.boundaries, band,
                                         away, setup).result()
        except ChildProcessEnded as exc:
            log.warning("%s; the P2 model is built here instead", exc)
            self._child.close()             # its pipes and reader now (closing again is harmless)
            self._child, self._built = None, None
            return None
        return dataclasses.replace(recovered, p1_at_peak_MPa=postprocess.p1_stress_at(system, cycle, recovered.peak))

    def model(self, system, mesh):
        """The P2 model in this process and the time it took, s: the one the ``background`` thread
        built, or one built now."""
        if self._built is not None:
            return self._built.result()
        return _timed(_p2_system, system, mesh)

    def close(self) -> None:
        """End the child process (its P2 model with it)."""
        if self._child is not None:
            self._child.close()


def recover_structural_peak(system, cycle, mesh, band, away, p2=None):
    """The structural peak recovered on P2 (:func:`rvfem.evaluate.postprocess.recover_peak`) at the P1
    envelope's peak angles. The P2 model of the same mesh is ``p2`` (a :class:`P2Model`, built
    beside the load cycle) or built here, or is the cycle's own for a P2 case."""

    angles = postprocess.peak_angles(cycle, mesh.points, mesh.boundaries, exclude=band)
    if system.model.order == 2:
        system_p2, system_p1, setup = system, None, 0.0
    elif p2 is None:
        (system_p2, setup), system_p1 = _timed(_p2_system, system, mesh), system
    elif (recovered := p2.recover_in_child(system, cycle, angles, mesh, band, away)) is not None:
        return recovered
    else:
        (system_p2, setup), system_p1 = p2.model(system, mesh), system
    return postprocess.recover_peak(system_p2, cycle, angles, mesh.points, mesh.boundaries, exclude=band,
                                    p1_peak=away, system_p1=system_p1, setup_seconds=setup)
