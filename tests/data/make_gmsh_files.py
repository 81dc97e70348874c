"""Make the small reference meshes read by tests/test_mesh_io.f90 with Gmsh itself.

    python3 tests/data/make_gmsh_files.py [output-folder]   (default: this script's folder)

gmsh_tri10_v41.msh: quarter cylinder surface, radius 1, z in [0, 2], 10-node triangles, MSH 4.1.
gmsh_tri10_v22.msh: lateral surface of a closed cylinder (radius 1, z in [-0.5, 0.5]), 10-node
    triangles, MSH 2.2, saved through physical groups (wall surface + rim curves), so elements carry
    two tags and the file holds cubic line elements too.
Both are ASCII and also hold point or line elements, which casca's reader must skip.
(A sphere was tried first: Gmsh places the high-order nodes of a sphere at equal steps of its
distorted pole parametrization, and a few dozen elements then miss 4*pi*R^2 by ~4e-3.)
The number of type-21 elements printed here is written into the test as the independent answer.
"""
import math
import os
import sys

import gmsh


def mesh_and_save(path, version, save_all, surface=-1):
    gmsh.option.setNumber("Mesh.ElementOrder", 3)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)  # keep the centroid node: TRI10
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.option.setNumber("Mesh.SaveAll", save_all)
    gmsh.model.mesh.generate(2)
    tags, _ = gmsh.model.mesh.getElementsByType(21, surface)
    gmsh.write(path)
    print(f"{os.path.basename(path)}: {len(tags)} type-21 elements")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)

    # Quarter cylinder x^2 + y^2 = 1, x, y >= 0, 0 <= z <= 2: circular arc extruded along z.
    gmsh.model.add("quarter_cylinder")
    geo = gmsh.model.geo
    c = geo.addPoint(0, 0, 0)
    a = geo.addPoint(1, 0, 0)
    b = geo.addPoint(0, 1, 0)
    arc = geo.addCircleArc(a, c, b)
    geo.extrude([(1, arc)], 0, 0, 2)
    geo.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
    mesh_and_save(os.path.join(out, "gmsh_tri10_v41.msh"), 4.1, 1)
    gmsh.model.remove()

    # Cylinder x^2 + y^2 = 1, -0.5 <= z <= 0.5 (OpenCASCADE solid; only its lateral face is saved).
    gmsh.model.add("cylinder")
    gmsh.model.occ.addCylinder(0, 0, -0.5, 0, 0, 1, 1.0)
    gmsh.model.occ.synchronize()
    wall = [t for d, t in gmsh.model.getEntities(2)
            if abs(gmsh.model.occ.getMass(d, t) - 2 * math.pi) < 1e-9]
    rims = sorted({abs(t) for _, t in gmsh.model.getBoundary([(2, wall[0])], oriented=False)})
    gmsh.model.addPhysicalGroup(2, wall, name="wall")
    gmsh.model.addPhysicalGroup(1, rims, name="rims")
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.6)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.6)
    mesh_and_save(os.path.join(out, "gmsh_tri10_v22.msh"), 2.2, 0, wall[0])

    gmsh.finalize()
    print(f"analytic areas: quarter cylinder {math.pi:.15f}, cylinder wall {2 * math.pi:.15f}")


if __name__ == "__main__":
    main()
