"""Writes the mesh files under assets/meshes/ used by tests/mesh_import/ and the scenes.

Needs gmsh and meshio from PyPI (and vtk and numpy for cube_vtk_library):
    python3 -m venv /tmp/venv-gmsh && /tmp/venv-gmsh/bin/pip install gmsh meshio vtk numpy
    /tmp/venv-gmsh/bin/python tools/make_test_meshes.py

With no arguments every function below is run; with arguments only the named ones, e.g.
    /tmp/venv-gmsh/bin/python tools/make_test_meshes.py cube_meshio_compressed cube_vtk_library
writes those files alone and leaves the others as they are.
"""
import math
import os
import struct

import gmsh
import meshio
import numpy as np

OUT = os.path.join(os.path.dirname(__file__), "..", "assets", "meshes")


def mesh_and_write_v41_ascii(size, dimension, name):
    """Meshes gmsh's current model up to `dimension` with elements of at most `size`, writes it
    to `name` in MSH 4.1 ASCII and finalizes gmsh."""
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(dimension)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(os.path.join(OUT, name))
    gmsh.finalize()


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


def cube_msh_other_forms():
    """cube_msh's cube in the other forms gmsh writes: MSH 4.0 (ASCII, the only form gmsh
    writes it in) and MSH 2.2 with parametric coordinates ($ParametricNodes); and a
    surface-only file, a unit sphere's triangles."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("cube")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.35)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.0)
    gmsh.write(os.path.join(OUT, "cube_v40_ascii.msh"))
    gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
    gmsh.option.setNumber("Mesh.SaveParametric", 1)
    gmsh.write(os.path.join(OUT, "cube_v22_parametric.msh"))
    gmsh.finalize()
    # A surface-only file: gmsh's 2D mesh of a unit sphere (MSH 4.1, ASCII).
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("sphere")
    gmsh.model.occ.addSphere(0, 0, 0, 1)
    gmsh.model.occ.synchronize()
    mesh_and_write_v41_ascii(0.25, 2, "sphere_surface.msh")


def cube_regions():
    """cube_msh's cube with physical groups: the face x = 0 as surface "clamp" (tag 1), the
    volume as "body" (tag 2), in MSH 2.2 ASCII and 4.1 binary."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("cube")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    left = [tag for _, tag in gmsh.model.getEntitiesInBoundingBox(-0.1, -0.1, -0.1, 0.1, 1.1, 1.1, 2)]
    gmsh.model.addPhysicalGroup(2, left, 1, name="clamp")
    gmsh.model.addPhysicalGroup(3, [1], 2, name="body")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.35)
    gmsh.model.mesh.generate(3)
    for version, binary, name in [(2.2, 0, "cube_regions_v22.msh"),
                                  (4.1, 1, "cube_regions_v41_binary.msh")]:
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.option.setNumber("Mesh.Binary", binary)
        gmsh.write(os.path.join(OUT, name))
    gmsh.finalize()


def two_volumes():
    """Two unit boxes side by side, [0, 1] x [0, 1]^2 and [1, 2] x [0, 1]^2, meshed conformingly
    (fragmented) with physical groups: volumes "left" (tag 1) and "right" (tag 2), surfaces
    "clamp" (the face x = 0, tag 3) and "load" (the face x = 2, tag 4); MSH 4.1 ASCII."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("two_volumes")
    left = gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    right = gmsh.model.occ.addBox(1, 0, 0, 1, 1, 1)
    gmsh.model.occ.fragment([(3, left)], [(3, right)])
    gmsh.model.occ.synchronize()

    def volume_at(x):
        return [t for _, t in gmsh.model.getEntitiesInBoundingBox(
            x - 0.6, -0.1, -0.1, x + 0.6, 1.1, 1.1, 3)]

    def face_at(x):
        return [t for _, t in gmsh.model.getEntitiesInBoundingBox(
            x - 0.01, -0.1, -0.1, x + 0.01, 1.1, 1.1, 2)]

    gmsh.model.addPhysicalGroup(3, volume_at(0.5), 1, name="left")
    gmsh.model.addPhysicalGroup(3, volume_at(1.5), 2, name="right")
    gmsh.model.addPhysicalGroup(2, face_at(0.0), 3, name="clamp")
    gmsh.model.addPhysicalGroup(2, face_at(2.0), 4, name="load")
    mesh_and_write_v41_ascii(0.4, 3, "two_volumes_v41.msh")


def cube_points_tets():
    """The cube of cube_v41_ascii.msh as cube_others reads it: the points its tetrahedra use,
    renumbered in sorted order (341 points), and those tetrahedra (1140), as numpy arrays."""
    import numpy as np

    mesh = meshio.read(os.path.join(OUT, "cube_v41_ascii.msh"))
    tets = mesh.cells_dict["tetra"]
    used = sorted(set(tets.flatten().tolist()))
    renumber = {old: new for new, old in enumerate(used)}
    points = np.asarray(mesh.points[used], dtype=np.float64)
    tets = np.array([[renumber[n] for n in t] for t in tets], dtype=np.int64)
    return points, tets


def cube_meshio_compressed():
    """The same cube through meshio as compressed VTU (base64 inline, zlib and lzma), and the
    cube meshed by gmsh at second order as an ASCII VTU of tetra10 cells."""
    points, tets = cube_points_tets()
    out = meshio.Mesh(points, [("tetra", tets)])
    meshio.write(os.path.join(OUT, "cube_zlib.vtu"), out, binary=True)  # zlib is the default
    meshio.write(os.path.join(OUT, "cube_lzma.vtu"), out, binary=True, compression="lzma")

    # Quadratic: cube_msh's geometry and size, raised to order 2 by gmsh, read back by meshio.
    import tempfile

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("cube_tet10")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.35)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    with tempfile.TemporaryDirectory() as tmp:
        msh = os.path.join(tmp, "cube_tet10.msh")
        gmsh.write(msh)
        gmsh.finalize()
        mesh = meshio.read(msh)
    tets10 = mesh.cells_dict["tetra10"]
    used = sorted(set(tets10.flatten().tolist()))
    renumber = {old: new for new, old in enumerate(used)}
    quad = meshio.Mesh(mesh.points[used], [("tetra10", [[renumber[n] for n in t] for t in tets10])])
    meshio.write(os.path.join(OUT, "cube_tet10_ascii.vtu"), quad, binary=False)
    print("cube_tet10_ascii.vtu: %d points, %d tetra10" % (len(used), len(tets10)))


def cube_vtk_library():
    """The same cube written by the VTK library itself (vtkXMLUnstructuredGridWriter in each of
    its data modes, encodings, compressors, header and id types, and the legacy
    vtkUnstructuredGridWriter in ASCII and binary)."""
    from vtkmodules.vtkCommonCore import VTK_DOUBLE, vtkIdList, vtkPoints, vtkVersion
    from vtkmodules.vtkCommonDataModel import VTK_TETRA, vtkUnstructuredGrid
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridWriter
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    points, tets = cube_points_tets()

    def make_grid(norm_range, cells_32bit=False):
        """A fresh grid for each file, so that no file depends on which were written before.
        Computing the points' L2 norm range, as ParaView does, caches it in the array's
        information, which the XML writer then writes as an <InformationKey> child inside the
        Points <DataArray> (after the data in ascii and inline binary modes). The cells are kept
        in 64-bit arrays, written as Int64 whatever the writer's IdType, unless cells_32bit."""
        vtk_points = vtkPoints()
        vtk_points.SetDataType(VTK_DOUBLE)
        vtk_points.SetNumberOfPoints(len(points))
        for i, p in enumerate(points):
            vtk_points.SetPoint(i, *(float(x) for x in p))
        grid = vtkUnstructuredGrid()
        grid.SetPoints(vtk_points)
        grid.Allocate(len(tets))
        for t in tets:
            ids = vtkIdList()
            for n in t:
                ids.InsertNextId(int(n))
            grid.InsertNextCell(VTK_TETRA, ids)
        if cells_32bit:
            if not grid.GetCells().ConvertTo32BitStorage():
                raise RuntimeError("could not convert the cells to 32-bit storage")
        if norm_range:
            vtk_points.GetData().GetRange(-1)
        return grid

    defaults = vtkXMLUnstructuredGridWriter()
    print("VTK %s vtkXMLUnstructuredGridWriter defaults: DataMode=%d (Ascii=0 Binary=1 Appended=2) "
          "EncodeAppendedData=%d Compressor=%s HeaderType=%d IdType=%d BlockSize=%d "
          "CompressionLevel=%d ByteOrder=%d (BigEndian=0 LittleEndian=1)"
          % (vtkVersion.GetVTKVersion(), defaults.GetDataMode(), defaults.GetEncodeAppendedData(),
             defaults.GetCompressor().GetClassName() if defaults.GetCompressor() else None,
             defaults.GetHeaderType(), defaults.GetIdType(), defaults.GetBlockSize(),
             defaults.GetCompressionLevel(), defaults.GetByteOrder()))

    def xml(name, configure, norm_range=True, cells_32bit=False):
        writer = vtkXMLUnstructuredGridWriter()
        writer.SetInputData(make_grid(norm_range, cells_32bit))
        writer.SetFileName(os.path.join(OUT, name))
        configure(writer)
        if writer.Write() != 1:
            raise RuntimeError("vtkXMLUnstructuredGridWriter failed on " + name)

    # The library's defaults untouched (VTK 9.7: appended, base64-encoded since
    # EncodeAppendedData is on by default, zlib, UInt32 headers, Int64 ids), from a grid on which
    # nothing was computed: no <InformationKey>.
    xml("cube_vtk_defaults.vtu", lambda w: None, norm_range=False)
    # Appended raw binary with the default compressor (zlib) and block size.
    xml("cube_vtk_appended_raw_zlib.vtu", lambda w: w.EncodeAppendedDataOff())
    xml("cube_vtk_appended_base64.vtu",
        lambda w: (w.EncodeAppendedDataOn(), w.SetCompressorTypeToNone()))
    xml("cube_vtk_appended_raw.vtu",
        lambda w: (w.EncodeAppendedDataOff(), w.SetCompressorTypeToNone()))
    xml("cube_vtk_binary_zlib.vtu",
        lambda w: (w.SetDataModeToBinary(), w.SetCompressorTypeToZLib()))
    # SetIdTypeToInt32 alone leaves VTK 9's connectivity and offsets Int64 (they are not
    # vtkIdTypeArrays): 32-bit cell storage makes them Int32.
    xml("cube_vtk_binary_uint32.vtu",
        lambda w: (w.SetDataModeToBinary(), w.SetCompressorTypeToNone(),
                   w.SetHeaderTypeToUInt32(), w.SetIdTypeToInt32()), cells_32bit=True)
    xml("cube_vtk_ascii.vtu", lambda w: w.SetDataModeToAscii())
    if hasattr(vtkXMLUnstructuredGridWriter, "SetCompressorTypeToLZ4"):
        xml("cube_vtk_lz4.vtu",
            lambda w: (w.EncodeAppendedDataOff(), w.SetCompressorTypeToLZ4()))
    else:
        print("this VTK has no LZ4 compressor: cube_vtk_lz4.vtu not written")
    # UInt64 block headers (as ParaView writes them), appended raw zlib.
    xml("cube_vtk_header_uint64.vtu",
        lambda w: (w.EncodeAppendedDataOff(), w.SetHeaderTypeToUInt64()))
    # Appended raw zlib in 1 KiB blocks, so that each array spans several compressed blocks.
    xml("cube_vtk_zlib_small_blocks.vtu",
        lambda w: (w.EncodeAppendedDataOff(), w.SetCompressorTypeToZLib(), w.SetBlockSize(1024)))

    for name, binary in [("cube_vtk9_legacy.vtk", False), ("cube_vtk9_legacy_binary.vtk", True)]:
        writer = vtkUnstructuredGridWriter()
        writer.SetInputData(make_grid(True))
        writer.SetFileName(os.path.join(OUT, name))
        if binary:
            writer.SetFileTypeToBinary()
        if writer.Write() != 1:
            raise RuntimeError("vtkUnstructuredGridWriter failed on " + name)


def multi_solid_stl():
    """The surface of a unit box meshed by gmsh, as ASCII STL with one solid per surface (six
    solids) and as one solid."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("box_surface")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
    gmsh.model.mesh.generate(2)
    gmsh.option.setNumber("Mesh.Binary", 0)
    for per_surface, name in [(1, "cube_multi_solid.stl"), (0, "cube_one_solid.stl")]:
        gmsh.option.setNumber("Mesh.StlOneSolidPerSurface", per_surface)
        gmsh.write(os.path.join(OUT, name))
    gmsh.finalize()
    for name in ["cube_multi_solid.stl", "cube_one_solid.stl"]:
        with open(os.path.join(OUT, name)) as f:
            words = [line.split()[0] for line in f if line.strip()]
        print("%s: %d solids, %d facets"
              % (name, words.count("solid"), words.count("facet")))


def pneumatic_finger():
    """A pneumatic finger: a 10 x 2 x 2 cm beam along +x from x = 0 with an inner chamber 8 cm
    long, 1 cm wide and 1 cm high whose floor (7.5 mm) is three times as thick as its roof
    (2.5 mm), meshed by gmsh (elements up to 3 mm) with physical groups: the volume "finger"
    (tag 1), the base x = 0 "base" (tag 2) and the chamber's six walls "chamber" (tag 3); MSH
    4.1 ASCII. assets/scenes/pneumatic_finger.toml inflates it."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("pneumatic_finger")
    outer = gmsh.model.occ.addBox(0, -0.01, -0.01, 0.1, 0.02, 0.02)
    chamber = gmsh.model.occ.addBox(0.01, -0.0025, -0.005, 0.08, 0.01, 0.01)
    gmsh.model.occ.cut([(3, outer)], [(3, chamber)])
    gmsh.model.occ.synchronize()
    volumes = [t for _, t in gmsh.model.getEntities(3)]
    base = [t for _, t in gmsh.model.getEntitiesInBoundingBox(
        -1e-4, -0.011, -0.011, 1e-4, 0.011, 0.011, 2)]
    walls = [t for _, t in gmsh.model.getEntitiesInBoundingBox(
        0.0099, -0.0026, -0.0051, 0.0901, 0.0076, 0.0051, 2)]
    gmsh.model.addPhysicalGroup(3, volumes, 1, name="finger")
    gmsh.model.addPhysicalGroup(2, base, 2, name="base")
    gmsh.model.addPhysicalGroup(2, walls, 3, name="chamber")
    mesh_and_write_v41_ascii(0.003, 3, "pneumatic_finger_v41.msh")


def two_volumes_vtu():
    """two_volumes_v41.msh converted by meshio to VTU (its default: binary, zlib), which keeps
    each cell's physical tag as the cell data array "gmsh:physical" (the groups' names are
    lost: VTU has no place for them); and to legacy VTK (its default: version 5.1, binary),
    where the tags are a FIELD array of the CELL_DATA."""
    mesh = meshio.read(os.path.join(OUT, "two_volumes_v41.msh"))
    meshio.write(os.path.join(OUT, "two_volumes_meshio.vtu"), mesh)
    meshio.write(os.path.join(OUT, "two_volumes_meshio.vtk"), mesh)


def two_volumes_tetgen():
    """two_volumes_v41.msh written by meshio as TetGen `.node`/`.ele`: its tetrahedra with their
    physical and geometrical tags as two attributes (the first, the physical tag, is the region),
    and its physical surfaces "clamp" (3) and "load" (4) as the points' boundary markers (0
    elsewhere), as TetGen marks the points of its facets."""
    mesh = meshio.read(os.path.join(OUT, "two_volumes_v41.msh"))
    blocks = [i for i, c in enumerate(mesh.cells) if c.type == "tetra"]
    tetra = np.concatenate([mesh.cells[i].data for i in blocks])
    tags = {key: [np.concatenate([mesh.cell_data[key][i] for i in blocks])]
            for key in ("gmsh:physical", "gmsh:geometrical")}
    markers = np.zeros(len(mesh.points), dtype=int)
    for i, cells in enumerate(mesh.cells):
        if cells.type == "triangle":
            for triangle, tag in zip(cells.data, mesh.cell_data["gmsh:physical"][i]):
                markers[triangle] = tag
    out = meshio.Mesh(mesh.points, [("tetra", tetra)], point_data={"tetgen:ref": markers},
                      cell_data=tags)
    meshio.write(os.path.join(OUT, "two_volumes_meshio.node"), out, file_format="tetgen")


def hexahedra():
    """A 1 x 0.5 x 0.25 box [0, 1] x [0, 0.5] x [0, 0.25] meshed by gmsh into 4 x 3 x 2
    hexahedra (transfinite, recombined), with physical groups "block" (the volume, tag 1) and
    "clamp" (the face x = 0, tag 2): linear (8-node, type 5) in MSH 4.1 ASCII and 2.2 binary,
    and 27-node (type 12) in MSH 4.1 ASCII; both through meshio to VTU (its default: binary,
    zlib), and the 27-node one through the VTK library's legacy writer (ASCII)."""
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridWriter
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    for order, names in [(1, ["box_hex8_v41.msh", "box_hex8_v22_binary.msh"]),
                         (2, ["box_hex27_v41.msh"])]:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("hexahedra")
        gmsh.model.occ.addBox(0, 0, 0, 1, 0.5, 0.25)
        gmsh.model.occ.synchronize()
        for _, curve in gmsh.model.getEntities(1):
            x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, curve)
            cells = 4 if x1 - x0 > 1e-3 else 3 if y1 - y0 > 1e-3 else 2
            gmsh.model.mesh.setTransfiniteCurve(curve, cells + 1)
        for _, surface in gmsh.model.getEntities(2):
            gmsh.model.mesh.setTransfiniteSurface(surface)
            gmsh.model.mesh.setRecombine(2, surface)
        gmsh.model.mesh.setTransfiniteVolume(1)
        clamp = [t for _, t in gmsh.model.getEntitiesInBoundingBox(
            -1e-6, -1e-6, -1e-6, 1e-6, 0.51, 0.26, 2)]
        gmsh.model.addPhysicalGroup(3, [1], 1, name="block")
        gmsh.model.addPhysicalGroup(2, clamp, 2, name="clamp")
        gmsh.model.mesh.generate(3)
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
            gmsh.model.mesh.setOrder(2)
        for name in names:
            gmsh.option.setNumber("Mesh.MshFileVersion", 2.2 if "v22" in name else 4.1)
            gmsh.option.setNumber("Mesh.Binary", 1 if "binary" in name else 0)
            gmsh.write(os.path.join(OUT, name))
        gmsh.finalize()
    for nodes in [8, 27]:
        mesh = meshio.read(os.path.join(OUT, "box_hex%d_v41.msh" % nodes))
        meshio.write(os.path.join(OUT, "box_hex%d_meshio.vtu" % nodes), mesh)
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(os.path.join(OUT, "box_hex27_meshio.vtu"))
    reader.Update()
    writer = vtkUnstructuredGridWriter()
    writer.SetFileName(os.path.join(OUT, "box_hex27_vtk9.vtk"))
    writer.SetInputData(reader.GetOutput())
    writer.SetFileTypeToASCII()
    writer.Write()


def hollow_sphere():
    """A thick-walled hollow sphere, outer radius 50 mm and inner radius 25 mm, meshed by gmsh
    into second-order tetrahedra (up to 10 mm, curved to the spheres) in millimetres, with physical groups "shell" (the volume, tag 1) and
    "cavity" (the inner sphere, tag 2); MSH 4.1 ASCII. tests/loads.rs inflates its cavity to a
    volume and compares the pressure with Lame's solution."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("hollow_sphere")
    outer = gmsh.model.occ.addSphere(0, 0, 0, 50)
    inner = gmsh.model.occ.addSphere(0, 0, 0, 25)
    gmsh.model.occ.cut([(3, outer)], [(3, inner)])
    gmsh.model.occ.synchronize()
    volumes = [t for _, t in gmsh.model.getEntities(3)]
    cavity = [t for _, t in gmsh.model.getEntitiesInBoundingBox(-26, -26, -26, 26, 26, 26, 2)]
    gmsh.model.addPhysicalGroup(3, volumes, 1, name="shell")
    gmsh.model.addPhysicalGroup(2, cavity, 2, name="cavity")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 10.0)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    # Curving the elements next to the spheres folds some; gmsh's optimizer unfolds them.
    gmsh.model.mesh.optimize("HighOrder")
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(os.path.join(OUT, "hollow_sphere_v41.msh"))
    gmsh.finalize()


def two_blocks_hex():
    """Two boxes [0, 0.5] x [0, 0.5] x [0, 0.25] and [0.5, 1] x [0, 0.5] x [0, 0.25] side by
    side, fragmented and meshed by gmsh into 2 x 3 x 2 hexahedra each (transfinite,
    recombined), with physical groups "soft" (the box x < 0.5, tag 1), "stiff" (x > 0.5, tag 2)
    and "clamp" (the face x = 0, tag 3): linear (8-node) and 27-node, MSH 4.1 ASCII. Gmsh
    numbers the "stiff" box's elements first or last as it likes, so a scene selecting it by
    its group must map its elements as a box of the same centroids does."""
    for order, name in [(1, "two_blocks_hex8_v41.msh"), (2, "two_blocks_hex27_v41.msh")]:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("two_blocks_hex")
        left = gmsh.model.occ.addBox(0, 0, 0, 0.5, 0.5, 0.25)
        right = gmsh.model.occ.addBox(0.5, 0, 0, 0.5, 0.5, 0.25)
        gmsh.model.occ.fragment([(3, left)], [(3, right)])
        gmsh.model.occ.synchronize()
        for _, curve in gmsh.model.getEntities(1):
            x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, curve)
            cells = 2 if x1 - x0 > 1e-3 else 3 if y1 - y0 > 1e-3 else 2
            gmsh.model.mesh.setTransfiniteCurve(curve, cells + 1)
        for _, surface in gmsh.model.getEntities(2):
            gmsh.model.mesh.setTransfiniteSurface(surface)
            gmsh.model.mesh.setRecombine(2, surface)
        for _, volume in gmsh.model.getEntities(3):
            gmsh.model.mesh.setTransfiniteVolume(volume)

        def volume_at(x):
            return [t for _, t in gmsh.model.getEntitiesInBoundingBox(
                x - 0.3, -0.1, -0.1, x + 0.3, 0.6, 0.35, 3)]

        clamp = [t for _, t in gmsh.model.getEntitiesInBoundingBox(
            -1e-6, -1e-6, -1e-6, 1e-6, 0.51, 0.26, 2)]
        gmsh.model.addPhysicalGroup(3, volume_at(0.25), 1, name="soft")
        gmsh.model.addPhysicalGroup(3, volume_at(0.75), 2, name="stiff")
        gmsh.model.addPhysicalGroup(2, clamp, 3, name="clamp")
        gmsh.model.mesh.generate(3)
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
            gmsh.model.mesh.setOrder(2)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 0)
        gmsh.write(os.path.join(OUT, name))
        gmsh.finalize()


STEPS = [cube_msh, cube_others, surfaces, cube_meshio_compressed, cube_vtk_library,
         multi_solid_stl, cube_msh_other_forms, cube_regions, two_volumes, pneumatic_finger,
         two_volumes_vtu, two_volumes_tetgen, hexahedra, hollow_sphere, two_blocks_hex]

if __name__ == "__main__":
    import sys

    os.makedirs(OUT, exist_ok=True)
    by_name = {step.__name__: step for step in STEPS}
    unknown = [name for name in sys.argv[1:] if name not in by_name]
    if unknown:
        sys.exit("unknown function(s) %s; choose among %s"
                 % (", ".join(unknown), ", ".join(by_name)))
    for name in sys.argv[1:] or list(by_name):
        by_name[name]()
