"""Plugin "fdm" as a package: its public names, the one explicit kernel body compiled twice, and the
registration of the model."""
from __future__ import annotations


import numpy as np

import railtherm
from railtherm import Method
from railtherm.testing import canonical

def test_public_names_of_the_fdm_modules():
    from railtherm_fdm import block2d, block3d, kernels, model
    assert {"FDMTemperature", "choose_scheme", "explicit_cost"} <= set(model.__all__)
    assert {"BlockResult", "Extent", "block_extent", "transient_block", "steady_block", "explicit_stability_limit",
            "box_overlap"} <= set(block3d.__all__)
    assert {"line_extent", "line_stability_limit", "transient_line", "steady_line", "X_SCHEMES"} <= set(block2d.__all__)
    assert {"explicit_step", "explicit_step_serial", "explicit_two_steps", "stencil_matvec", "PARALLEL_MIN_NODES",
            "step_kernel", "matvec_kernel"} <= set(kernels.__all__)


def test_one_kernel_body_compiled_parallel_and_serial():
    """The parallel and the serial explicit step (and 7-point operator) are one Python function compiled
    twice; they give bit-identical results, and the serial build is a separately cached copy."""
    from railtherm_fdm import kernels as K
    assert K.explicit_step.py_func.__code__ is K.explicit_step_serial.py_func.__code__
    assert K.stencil_matvec.py_func.__code__ is K.stencil_matvec_serial.py_func.__code__
    assert K.explicit_step.targetoptions.get("parallel") and not K.explicit_step_serial.targetoptions.get("parallel")
    assert K.explicit_step_serial.py_func.__qualname__.endswith("_serial")       # own numba cache entry
    rng = np.random.default_rng(3)
    T = rng.random((24, 11, 9))
    T[0] = T[-1] = 0.0
    T[:, :, -1] = 0.0
    src, hloss = rng.random((24, 11)), 1e-3 * rng.random((24, 11))
    out = [np.zeros_like(T) for _ in range(2)]
    K.explicit_step(T, out[0], 0.15, src, hloss)
    K.explicit_step_serial(T, out[1], 0.15, src, hloss)
    assert np.array_equal(out[0], out[1])
    coef = [rng.random(T.shape) for _ in range(7)]
    K.stencil_matvec(*coef, T, out[0])
    K.stencil_matvec_serial(*coef, T, out[1])
    assert np.array_equal(out[0], out[1])


def test_plugin_registers_the_model_that_a_method_of_another_plugin_names(railtherm_register):
    """The fdm plugin registers only the model; a method of another plugin names it."""
    import types

    import railtherm_fdm.plugin as fdm_plugin
    host = railtherm_register("fdm", fdm_plugin)
    assert "fdm" in host.models and host.models["fdm"].plugin == "fdm"
    chain = types.ModuleType("chain_plugin")

    @railtherm.hookimpl
    def railtherm_register_methods():
        return [Method("given-fdm", {"temperature": ("fdm",)})]

    chain.railtherm_register_methods = railtherm_register_methods
    host.add_plugin(chain, "chain")
    host.build()
    ds = railtherm.solve(canonical("line-given-flux"), "given-fdm", 0)
    assert ds.attrs["fdm_rail_scheme"] == "steady" and abs(ds.attrs["fdm_heat_balance_error"]) < 1e-9
