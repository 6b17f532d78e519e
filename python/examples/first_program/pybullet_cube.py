# The same cube in pybullet: it needs a tetrahedral mesh file, so the program writes one (a
# 4 x 4 x 4 grid of hexahedra, five tetrahedra each) in legacy VTK, and converts E and nu to
# its Neo-Hookean constants. z is up.
import itertools
import tempfile

import numpy as np
import pybullet as p

n, h = 4, 0.2
grid = np.array(list(itertools.product(range(n + 1), repeat=3)))  # (i, j, k), k fastest
points = grid * (h / n) - h / 2
index = lambda i, j, k: (i * (n + 1) + j) * (n + 1) + k
tets = []
for i, j, k in itertools.product(range(n), repeat=3):
    c = [index(i + a, j + b, k + d) for a, b, d in [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
                                                   (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]]
    split = [(0, 1, 3, 4), (1, 2, 3, 6), (1, 4, 5, 6), (3, 4, 6, 7), (1, 3, 4, 6)] if (i + j + k) % 2 == 0 \
        else [(0, 1, 2, 5), (0, 2, 3, 7), (0, 4, 5, 7), (2, 5, 6, 7), (0, 2, 5, 7)]
    for t in split:
        tet = [c[v] for v in t]
        a, b, cc, d = points[tet]
        if np.dot(np.cross(b - a, cc - a), d - a) < 0:  # pybullet needs positive orientation
            tet[0], tet[1] = tet[1], tet[0]
        tets.append(tet)
path = tempfile.mktemp(suffix=".vtk")
with open(path, "w") as f:
    f.write(f"# vtk DataFile Version 2.0\ncube\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS {len(points)} double\n")
    f.writelines(f"{x} {y} {z}\n" for x, y, z in points)
    f.write(f"CELLS {len(tets)} {5 * len(tets)}\n")
    f.writelines(f"4 {a} {b} {c} {d}\n" for a, b, c, d in tets)
    f.write(f"CELL_TYPES {len(tets)}\n" + "10\n" * len(tets))

E, nu, rho = 1e6, 0.3, 1000.0
mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
p.connect(p.DIRECT)
p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD)
p.setGravity(0, 0, -9.81)
p.setTimeStep(1 / 240)
ground = p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=[5, 5, 0.5]), basePosition=[0, 0, -0.5])
cube = p.loadSoftBody(path, basePosition=[0, 0, 0.3], mass=rho * h**3, useNeoHookean=1,
                      NeoHookeanMu=4 / 3 * mu, NeoHookeanLambda=lam + 5 / 6 * mu, NeoHookeanDamping=0.01,
                      collisionMargin=0.006, frictionCoeff=0.5, useFaceContact=1)
for _ in range(480):
    p.stepSimulation()
nodes = np.array(p.getMeshData(cube, -1, flags=p.MESH_DATA_SIMULATION_MESH)[1])
print("lowest point (m):", nodes[:, 2].min())
