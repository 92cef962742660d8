"""railtherm plugin "fem": 2-D quasistatic thermoelastic FEM rolling contact (seed paper section 4).

Modules: :mod:`.mesh` (graded strip mesh), :mod:`.elastic` (scikit-fem plane-strain assembly with the
moving-frame term and thermal expansion), :mod:`.condense` (compliance of the contact window),
:mod:`.contact` (Signorini + Coulomb, semismooth Newton), :mod:`.thermal` (moving-frame conduction,
1-D-in-depth and 2-D), :mod:`.coupled` (Steps 1-4), :mod:`.history` (the pass histories of transient
scenes on the fixed section), :mod:`.model` (the CoupledModel "fem").
"""
__version__ = "0.2.0"
