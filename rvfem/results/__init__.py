"""The results of an analysis, typed, one **section** per result (the layer between
:mod:`rvfem.evaluate` and :mod:`rvfem.outputs`).

- :mod:`rvfem.results.analysis`: :class:`~rvfem.results.analysis.Analysis`, everything one analysis
  computed, and the result types with no home in a lower layer;
- :mod:`rvfem.results.section`: what a section declares (:class:`~rvfem.results.section.Section`:
  what it requires, how it is computed, its summary keys and their documentation, its screen lines,
  its report rows, its writers);
- one module per section (``header``, ``warnings``, ``model``, ``references``, ``bearings``,
  ``cycle``, ``stress``, ``mass_strength``, ``hertz``, ``duty_cycle``, ``reducer_stage``,
  ``attribution``, ``roller_depth``, ``bearing_checks``, ``accuracy``, ``files``);
- :mod:`rvfem.results.registry`: the sections listed once, :func:`~rvfem.results.registry.register_section`
  for a section from outside, and the key table of docs/outputs.md generated from the declarations;
- :mod:`rvfem.results.format` and :mod:`rvfem.results.screen_lines`: how numbers are written into
  ``summary.json`` and onto the screen.

The analysis (:func:`rvfem.app.analysis.analyse`) computes the sections in order; the summary
(:func:`rvfem.outputs.summary.build_summary`), the screen (:func:`rvfem.app.screen.summary_text`)
and the report (:mod:`rvfem.outputs.report`) iterate them.
"""
