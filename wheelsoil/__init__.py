"""wheelsoil: a single-wheel terramechanics testbed in software.

The physics lives in sub-packages that sit at the repository root and are installed under this
namespace:

* :mod:`wheelsoil.granular` -- Hertz--Mindlin DEM soil (particles, walls, contact, beds)
* :mod:`wheelsoil.flexwheel` -- corotational FEM wheel
* :mod:`wheelsoil.coupling` -- DE--FE contact interface and the testbed driver
* :mod:`wheelsoil.cases` -- case files, runs, results, renders and the ``wheelsoil`` command
* :mod:`wheelsoil.validation` -- measured data, semi-empirical models, discrepancy discovery
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("wheelsoil")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
