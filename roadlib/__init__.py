"""roadlib: ISO 8608 road surfaces for eroad (knows nothing of vehicles).

Modules: ``psd`` (class table, target spectra, eq 5), ``synthesis`` (harmonic
superposition, eq 3), ``segments`` (segments and junction patches, eq 8),
``surface`` (RoadSurface, .npz/.crg io), ``metrics`` (Welch PSD, ISO fit),
``iri`` (golden-car IRI), ``plot`` and ``cli`` (``eroad road ...``).
See docs/roadlib.md.
"""
