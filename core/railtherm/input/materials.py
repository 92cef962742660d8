"""Material (body) properties of wheel and rail."""
from __future__ import annotations

import math
from dataclasses import dataclass, field, asdict


@dataclass(frozen=True)
class Material:
    """Elastic and thermal properties of one body, SI units.

    Parameters
    ----------
    shear_modulus : float
        Shear modulus G [Pa].
    poisson_ratio : float
        Poisson's ratio nu [1], 0 <= nu < 0.5.
    density : float
        Mass density rho [kg/m^3].
    specific_heat : float
        Specific heat c [J/(kg K)].
    conductivity : float
        Thermal conductivity lambda [W/(m K)].
    thermal_expansion : float
        Linear thermal expansion coefficient alpha [1/K].
    bulk_temperature : float
        Bulk (initial / far-field) temperature [degC].
    radius : float
        Rolling radius of the body [m] (used by convection and transient wheel heating).
    rigid : bool
        Treat the body as rigid (paper section 4: rigid wheel on an elastic strip).
    """

    shear_modulus: float = 82e9
    poisson_ratio: float = 0.28
    density: float = 7850.0
    specific_heat: float = 450.0
    conductivity: float = 50.0
    thermal_expansion: float = 12e-6
    bulk_temperature: float = 0.0
    radius: float = 0.46
    rigid: bool = False

    @property
    def youngs_modulus(self) -> float:
        """Young's modulus E = 2 G (1 + nu) [Pa]."""
        return 2.0 * self.shear_modulus * (1.0 + self.poisson_ratio)

    @property
    def lame_lambda(self) -> float:
        """First Lamé parameter [Pa]."""
        nu = self.poisson_ratio
        return 2.0 * self.shear_modulus * nu / (1.0 - 2.0 * nu)

    @property
    def diffusivity(self) -> float:
        """Thermal diffusivity kappa = lambda / (rho c) [m^2/s]."""
        return self.conductivity / (self.density * self.specific_heat)

    @property
    def effusivity(self) -> float:
        """Thermal penetration coefficient beta = sqrt(lambda rho c) [W s^0.5 / (m^2 K)] (seed eq. 31)."""
        return math.sqrt(self.conductivity * self.density * self.specific_heat)

    def as_dict(self) -> dict:
        return asdict(self)
