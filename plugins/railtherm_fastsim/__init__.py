"""railtherm plugin "fastsim": method ``fastsim-fdm`` (seed paper section 6).

Stage models
------------
``fastsim`` (heat source)
    Kalker's FASTSIM on the Hertz patch: tractions, slip, stick/slip, creep forces, spin moment and
    the local frictional power density -p.s (the seed's "modified FASTSIM"). Line contacts: one
    strip with the flexibility that reproduces Carter's linear law (:mod:`.fastsim_line`).
``fdm`` (temperature)
    The 3-D finite-difference rail block: explicit transient (the seed's scheme), implicit, or
    moving-frame steady for stiff cases; for line contacts the 2-D (x-z) block (:mod:`.fdm_line`).

Method ``fastsim-fdm`` chains Hertz -> fastsim -> fdm. The stages stay composable: other methods
may name ``fastsim`` as their heat source.
"""
__version__ = "0.2.0"
