"""The base of a stage component (:class:`StageComponent`) and the stiffening factor of the
compliance shares (:data:`STIFFEN`), apart from the table of components
(:mod:`rvfem.solve.stage_parts`) so that a component in a module of its own can derive from it and
be listed there (as :mod:`rvfem.solve.stage_pin_housing`, :mod:`rvfem.solve.stage_carrier` and
:mod:`rvfem.solve.stage_main_bearings` are)."""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

from rvfem.case.definition import Case
from rvfem.solve.cycle_stage import ReducerStage

__all__ = ["STIFFEN", "StageComponent"]

STIFFEN = 1.0e3
"""The factor a component is stiffened by to remove its compliance (:func:`stiffened_stage`)."""


class StageComponent:
    """One part of the reducer stage (module docstring). Subclass it, set the class attributes and
    override :meth:`build` (if the part is not already in the disc model or the crankshafts) and
    :meth:`stiffen`.

    Attributes
    ----------
    name : str
        The component's name in the compliance shares (``"disc body"``); unique.
    table : str or None
        The case table it owns (``"pins"``; a new one for a component registered from outside,
        :func:`register_stage_component`); None for a component without one.
    schema : type or None
        The dataclass of that table (its keys, declared with :func:`rvfem.case.schema.param`).
    table_by_default : bool
        For a new table: a case without it has it with its defaults (True), or has no such
        component (False, the default).
    held : str
        How the stage model holds the part, in words (a noun phrase of :func:`held_in_words`).
    step : str or None
        The attribution step that first models the part (``one_disc``, ``two_discs`` or
        ``crankshafts``, or a step of its own named by ``step_label``); None for a part that changes
        no bearing load (a compliance in series with the whole stage): it has no step.
    step_label : str or None
        What its own attribution step adds, in words (None: ``step`` is a built-in step).
    body : bool
        True for the bodies the other parts connect (named first in :func:`held_in_words`).
    models : tuple of str
        The keys of :data:`NOT_MODELLED` it brings into the model (they leave the left-out list).
    """

    name: ClassVar[str]
    table: ClassVar[str | None] = None
    schema: ClassVar[type[Any] | None] = None
    table_by_default: ClassVar[bool] = False
    held: ClassVar[str]
    step: ClassVar[str | None] = None
    step_label: ClassVar[str | None] = None
    body: ClassVar[bool] = False
    models: ClassVar[tuple[str, ...]] = ()

    def parameters(self, case: Case) -> Any:
        """The component's table of ``case`` (a field of the case, or a registered component table),
        or None if the case does not have it; a table there by default (``table_by_default``) that
        the case lacks (read before the table was registered) has its defaults."""
        if self.table is None:
            return None
        if self.table in {f.name for f in dataclasses.fields(Case)}:
            return getattr(case, self.table)
        table = case.component_table(self.table)
        if table is None and self.table_by_default and self.schema is not None:
            return self.schema()        # a case read before the table was registered: its defaults
        return table

    def present(self, case: Case) -> bool:
        """True if ``case`` has the part (its table, where it owns one)."""
        return self.table is None or self.parameters(case) is not None

    def build(self, stage: ReducerStage) -> ReducerStage:
        """The stage with this part added, from the stage's case (``stage.first.case``). The default
        returns the stage as it is: the part is in the disc's model (:func:`build_system`), which the
        stage is made of."""
        return stage

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """The stage with this part :data:`STIFFEN` times stiffer; ValueError where the stage has no
        such compliance to remove."""
        raise ValueError(f"the component {self.name!r} cannot be stiffened")

    def carry(self, before: ReducerStage, after: ReducerStage) -> ReducerStage:
        """``after`` (``before`` with another component stiffened) with this part as ``before`` has
        it, where the other component's stiffening rebuilt what holds it. The default: ``after``
        as it is (the part is carried through by :func:`dataclasses.replace`)."""
        return after
