"""eroad: multibody-dynamics study tool for heavy vehicles on electrified roads.

This package holds only the command-line entry point and the shared error type;
the science lives in the flat packages ``roadlib``, ``vehicles``, ``drives``,
``inverse``, ``studies`` and ``diagnosis``.
"""
__version__ = "0.1.0"
