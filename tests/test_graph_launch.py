"""wheelsoil.graph_launch: a kernel run through a compute graph computes what the kernel computes."""

import numpy as np
import pytest
import taichi as ti

from wheelsoil.graph_launch import GraphKernel
from wheelsoil.runtime import init
from wheelsoil.taichi_types import nd_f64, nd_vec3, vec3

init()


@ti.kernel
def scaled_sum(x: nd_vec3, scale: ti.f64, offset: ti.i32, out: nd_f64):
    """out[i] = scale * (x[i] . (1, 1, 1)) + offset, and out[last] = the number of rows."""
    for i in x:
        out[i] = scale * x[i].dot(vec3(1.0, 1.0, 1.0)) + offset
    out[out.shape[0] - 1] = x.shape[0]


@ti.kernel
def returns_value(x: nd_f64) -> ti.f64:
    return x[0]


def test_graph_runs_the_kernel_with_its_arguments():
    rng = np.random.default_rng(0)
    values = rng.normal(size=(50, 3))
    x = ti.Vector.ndarray(3, ti.f64, shape=50)
    x.from_numpy(values)
    direct = ti.ndarray(ti.f64, shape=51)
    graph = ti.ndarray(ti.f64, shape=51)
    scaled_sum(x, 2.5, 3, direct)
    run = GraphKernel(scaled_sum)
    run(x, 2.5, 3, graph)
    np.testing.assert_array_equal(graph.to_numpy(), direct.to_numpy())
    # scalars are converted to their parameter's type (an integer scale, a NumPy integer offset)
    run(x, 2, np.int64(-1), graph)
    np.testing.assert_allclose(graph.to_numpy()[:50], 2.0 * values.sum(axis=1) - 1.0, rtol=1e-15)
    # arrays of another size go through the same compiled graph
    small = ti.Vector.ndarray(3, ti.f64, shape=4)
    small.from_numpy(values[:4])
    out = ti.ndarray(ti.f64, shape=5)
    run(small, 1.0, 0, out)
    np.testing.assert_allclose(out.to_numpy(), np.append(values[:4].sum(axis=1), 4.0), rtol=1e-15)


def test_graph_refuses_return_values_and_wrong_arity():
    with pytest.raises(TypeError, match="returns a value"):
        GraphKernel(returns_value)
    with pytest.raises(TypeError, match="takes 4 arguments, got 2"):
        GraphKernel(scaled_sum)(1.0, 2.0)
