"""Writes the mesh files under assets/meshes/ used by tests/mesh_import.rs.

Needs gmsh and meshio from PyPI:
    python3 -m venv /tmp/venv-gmsh && /tmp/venv-gmsh/bin/pip install gmsh meshio
    /tmp/venv-gmsh/bin/python tools/make_test_meshes.py
"""
import math
import os
import struct

import gmsh
import meshio

OUT = os.path.join(os.path.dirname(__file__), "..", "assets", "meshes")


def cube_msh():
    """A unit cube [0, 1]^3 meshed by gmsh, written in MSH 2.2 and 4.1, ASCII and binary."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("cube")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.35)
    gmsh.model.mesh.generate(3)
    for version, binary, name in [
        (2.2, 0, "cube_v22_ascii.msh"),
        (2.2, 1, "cube_v22_binary.msh"),
        (4.1, 0, "cube_v41_ascii.msh"),
        (4.1, 1, "cube_v41_binary.msh"),
    ]:
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.option.setNumber("Mesh.Binary", binary)
        gmsh.write(os.path.join(OUT, name))
    gmsh.finalize()


def cube_others():
    """The same cube through meshio: VTU (ASCII and base64 binary), legacy VTK and TetGen."""
    mesh = meshio.read(os.path.join(OUT, "cube_v41_ascii.msh"))
    tets = mesh.cells_dict["tetra"]
    used = sorted(set(tets.flatten().tolist()))
    renumber = {old: new for new, old in enumerate(used)}
    points = mesh.points[used]
    cells = [("tetra", [[renumber[n] for n in t] for t in tets])]
    out = meshio.Mesh(points, cells)
    meshio.write(os.path.join(OUT, "cube_ascii.vtu"), out, binary=False)
    meshio.write(os.path.join(OUT, "cube_binary.vtu"), out, binary=True, compression=None)
    meshio.write(os.path.join(OUT, "cube_ascii.vtk"), out, binary=False)
    meshio.write(os.path.join(OUT, "cube_binary.vtk"), out, binary=True)
    meshio.write(os.path.join(OUT, "cube.node"), out, file_format="tetgen")
    # A VTU holding a triangle beside the tetrahedra: mixed element types.
    mixed = meshio.Mesh(points, cells + [("triangle", [[0, 1, 2]])])
    meshio.write(os.path.join(OUT, "cube_mixed.vtu"), mixed, binary=False)


def icosphere(subdivisions):
    """A unit icosphere: an icosahedron with each triangle split in four, projected to the sphere."""
    t = (1 + math.sqrt(5)) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = [(verts[a][i] + verts[b][i]) / 2 for i in range(3)]
                n = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / n for x in m))
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return verts, faces


def surfaces():
    verts, faces = icosphere(3)  # 642 vertices, 1280 triangles
    with open(os.path.join(OUT, "sphere.obj"), "w") as f:
        f.write("# unit icosphere, 642 vertices, 1280 triangles\n")
        for v in verts:
            f.write("v %.17g %.17g %.17g\n" % v)
        for a, b, c in faces:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
    # A unit cube [0, 1]^3 as a binary STL (12 triangles, outward normals).
    corners = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]

    def normal(a, b, c):
        pa, pb, pc = corners[a], corners[b], corners[c]
        u = [pb[i] - pa[i] for i in range(3)]
        v = [pc[i] - pa[i] for i in range(3)]
        return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])

    with open(os.path.join(OUT, "cube.stl"), "wb") as f:
        f.write(b"unit cube, binary STL".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for tri in tris:
            f.write(struct.pack("<3f", *normal(*tri)))
            for n in tri:
                f.write(struct.pack("<3f", *corners[n]))
            f.write(b"\0\0")
    with open(os.path.join(OUT, "sphere_ascii.stl"), "w") as f:
        vs, fs = icosphere(2)
        f.write("solid sphere\n")
        for a, b, c in fs:
            f.write("  facet normal 0 0 0\n    outer loop\n")
            for n in (a, b, c):
                f.write("      vertex %.9g %.9g %.9g\n" % vs[n])
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid sphere\n")


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    cube_msh()
    cube_others()
    surfaces()
