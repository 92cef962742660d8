"""railtherm_kalker: Kalker's exact (complete) theory of steady rolling contact on the elastic half-space.

Modules
-------
influence
    Influence coefficients of uniform loads on rectangles (Love, Boussinesq-Cerruti) and strips, FFT products.
potential_area
    The undeformed gap, the potential contact area chosen from it and the border check.
normal_solver
    Vollebregt's FFT-preconditioned conjugate gradients for the normal problem (force or approach prescribed).
tangential_solver
    Steady rolling with creepage: slip, Coulomb's law per element, semismooth Newton-GMRES.
normal_model, tangential_model, plugin
    The stage models ``kalker`` (normal and tangential) and the hooks registering them and the method ``kalker``.
"""
