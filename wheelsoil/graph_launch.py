"""Launch a Taichi kernel through a compiled compute graph, which sets its arguments in C++.

Taichi's Python launch path inspects and converts every ndarray argument on every call: about 9 us
per ndarray on the 2-core benchmark machine, so the one-launch DEM step with its 25 arrays spent
~0.3 ms in Python per step before its loops started, against ~7 ms for the whole step on a 53k bed
and ~0.5 ms on a small one (``benchmarks/README.md``). A compute graph with one dispatch
(``ti.graph``) takes the same arguments by name and sets them in C++: 30 arrays cost ~0.1 ms.

A kernel run this way cannot return values, so it writes its results into a small ndarray.

>>> step = GraphKernel(fused_step.contact_step)      # doctest: +SKIP
>>> step(x, v, ..., result)                          # same positional arguments as the kernel
"""

import inspect

import taichi as ti
from taichi.types.ndarray_type import NdarrayType

#: Compiled graphs, by (Taichi program, kernel): a graph binds no arrays, so one serves every scene.
_GRAPHS: dict = {}


class GraphKernel:
    """Callable that runs ``kernel`` (a ``@ti.kernel`` with ndarray and scalar arguments and no return
    value) through a one-dispatch compute graph, compiled on first use in each Taichi program.

    Call it with the kernel's arguments, positionally; scalars are converted to ``float`` or ``int``
    as their parameter's type asks.
    """

    def __init__(self, kernel):
        signature = inspect.signature(kernel)
        if signature.return_annotation is not inspect.Signature.empty:
            raise TypeError(f"{kernel.__name__} returns a value; a compute graph cannot return one")
        self.kernel = kernel
        self.names = tuple(signature.parameters)
        self._annotations = [p.annotation for p in signature.parameters.values()]
        # scalars go to the graph as the Python type of their parameter
        self._scalar_types = [
            None if isinstance(a, NdarrayType) else (float if a in (ti.f32, ti.f64) else int) for a in self._annotations
        ]

    def _graph(self):
        key = (id(ti.lang.impl.get_runtime().prog), self.kernel)
        graph = _GRAPHS.get(key)
        if graph is None:
            symbols = []
            for name, annotation in zip(self.names, self._annotations):
                if isinstance(annotation, NdarrayType):
                    symbols.append(
                        ti.graph.Arg(ti.graph.ArgKind.NDARRAY, name, dtype=annotation.dtype, ndim=annotation.ndim)
                    )
                else:
                    symbols.append(ti.graph.Arg(ti.graph.ArgKind.SCALAR, name, dtype=annotation))
            builder = ti.graph.GraphBuilder()
            builder.dispatch(self.kernel, *symbols)
            graph = _GRAPHS[key] = builder.compile()
        return graph

    def __call__(self, *args) -> None:
        if len(args) != len(self.names):
            raise TypeError(f"{self.kernel.__name__} takes {len(self.names)} arguments, got {len(args)}")
        self._graph().run(
            {
                name: value if kind is None else kind(value)
                for name, value, kind in zip(self.names, args, self._scalar_types)
            }
        )
