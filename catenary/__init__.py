"""Overhead contact line (catenary) dynamics: finite-element contact line, moving penalty
contact with a lumped collector, closed-form reference solutions and contact statistics.

Bottom layer: imports only numpy, scipy and :mod:`eroad.errors`.  It knows nothing of
vehicles or roads; a pantograph enters as a generic linear collector
(:class:`catenary.contact.Collector`) and its base motion as arrays.
"""
