"""Shared pytest configuration.

Matplotlib uses the Agg backend in tests so no display is needed.
"""
import os

os.environ.setdefault("MPLBACKEND", "Agg")
