"""A rigid tool of the virtual lab (a plate, a wheel, the halves and cap of a shear box) in a DEM scene: a rigid
:class:`~wheelsoil.flexwheel.structure.Structure` whose every node is tied to its hub, in Hertz--Mindlin contact
with the spheres through the DE--FE interface (:class:`~wheelsoil.coupling.contact.WheelContact`, seed 004
eqs. 3--13 with a flat partner). The rig prescribes the tool's velocity, or leaves a direction free under a force;
:meth:`RigidTool.soil_force` is the mean force of the soil on the tool since it was last read.
"""

from __future__ import annotations

import numpy as np

from wheelsoil.coupling.contact import WheelContact
from wheelsoil.flexwheel.mesh import StructureMesh
from wheelsoil.flexwheel.structure import Structure
from wheelsoil.granular.materials import STEEL, Material, PairProperties
from wheelsoil.granular.scene import Scene


class RigidTool:
    """A rigid triangle mesh moved by the lab's rig.

    Parameters
    ----------
    scene: the DEM scene the tool acts on (the tool adds itself as an interaction).
    nodes, triangles: the tool's mesh, already placed [m].
    thickness: its shell thickness [m] (the contact surface lies half of it either side of the mesh).
    pair: soil--tool restitution and friction.
    material: the tool's material (its E enters the contact stiffness, its density the tool's mass).
    center: the point the tool's motion is about [m] (default: the nodes' centroid).
    gravity: gravity on the tool itself [m/s^2] (a tool that is only moved by the rig needs none).
    mass: mass [kg] added to the mesh's own (a loading cap's dead weight).
    """

    def __init__(self, scene: Scene, nodes, triangles, thickness: float, pair: PairProperties, *,
                 material: Material = STEEL, center=None, gravity=(0.0, 0.0, 0.0), mass: float = 0.0) -> None:
        nodes = np.asarray(nodes, float)
        mesh = StructureMesh(nodes=nodes, triangles=triangles, thickness=thickness, material=material)
        center = nodes.mean(axis=0) if center is None else np.asarray(center, float)
        self.structure = Structure(mesh, rigid=True, hub_center=center, hub_mass=mass, gravity=gravity, arch=scene.arch)
        self.contact = WheelContact(self.structure, scene.material, pair)
        self.scene = scene
        scene.add_interaction(self.contact)
        self.hold()

    @property
    def mass(self) -> float:
        """The tool's mass [kg] (its mesh's lumped mass and the extra ``mass``)."""
        return float(self.structure.hub_mass_total)

    def hold(self) -> None:
        """Hold the tool still."""
        self.move((0.0, 0.0, 0.0))

    def move(self, velocity, *, free_z: bool = False, force_z: float = 0.0) -> None:
        """Prescribe the tool's velocity [m/s] (no spin); ``free_z`` leaves the vertical free under the rig's force
        ``force_z`` [N] (+ up) instead."""
        v = np.asarray(velocity, float).reshape(3)
        self.structure.set_hub_state(velocity=v, angular_velocity=(0.0, 0.0, 0.0))
        self.structure.drive_hub(velocity=v, angular_velocity=(0.0, 0.0, 0.0), free_translation=(False, False, free_z),
                                 free_rotation=(False, False, False), force=(0.0, 0.0, force_z))

    @property
    def position(self) -> np.ndarray:
        """The tool's reference point [m]."""
        return self.structure.hub_position

    @property
    def velocity(self) -> np.ndarray:
        return self.structure.hub_velocity

    def soil_force(self) -> np.ndarray:
        """Mean force of the soil on the tool [N] since the last call (over every DEM step in between)."""
        force, _, _ = self.contact.mean_resultant(reset=True)
        return np.asarray(force, float)
