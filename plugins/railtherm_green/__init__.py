"""railtherm plugin "green": Ertz & Knothe's analytic (1-D Green function) flash temperatures.

Registers the temperature model :class:`~railtherm_green.model.GreenTemperature` (name ``"green"``)
and the method ``green`` = Hertz patch -> full-sliding (or FASTSIM) heat -> green temperatures.
Heavy work lives in :mod:`railtherm_green.kernel` (strip quadrature), :mod:`railtherm_green.steady`
(long-term wheel temperature) and :mod:`railtherm_green.validity` (Péclet limits, model error).
"""
__version__ = "0.2.0"
