"""Type stubs of the extension module `rapier_fvm._native` (re-exported by `rapier_fvm`).

SI units: m, s, kg, Pa, N. Arrays are float64 unless said otherwise; each is a fresh array
the caller owns.
"""

from os import PathLike
from typing import Any, List, Mapping, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt
from typing_extensions import Self

_Vec3 = Tuple[float, float, float]
_Quat = Tuple[float, float, float, float]
_FloatArray = npt.NDArray[np.float64]
_IndexArray = npt.NDArray[np.uint32]
_Path = Union[str, "PathLike[str]"]

class Error(ValueError):
    """What rapier_fvm refuses: invalid meshes, materials, settings or states, failed steps."""

class SceneError(Error):
    """A scene file that cannot be read or built, naming its file, line and key."""

@final
class Material:
    """An elastic material. `model`: "linear", "st_venant_kirchhoff", "corotated" or
    "stable_neo_hookean"; `young` (Pa, > 0), `poisson` (in (-1, 0.5)), `density` (kg/m^3, > 0)."""

    def __new__(cls, model: str, young: float, poisson: float, density: float) -> Material: ...
    @property
    def young(self) -> float: ...
    @property
    def poisson(self) -> float: ...
    @property
    def density(self) -> float: ...

@final
class Mesh:
    """A checked tetrahedral mesh (m); a defect raises `Error` naming the tetrahedron or node."""

    def __new__(cls, nodes: npt.ArrayLike, tets: npt.ArrayLike) -> Mesh:
        """Nodes as an (n, 3) float array (m), tets as an (m, 4) integer array."""
    @staticmethod
    def cuboid(half_extents: _Vec3, cells: Tuple[int, int, int]) -> Mesh: ...
    @staticmethod
    def sphere(radius: float, cells_across: int) -> Mesh: ...
    @staticmethod
    def cylinder(radius: float, half_height: float, cells_across: int, cells_along: int) -> Mesh: ...
    @staticmethod
    def load(path: _Path, scale: float = 1.0) -> Mesh:
        """Gmsh .msh, TetGen .node/.ele, VTK .vtk/.vtu; OBJ/STL surfaces are filled."""
    @property
    def nodes(self) -> _FloatArray: ...
    @property
    def tets(self) -> _IndexArray: ...
    @property
    def node_count(self) -> int: ...
    @property
    def tet_count(self) -> int: ...
    @property
    def volume(self) -> float: ...

@final
class Shape:
    """A rigid body's collision shape (m); y is the axis of capsules and cylinders."""

    @staticmethod
    def cuboid(half_extents: _Vec3) -> Shape: ...
    @staticmethod
    def ball(radius: float) -> Shape: ...
    @staticmethod
    def capsule(half_height: float, radius: float) -> Shape: ...
    @staticmethod
    def cylinder(half_height: float, radius: float) -> Shape: ...

@final
class SoftBody:
    """A soft body's handle (hashable, compared by value)."""

    def __new__(cls, index: int, generation: int) -> Self:
        """A handle from its raw parts (as pickling makes it)."""

@final
class RigidBody:
    """A rigid body's handle (hashable, compared by value)."""

    def __new__(cls, index: int, generation: int) -> Self:
        """A handle from its raw parts (as pickling makes it)."""

@final
class Collider:
    """A collider's handle (hashable, compared by value)."""

    def __new__(cls, index: int, generation: int) -> Self:
        """A handle from its raw parts (as pickling makes it)."""

@final
class World:
    """Rigid and soft bodies stepped together; `dt` the frame step (s), `gravity` (m/s^2)."""

    def __new__(cls, dt: float = ..., gravity: _Vec3 = ...) -> World: ...
    @staticmethod
    def from_scene(path: _Path, overrides: Optional[Mapping[str, Any]] = None) -> World:
        """A 3D scene file's world; `overrides` maps key paths ("soft_body[0].material.young")
        to values."""
    def step(self, frames: int = 1) -> None:
        """Advances `frames` frames with the GIL released; raises `Error` if a body's step failed."""
    @property
    def time(self) -> float: ...
    @property
    def frame(self) -> int: ...
    @property
    def dt(self) -> float: ...
    coupling_substeps: int
    def save(self) -> bytes:
        """The whole state; `restore` puts it back and the run goes on bit for bit."""
    def restore(self, state: bytes) -> None:
        """A state of a world of the same bodies (raises ValueError otherwise)."""
    # Scenes
    def soft_body(self, name: str) -> SoftBody: ...
    def rigid_body(self, name: str) -> RigidBody: ...
    def probes(self) -> dict[str, _FloatArray]:
        """Each probe's (n, 2) array of (time (s), value) rows, one per frame from 0."""
    # Rigid bodies
    def add_ground(self, *, height: float = ..., normal: _Vec3 = ...,
                   friction: float = ...) -> Collider: ...
    def add_rigid_body(self, shape: Shape, *, kind: str = ..., translation: _Vec3 = ...,
                       rotation: _Vec3 = ..., linvel: _Vec3 = ..., angvel: _Vec3 = ...,
                       density: float = ..., friction: float = ...,
                       restitution: float = ...) -> RigidBody:
        """kind: "dynamic", "fixed" or "kinematic"; rotation a scaled axis (rad)."""
    @property
    def rigid_bodies(self) -> list[RigidBody]: ...
    def colliders_of(self, body: RigidBody) -> list[Collider]: ...
    def rigid_pose(self, body: RigidBody) -> Tuple[List[float], List[float]]:
        """Translation (m) and unit quaternion (x, y, z, w)."""
    def rigid_velocity(self, body: RigidBody) -> Tuple[List[float], List[float]]:
        """Linear (m/s) and angular (rad/s) velocity."""
    def rigid_poses(self) -> _FloatArray:
        """(n, 7): translation then quaternion (x, y, z, w), in the order of `rigid_bodies`."""
    def set_kinematic_target(self, body: RigidBody, translation: _Vec3,
                             rotation: Optional[_Quat] = None) -> None: ...
    # Soft bodies
    def add_soft_body(self, mesh: Mesh, material: Material, *, translation: _Vec3 = ...,
                      rotation: _Vec3 = ..., linvel: _Vec3 = ..., angvel: _Vec3 = ...,
                      stiffness_time: Optional[float] = None, pinned: Sequence[int] = ...,
                      friction: Optional[float] = None,
                      self_contact: bool = False,
                      rigid_stand_in: Optional[float] = None) -> SoftBody: ...
    def stands_in(self, soft: SoftBody) -> bool: ...
    def attach(self, soft: SoftBody, nodes: Sequence[int], rigid: RigidBody) -> None: ...
    @property
    def soft_bodies(self) -> list[SoftBody]: ...
    def positions(self, body: SoftBody) -> _FloatArray: ...
    def velocities(self, body: SoftBody) -> _FloatArray: ...
    def masses(self, body: SoftBody) -> _FloatArray: ...
    def surface_triangles(self, body: SoftBody) -> _IndexArray: ...
    def tets(self, body: SoftBody) -> _IndexArray: ...
    def stresses(self, body: SoftBody) -> _FloatArray:
        """(m, 3, 3) Cauchy stress per element (Pa), elastic part."""
    def contact_force(self, soft: SoftBody, collider: Collider) -> Tuple[List[float], List[float]]:
        """Force (N) and torque about the origin (N m) over the body's last step."""
    def load_on(self, soft: SoftBody, rigid: RigidBody) -> Tuple[List[float], List[float]]:
        """Force (N) and torque about the origin (N m) over the last frame."""
    def set_positions(self, body: SoftBody, positions: npt.ArrayLike,
                      nodes: Optional[Sequence[int]] = None) -> None: ...
    def set_velocities(self, body: SoftBody, velocities: npt.ArrayLike,
                       nodes: Optional[Sequence[int]] = None) -> None: ...
    def measures(self, body: SoftBody) -> dict[str, Any]:
        """kinetic_energy, elastic_energy (J), linear_momentum, angular_momentum,
        center_of_mass (arrays)."""
    # Loads
    def add_pressure(self, body: SoftBody, triangles: npt.ArrayLike, pressure: float) -> int: ...
    def add_traction(self, body: SoftBody, triangles: npt.ArrayLike, traction: _Vec3) -> int: ...
    def add_body_force(self, body: SoftBody, density: _Vec3) -> int: ...
    def add_cable(self, body: SoftBody, path: Sequence[int], tension: float) -> int: ...
    def set_load(self, body: SoftBody, load: int, value: Union[float, _Vec3]) -> None: ...

def run_scene(path: _Path, out: _Path, *, duration: Optional[float] = None,
              overrides: Optional[Mapping[str, Any]] = None) -> dict[str, Any]:
    """Runs a scene file (3D or 2D) as `rapier-fvm run` does; returns its report."""

def advise(path: _Path, out: _Path, *, target: float = 0.05, duration: Optional[float] = None,
           overrides: Optional[Mapping[str, Any]] = None) -> dict[str, Any]:
    """Advises on a 3D scene file as `rapier-fvm advise` does; returns the advice."""

def _unpickle_world(scene: Optional[Tuple[str, str]], state: bytes) -> World:
    """A pickled world rebuilt (`World.__reduce__`)."""

__all__ = [
    "Collider",
    "Error",
    "Material",
    "Mesh",
    "RigidBody",
    "SceneError",
    "Shape",
    "SoftBody",
    "World",
    "advise",
    "run_scene",
    "_unpickle_world",
]

