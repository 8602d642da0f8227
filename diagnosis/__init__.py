"""Sim-to-real gap diagnosis: where the gap lies, which unmodelled effect closes it, how far.

Modules: ``signals`` (data container), ``bandpower`` (band powers and their degrees of
freedom), ``fdr`` (multiple testing), ``where`` (localisation), ``compare``
(road-independent comparisons, time-history metrics), ``gap`` (the gap scalar), ``which``
(effect ranking), ``report`` (summary.json, figures, report.md), ``toy`` (a stand-in
simulator for tests).  See docs/diagnosis.md.
"""
