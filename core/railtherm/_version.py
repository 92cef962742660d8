"""The version of railtherm (imported by the modules that stamp it on results; imports nothing)."""
__version__ = "0.2.0"
