"""railtherm plugin "fdm" (work in progress)."""
__version__ = "0.2.0"
