"""Closed forms the semi-empirical model's tests hold it to (not a test module): the linear soil, whose stress
integrals over the contact have closed forms, and those integrals."""

from dataclasses import replace

import numpy as np


def linear_soil(soil, **kw):
    """``soil`` with n = 1, theta_m = 0 (no rear region), no cohesion: the stress integrals have closed forms."""
    base = dict(cohesion=0.0, n0=1.0, n1=0.0, a1=0.0, a2=0.0, c3=0.0, kc_prime=0.0)
    return replace(soil, **(base | kw))


def closed_form_integrals(theta_f):
    """(A, B, t) of the linear soil's contact from 0 to theta_f [rad]."""
    c, s = np.cos(theta_f), np.sin(theta_f)
    a = theta_f / 2 + np.sin(2 * theta_f) / 4 - c * s  # int_0^tf (cos t - cos tf) cos t dt
    b = (1 - c) ** 2 / 2  # int_0^tf (cos t - cos tf) sin t dt
    t = s - theta_f * c  # int_0^tf (cos t - cos tf) dt
    return a, b, t
