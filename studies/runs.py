"""The run archive moved to :mod:`eroad.archive` (a base module every layer may use);
this name is kept so existing imports keep working."""
from eroad.archive import *  # noqa: F401,F403
from eroad.archive import __all__  # noqa: F401
