"""The rigid hub of a :class:`~.structure.Structure`: its drive (each of six dofs prescribed or force-driven), its
state and the reactions of its prescribed dofs.

:class:`HubDrive` is mixed into :class:`~.structure.Structure`; the hub's state rows live on the device
(``arrays.hub``, rows ``flexwheel.integrator.HUB_*``; ``arrays.hub_rot``, ``arrays.hub_scalar``), which the
structure's integrator advances (:mod:`.stepper`).
"""

from __future__ import annotations

import numpy as np

from wheelsoil.errors import WheelsoilInputError

from . import integrator as itg


class HubDrive:
    """Set and read a structure's hub (mixed into :class:`~.structure.Structure`, which has ``hub_nodes`` and
    ``arrays``)."""

    def _hub_state(self) -> np.ndarray:
        if not self.hub_nodes.size:
            raise WheelsoilInputError("this structure has no hub")
        return self.arrays.hub.to_numpy()

    def drive_hub(self, *, velocity=None, angular_velocity=None, free_translation=None, free_rotation=None,
                  force=None, moment=None) -> None:
        """Set the hub's drive, held until changed.

        velocity, angular_velocity: prescribed velocity [m/s] and spin [rad/s] (global frame) of the
            prescribed degrees of freedom.
        free_translation, free_rotation: three booleans each; True makes that dof force-driven.
        force, moment: load the rig applies to the hub [N, N m] (acts on the free dofs; on prescribed
            ones it only changes the reported reaction).
        """
        s = self._hub_state()
        for row, val in ((itg.HUB_CMD_VELOCITY, velocity), (itg.HUB_CMD_SPIN, angular_velocity),
                         (itg.HUB_APPLIED_FORCE, force), (itg.HUB_APPLIED_MOMENT, moment)):
            if val is not None:
                arr = np.asarray(val, float).reshape(3)
                if not np.all(np.isfinite(arr)):
                    raise WheelsoilInputError(f"hub drive value {arr.tolist()} must be finite")
                s[row] = arr
        for row, val in ((itg.HUB_FREE_TRANSLATION, free_translation), (itg.HUB_FREE_ROTATION, free_rotation)):
            if val is not None:
                s[row] = np.asarray(val, bool).reshape(3).astype(float)
        self.arrays.hub.from_numpy(s)

    def set_hub_state(self, *, velocity=None, angular_velocity=None) -> None:
        """Set the hub's current velocity and spin (e.g. to start a free dof moving)."""
        s = self._hub_state()
        if velocity is not None:
            s[itg.HUB_VELOCITY] = np.asarray(velocity, float).reshape(3)
        if angular_velocity is not None:
            s[itg.HUB_SPIN] = np.asarray(angular_velocity, float).reshape(3)
        self.arrays.hub.from_numpy(s)

    @property
    def hub_position(self) -> np.ndarray:
        return self._hub_state()[itg.HUB_POSITION].copy()

    @property
    def hub_velocity(self) -> np.ndarray:
        return self._hub_state()[itg.HUB_VELOCITY].copy()

    @property
    def hub_angular_velocity(self) -> np.ndarray:
        return self._hub_state()[itg.HUB_SPIN].copy()

    @property
    def hub_applied_force(self) -> np.ndarray:
        """The force the rig applies to the hub [N] (``drive_hub(force=...)``), held until changed."""
        return self._hub_state()[itg.HUB_APPLIED_FORCE].copy()

    @property
    def hub_rotation(self) -> np.ndarray:
        self._hub_state()
        return self.arrays.hub_rot.to_numpy()[0]

    def hub_reaction(self, reset: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Mean force [N] and moment about the hub centre [N m] the rig applied to the prescribed hub
        dofs since the last reset (zero on free dofs)."""
        s = self._hub_state()
        scal = self.arrays.hub_scalar.to_numpy()
        k = max(scal[itg.HUB_SAMPLES], 1.0)
        f, m = s[itg.HUB_REACTION_FORCE] / k, s[itg.HUB_REACTION_MOMENT] / k
        if reset:
            s[itg.HUB_REACTION_FORCE] = 0.0
            s[itg.HUB_REACTION_MOMENT] = 0.0
            scal[itg.HUB_SAMPLES] = 0.0
            self.arrays.hub.from_numpy(s)
            self.arrays.hub_scalar.from_numpy(scal)
        return f, m
