"""gmsh geometry as code, meshes with named physical groups, and a mesh cache."""
