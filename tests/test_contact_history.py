"""The host-side contact history (granular.contact_history): the edits a scene, a bed and a moving patch make."""

import numpy as np
import pytest

from wheelsoil.granular import WheelsoilInputError
from wheelsoil.granular.contact_history import ContactHistory


def test_pairs_given_win_and_a_pair_given_backwards_is_turned_around():
    h = ContactHistory.empty(4, 1).with_pairs([0, 2], [3, 1], [[1.0, 0, 0], [0, 2.0, 0]], [[0, 0, 3.0], [4.0, 0, 0]])
    assert h.pair_i.tolist() == [0, 1] and h.pair_j.tolist() == [3, 2]  # sorted by owner, owner the lower index
    np.testing.assert_array_equal(h.pair_xi, [[1.0, 0, 0], [0, -2.0, 0]])
    np.testing.assert_array_equal(h.pair_roll, [[0, 0, 3.0], [-4.0, 0, 0]])
    again = h.with_pairs([3], [0], [[5.0, 0, 0]])  # replaces (0, 3), seen from sphere 3; rolling torque zero
    np.testing.assert_array_equal(again.pair_xi[0], [-5.0, 0, 0])
    np.testing.assert_array_equal(again.pair_roll[0], [0, 0, 0])
    assert again.n_pairs == 2


@pytest.mark.parametrize("i, j, fragment", [([0], [4], "indices below 4"), ([1], [1], "cannot pair with itself")])
def test_bad_pairs_are_named(i, j, fragment):
    with pytest.raises(WheelsoilInputError, match=fragment):
        ContactHistory.empty(4, 0).with_pairs(i, j, [[0.0, 0, 0]])


def test_kept_spheres_keep_their_pairs_and_walls_renumbered():
    h = ContactHistory.empty(4, 1).with_pairs([0, 1, 2], [1, 3, 3], np.eye(3), 2 * np.eye(3))
    walls = np.arange(12.0).reshape(4, 1, 3)
    h = ContactHistory(h.pair_i, h.pair_j, h.pair_xi, h.pair_roll, walls, -walls)
    out = h.kept(np.array([True, False, True, True]))  # sphere 1 goes: 2 -> 1, 3 -> 2
    assert out.pair_i.tolist() == [1] and out.pair_j.tolist() == [2]
    np.testing.assert_array_equal(out.pair_xi, [np.eye(3)[2]])
    np.testing.assert_array_equal(out.roll_wall, -walls[[0, 2, 3]])


def test_walls_and_spheres_added_and_old_arrays_read_with_zero_rolling_torque():
    h = ContactHistory.empty(2, 1).with_wall().with_spheres(1, xi_wall=np.ones((1, 2, 3)))
    assert h.xi_wall.shape == h.roll_wall.shape == (3, 2, 3) and h.xi_wall[2].sum() == 6 and h.roll_wall.sum() == 0
    old = {"pair_i": np.array([0]), "pair_j": np.array([1]), "pair_xi": np.ones((1, 3)), "xi_wall": np.ones((2, 1, 3))}
    read = ContactHistory.from_arrays(old)
    assert read.pair_roll.shape == (1, 3) and not read.pair_roll.any() and not read.roll_wall.any()
    with pytest.raises(WheelsoilInputError, match="without pair_j"):
        ContactHistory.from_arrays({k: v for k, v in old.items() if k != "pair_j"})
