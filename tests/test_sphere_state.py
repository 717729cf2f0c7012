"""The spheres' typed host state (granular/sphere_state.py, issue 38 item 5): every edit keeps the arrays the same
length, a checkpoint round-trips, and the module needs no engine."""

import subprocess
import sys

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular.sphere_state import STATE_ARRAYS, SphereMotion, SphereState


def three_spheres() -> SphereState:
    x = np.arange(9.0).reshape(3, 3)
    return SphereState.empty().appended(x, x + 10, x + 20, np.array([1.0, 2.0, 3.0]))


def test_appended_spheres_are_free_and_without_forces():
    s = three_spheres()
    assert len(s) == 3 and np.all(s.mobile == 1.0) and not s.f.any() and not s.t.any()
    more = s.appended(np.ones((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), np.array([4.0, 5.0]))
    np.testing.assert_array_equal(more.r, [1, 2, 3, 4, 5])
    np.testing.assert_array_equal(more.x[:3], s.x)


def test_kept_held_and_motion_edit_every_array_alike():
    s = three_spheres()
    kept = s.kept(np.array([True, False, True]))
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(getattr(kept, name), getattr(s, name)[[0, 2]])
    held = s.held(np.array([False, True, False]))
    np.testing.assert_array_equal(held.mobile, [1, 0, 1])
    assert not held.v[1].any() and not held.w[1].any() and held.v[0].any()
    assert s.v[1].any()  # the edit made a new state; the old one is unchanged
    motion = SphereMotion(*(np.full((3, 3), k, float) for k in range(5)))
    moved = s.with_motion(motion)
    assert moved.t[0, 0] == 4.0 and moved.r is s.r
    # an empty scene's device arrays hold one row: none of it comes back
    assert len(SphereState.empty().with_motion(SphereMotion(*(np.zeros((1, 3)) for _ in range(5))))) == 0


def test_a_checkpoint_round_trips_and_an_old_one_without_mobility_frees_every_sphere():
    s = three_spheres().held(np.array([True, False, False]))
    arrays = s.to_arrays()
    back = SphereState.from_arrays(arrays)
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(getattr(back, name), getattr(s, name))
    arrays["x"][0, 0] = -1.0  # copies: editing the checkpoint's arrays leaves the state alone
    assert s.x[0, 0] == 0.0
    del arrays["mobile"]
    assert np.all(SphereState.from_arrays(arrays).mobile == 1.0)


def test_arrays_of_different_lengths_are_refused_with_the_array_named():
    s = three_spheres()
    with pytest.raises(WheelsoilInputError, match=r"sphere state v has shape \(2, 3\); expected \(3, 3\)"):
        SphereState(s.x, s.v[:2], s.w, s.f, s.t, s.r, s.mobile)


def test_the_module_needs_no_engine():
    code = ("import sys; import wheelsoil.granular.sphere_state as m; m.SphereState.empty(); "
            "assert 'taichi' not in sys.modules, 'taichi imported'")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
