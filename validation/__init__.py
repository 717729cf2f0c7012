"""Validation: measured data and the semi-empirical terramechanics model (``terramechanics``)."""
