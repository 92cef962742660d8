"""TemperatureField.from_bodies: bulk temperatures, a body without heat, the common depth axis and
body-prefixed diagnostics are assembled in one place."""
import numpy as np
import pytest

from railtherm import BodyTemperature, TemperatureField
from railtherm.contract.grid import surface_grid


@pytest.fixture
def grid():
    return surface_grid(2e-3, 3e-3, 0, 8)


def test_bulk_added_and_body_without_heat_stays_at_bulk(grid):
    rise = np.linspace(0.0, 10.0, int(np.prod(grid.shape))).reshape(grid.shape)
    f = TemperatureField.from_bodies(grid, (35.0, 20.0), BodyTemperature(rise), None)
    np.testing.assert_allclose(f.surface_temperature[0], 35.0 + rise)
    np.testing.assert_allclose(f.surface_temperature[1], 20.0)
    assert f.max_surface_temperature[0] == pytest.approx(45.0)
    assert f.max_surface_temperature[1] == 20.0
    assert f.z is None and f.temperature is None


def test_depth_profiles_on_the_rail_axis_wheel_interpolated_bulk_below(grid):
    nx = grid.shape[0]
    zw = np.array([0.0, 1e-3, 2e-3])
    zr = np.array([0.0, 0.5e-3, 1e-3, 2e-3, 4e-3])
    w = BodyTemperature(np.ones(grid.shape), z=zw, depth_rise=np.tile([10.0, 5.0, 0.0], (nx, 1)))
    r = BodyTemperature(np.ones(grid.shape), z=zr, depth_rise=np.tile([8.0, 6.0, 4.0, 2.0, 0.0], (nx, 1)))
    f = TemperatureField.from_bodies(grid, (0.0, 100.0), w, r)
    np.testing.assert_array_equal(f.z, zr)
    np.testing.assert_allclose(f.temperature[0, 0], [10.0, 7.5, 5.0, 0.0, 0.0])     # linear, then bulk
    np.testing.assert_allclose(f.temperature[1, 0], 100.0 + np.array([8.0, 6.0, 4.0, 2.0, 0.0]))
    assert f.temperature.shape == (2, nx, zr.size)


def test_explicit_depth_axis_without_profiles_is_bulk(grid):
    f = TemperatureField.from_bodies(grid, (5.0, 7.0), None, None, z=np.zeros(1))
    assert f.temperature.shape == (2, grid.shape[0], 1)
    np.testing.assert_allclose(f.temperature[:, :, 0], [[5.0] * grid.shape[0], [7.0] * grid.shape[0]])


def test_body_diagnostics_prefixed_and_inputs_not_kept(grid):
    rise = np.zeros(grid.shape)
    w = BodyTemperature(rise, diagnostics={"iterations": 3})
    r = BodyTemperature(rise, diagnostics={"iterations": 5, "residual": 1e-9})
    f = TemperatureField.from_bodies(grid, (0.0, 0.0), w, r, diagnostics={"converged": True})
    assert f.diagnostics == {"converged": True, "wheel_iterations": 3, "rail_iterations": 5, "rail_residual": 1e-9}
    rise[:] = 99.0
    assert f.surface_temperature.max() == 0.0
