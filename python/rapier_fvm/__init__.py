"""Finite-volume soft bodies coupled two-way with rapier's rigid bodies, from Python.

SI units throughout: lengths in m, times in s, masses in kg, stresses and pressures in Pa,
forces in N. A world of rigid and soft bodies is built body by body or read from a scene file,
stepped frame by frame (the GIL released), read and driven through numpy arrays, and saved and
restored bit for bit::

    import rapier_fvm as rf

    world = rf.World(dt=1 / 60)
    world.add_ground()
    rubber = rf.Material("stable_neo_hookean", young=1e6, poisson=0.3, density=1000.0)
    cube = world.add_soft_body(rf.Mesh.cuboid((0.1, 0.1, 0.1), (4, 4, 4)), rubber,
                               translation=(0.0, 0.3, 0.0))
    world.step(60)
    print(world.positions(cube)[:, 1].min())   # the cube's lowest point (m)

`run_scene` runs a scene file as ``rapier-fvm run`` does and returns its report; `advise`
finds a cheaper scene within a target error as ``rapier-fvm advise`` does; `sweep` runs a
scene over a grid of values, locally or on Ray.
"""

from ._native import (
    Collider,
    Error,
    Material,
    Mesh,
    RigidBody,
    SceneError,
    Shape,
    SoftBody,
    World,
    advise,
    run_scene,
)

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
]
