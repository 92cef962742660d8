"""railtherm plugin "fdm": the finite-difference rail block of seed section 6.3.

Registers the temperature model ``fdm`` (:class:`railtherm_fdm.model.FDMTemperature`); method
``fastsim-fdm`` of plugin ``fastsim`` names it (FASTSIM power density -> this block). Modules:

``model``: the stage model (scheme per body, 3-D or 2-D block, the two-body result).
``scheme_choice``: which scheme runs ("auto"), and forced explicit steps beyond the stability limit.
``block3d``, ``block2d``: the block of an elliptical patch (x-y-z) and of a line contact (x-z per unit
width): transient (explicit, implicit) and moving-frame steady solvers.
``layout``, ``source_loading``, ``energy``, ``sampling``, ``linear_solvers``: what both blocks share
(extent, node grid, time steps, graded grid; conservative source loading; heat balance; reading fields
off on the patch grid; backward Euler, CG and GMRES).
``kernels``: the numba kernels (one explicit stencil, compiled parallel and serial).
"""
__version__ = "0.2.0"
