"""Taichi vector/matrix types and 1-D/2-D ndarray annotations shared by the solvers' kernels (f64, i32),
and :func:`to_ndarray` to put a NumPy array on the device."""

import numpy as np
import taichi as ti

vec3 = ti.types.vector(3, ti.f64)
vec4 = ti.types.vector(4, ti.f64)
vec9 = ti.types.vector(9, ti.f64)
ivec2 = ti.types.vector(2, ti.i32)
ivec3 = ti.types.vector(3, ti.i32)
mat3 = ti.types.matrix(3, 3, ti.f64)
mat32 = ti.types.matrix(3, 2, ti.f64)
mat23 = ti.types.matrix(2, 3, ti.f64)

nd_f64 = ti.types.ndarray(dtype=ti.f64, ndim=1)
nd_f64_2d = ti.types.ndarray(dtype=ti.f64, ndim=2)
nd_i32 = ti.types.ndarray(dtype=ti.i32, ndim=1)
nd_i32_2d = ti.types.ndarray(dtype=ti.i32, ndim=2)
nd_vec3 = ti.types.ndarray(dtype=vec3, ndim=1)
nd_vec3_2d = ti.types.ndarray(dtype=vec3, ndim=2)
nd_vec4 = ti.types.ndarray(dtype=vec4, ndim=1)
nd_ivec2 = ti.types.ndarray(dtype=ivec2, ndim=1)
nd_ivec3 = ti.types.ndarray(dtype=ivec3, ndim=1)
nd_mat3 = ti.types.ndarray(dtype=mat3, ndim=1)
nd_mat32 = ti.types.ndarray(dtype=mat32, ndim=1)
nd_mat23 = ti.types.ndarray(dtype=mat23, ndim=1)


def to_ndarray(dtype, values) -> ti.Ndarray:
    """A Taichi ndarray holding ``values`` (element shape taken from ``dtype``).

    Taichi has no empty arrays: an empty ``values`` gives one zero row (kernels are never launched over it).
    """
    values = np.ascontiguousarray(values)
    if values.shape[0] == 0:
        values = np.zeros((1,) + values.shape[1:], dtype=values.dtype)
    elem_ndim = getattr(dtype, "ndim", 0)
    arr = ti.ndarray(dtype=dtype, shape=values.shape[: values.ndim - elem_ndim])
    arr.from_numpy(values)
    return arr
