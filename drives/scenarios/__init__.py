"""Built-in scenario files of ``eroad synth`` (TOML; see docs/measurement.md)."""
