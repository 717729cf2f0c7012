"""Validation: hold models against measured data, find what they get wrong, name the cause, measure the gain.

* :mod:`.measured` -- measured data (CSV with units in the column names) into SI arrays
* :mod:`.terramechanics` -- the semi-empirical 3-D wheel--soil model
* :mod:`.extensions` -- named candidate mechanisms and their parameters
* :mod:`.discovery` -- calibration, residual diagnostics, candidate ranking, held-out gain
* :mod:`.periodic` -- periodic components of time series and their frequency laws
* :mod:`.synthetic` -- synthetic data with a hidden mechanism (for tests and demonstrations)
* :mod:`.report`, :mod:`.workflow` -- the report and ``wheelsoil validate``
"""
