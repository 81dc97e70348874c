"""Add Gmsh physical groups to casca's generated cantilever strip (10 x 1, 10 x 1 cells of
10-node triangles), as Gmsh would write them for a strip whose short edges are named curves:

    casca mesh strip --lx 10 --ly 1 --nx 10 --ny 1 -o strip.msh
    python3 tests/data/make_strip_sets.py strip.msh tests/data

strip_sets_v41.msh (MSH 4.1): $Entities with two curves (tags 1 and 2, physical groups 1
    'clamped' at x = 0 and 2 'tip' at x = 10) and the surface (physical group 3 'strip'),
    $PhysicalNames, and each short edge as one 4-node cubic line element (Gmsh type 26: end
    nodes first, then the inner two).
strip_sets_v22.msh (MSH 2.2): the same groups on the same elements, physical tags as the
    elements' first tag.
The nodes and triangles are the generator's, unchanged (so a deck may compare the file with
mesh = 'strip').
"""
import os
import sys


def read_msh41(path):
    lines = open(path).read().split("\n")
    i = lines.index("$Nodes")
    nblocks, nnodes = map(int, lines[i + 1].split()[:2])
    assert nblocks == 1
    tags = [int(t) for t in lines[i + 3:i + 3 + nnodes]]
    xyz = [lines[i + 3 + nnodes + k] for k in range(nnodes)]
    j = lines.index("$Elements")
    nel = int(lines[j + 1].split()[1])
    tris = [lines[j + 3 + k].split() for k in range(nel)]
    return tags, xyz, tris


def main():
    src, out = sys.argv[1], sys.argv[2]
    tags, xyz, tris = read_msh41(src)
    x = {t: [float(v) for v in s.split()] for t, s in zip(tags, xyz)}
    edges = {}
    for name, x_edge in (("clamped", 0.0), ("tip", 10.0)):
        on = sorted((t for t in tags if abs(x[t][0] - x_edge) < 1e-12), key=lambda t: x[t][1])
        assert len(on) == 4, on
        edges[name] = [on[0], on[3], on[1], on[2]]   # Gmsh line4: ends, then inner nodes
    names = [(1, 1, "clamped"), (1, 2, "tip"), (2, 3, "strip")]

    with open(os.path.join(out, "strip_sets_v41.msh"), "w") as f:
        f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
        f.write("$PhysicalNames\n3\n" + "".join('%d %d "%s"\n' % n for n in names) + "$EndPhysicalNames\n")
        f.write("$Entities\n0 2 1 0\n")
        f.write("1 0 0 0 0 1 0 1 1 0\n")      # curve 1, physical 1, no bounding points
        f.write("2 10 0 0 10 1 0 1 2 0\n")    # curve 2, physical 2
        f.write("1 0 0 0 10 1 0 1 3 0\n")     # surface 1, physical 3, no bounding curves
        f.write("$EndEntities\n")
        f.write("$Nodes\n1 %d 1 %d\n2 1 0 %d\n" % (len(tags), max(tags), len(tags)))
        f.write("".join("%d\n" % t for t in tags) + "".join(s + "\n" for s in xyz) + "$EndNodes\n")
        n = len(tris)
        f.write("$Elements\n3 %d 1 %d\n" % (n + 2, n + 2))
        f.write("1 1 26 1\n%d %s\n" % (n + 1, " ".join(map(str, edges["clamped"]))))
        f.write("1 2 26 1\n%d %s\n" % (n + 2, " ".join(map(str, edges["tip"]))))
        f.write("2 1 21 %d\n" % n + "".join(" ".join(t) + "\n" for t in tris))
        f.write("$EndElements\n")

    with open(os.path.join(out, "strip_sets_v22.msh"), "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
        f.write("$PhysicalNames\n3\n" + "".join('%d %d "%s"\n' % n for n in names) + "$EndPhysicalNames\n")
        f.write("$Nodes\n%d\n" % len(tags) + "".join("%d %s\n" % (t, s) for t, s in zip(tags, xyz)) + "$EndNodes\n")
        f.write("$Elements\n%d\n" % (len(tris) + 2))
        f.write("1 26 2 1 1 %s\n" % " ".join(map(str, edges["clamped"])))
        f.write("2 26 2 2 2 %s\n" % " ".join(map(str, edges["tip"])))
        for k, t in enumerate(tris):
            f.write("%d 21 2 3 1 %s\n" % (k + 3, " ".join(t[1:])))
        f.write("$EndElements\n")


if __name__ == "__main__":
    main()
