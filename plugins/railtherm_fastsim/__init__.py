"""railtherm plugin "fastsim": method ``fastsim-fdm`` (seed paper section 6).

Stage models
------------
``fastsim`` (heat source)
    Kalker's FASTSIM on the Hertz patch: tractions, slip, stick/slip, creep forces, spin moment and
    the local frictional power density -p.s (the seed's "modified FASTSIM").
``fdm`` (temperature)
    The 3-D finite-difference rail block: explicit transient (the seed's scheme), implicit, or
    moving-frame steady for stiff cases.

Method ``fastsim-fdm`` chains Hertz -> fastsim -> fdm. The stages stay composable: other methods
may name ``fastsim`` as their heat source.
"""
__version__ = "0.1.0"
