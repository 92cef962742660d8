"""railtherm plugin "fastsim": Kalker's simplified theory and the method ``fastsim-fdm`` (seed paper §6).

Stage models:
``fastsim`` (tangential)
    Kalker's FASTSIM on the patch it is given (:mod:`.tangential`, algorithm in :mod:`.simplified_theory`):
    tractions, slip, stick/slip, creep forces, spin moment and the local dissipation -p.s (the seed's
    "modified FASTSIM", §6.2), which core's ``frictional`` heat source turns into the heat flux. Line
    contacts: one strip reproducing Carter's linear law (:mod:`.fastsim_line`).
``wheelset`` (normal)
    The conical wheelset in a curve of §6.1: the equilibrium that sets each contact's load and
    creepages, then the Hertz patch (:mod:`.wheelset_normal`, kinematics in :mod:`.kinematics`).

Method ``fastsim-fdm`` chains wheelset | hertz -> fastsim -> frictional -> ``fdm``, the finite-difference
temperature model of the separate plugin ``railtherm_fdm``. Other methods name ``fastsim`` as their
tangential model.
"""
__version__ = "0.2.0"
