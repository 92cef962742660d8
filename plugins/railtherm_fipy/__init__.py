"""railtherm plugin "fipy": finite-volume heat conduction with FiPy.

Registers the temperature stage model ``fipy`` (:class:`railtherm_fipy.model.FipyTemperature`) and
the method ``fipy``: Hertz patch -> full-sliding heat (or FASTSIM when the scene gives creepages and
that plugin is installed) -> FiPy temperatures. FiPy itself is imported only when a model computes
(:func:`railtherm_fipy.solvers.import_fipy`), with the SciPy solver suite and with ``sys.argv``
hidden from FiPy's command-line parsing.
"""
__version__ = "0.2.0"
