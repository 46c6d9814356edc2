"""Evaluation reports, pictures and USD export (issue 5).

* ``footfall report`` (:func:`reports._report.build_report`): the sweep of
  :mod:`reports._sweep` (scenarios x LOD settings x crowd sizes), the quality-vs-cost
  Pareto front and recommended budget (:mod:`reports._pareto`), matplotlib plots
  (:mod:`reports._plots`), pyvista renders in a subprocess (:mod:`reports._render`)
  and one self-contained ``index.html`` (:mod:`reports._html`).
* ``footfall export-usd`` (:func:`reports._usd.export_usd`): a recording
  (:func:`reports._recording.load_recording`, version-checked) as a USD stage.

Importing this package imports nothing heavy; the modules load matplotlib and
pyvista only when used.
"""
