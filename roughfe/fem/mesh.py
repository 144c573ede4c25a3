"""gmsh meshes of a plane-strain body whose top edge carries a rough profile.

The body is the rectangle ``0 <= x <= W``, ``-H_d <= y <= top(x)`` where ``W = (n-1) dx``
spans the first to the last sample of an ``n``-point profile (spacing ``dx``), and

* ``formulation="flat"`` (a, small slope, equivalent to the BEM): ``top(x) = 0``; the
  roughness enters only through the gap function of a rigid rough obstacle;
* ``formulation="profile"`` (b, finite slopes): ``top(x) = h(x) - mean(h)``; the profile
  is the real boundary of the body, pressed by a rigid flat.

The top edge is a polyline with one straight element between consecutive samples, so
every profile sample is a mesh vertex (top element size = dx). Below the top the element
size grows linearly with the distance from the highest top point,
``size(d) = dx (1 + growth d / dx) = dx + growth d``, capped at ``size_max``. A gentle
growth is essential: measured on the Westergaard problem, growth 0.3 gives 1-2.6 %% error
on the contact width, 0.1 gives <= 0.7 %%, 0.03 gives <= 0.14 %%.

The mesh is built in non-dimensional coordinates ``x / W`` (the length scale is stored
in :attr:`ProfileMesh.length_scale`), which keeps the VI solver's absolute tolerances
meaningful. They are unit-free: ``x_i / W = i / (n-1)``, ``dx / W = 1 / (n-1)``, and the
default depth and ``size_max`` are 2 and 1/4 exactly, so one profile gives the same mesh
and the same dimensionless answer at any dx (``i dx / ((n-1) dx)`` rounds with dx, and
gmsh turned those 1-ulp differences into other interior meshes). Physical groups (facet
tags): top = 1, bottom = 2, left = 3, right = 4; the domain is cell tag 1.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, Mapping

import numpy as np

from ..errors import InputError, check_finite_positive, check_instance
from ..surfaces import Surface
from ..frozen import FrozenMapping
from ..writers import atomic_path, output_file
from .limits import check_depth, check_mesh_size
from .petsc_tools import ensure_jit_cache

FACET_TAGS = {"top": 1, "bottom": 2, "left": 3, "right": 4}
DOMAIN_TAG = 1
Formulation = Literal["flat", "profile"]
FORMULATIONS = ("flat", "profile")


@dataclass(frozen=True, eq=False)
class ProfileMesh:
    """A meshed plane-strain body below a profile (non-dimensional coordinates).

    Attributes
    ----------
    mesh : dolfinx.mesh.Mesh
        Triangle mesh, coordinates divided by ``length_scale``.
    cell_tags, facet_tags : dolfinx.mesh.MeshTags
        Domain tag 1; facet tags :data:`FACET_TAGS`.
    heights : ndarray, shape (n,)
        Profile heights (m) at the top vertices, left to right.
    x : ndarray, shape (n,)
        Positions (m) of the top vertices, ``x[i] = i dx``.
    width, depth : float
        W = (n-1) dx and H_d (m).
    element_size : float
        Top element size dx (m).
    growth : float
        Growth rate of the element size with depth (dimensionless).
    length_scale : float
        Coordinates of ``mesh`` are physical coordinates / ``length_scale`` (= W).
    formulation : str
        ``"flat"`` or ``"profile"`` (see module docstring).
    n_cells : int
        Number of triangles.
    files : mapping
        Paths of the written ``.msh`` / ``.xdmf`` files (empty unless requested).
    """

    mesh: Any
    cell_tags: Any
    facet_tags: Any
    heights: np.ndarray
    x: np.ndarray
    width: float
    depth: float
    element_size: float
    growth: float
    length_scale: float
    formulation: str
    n_cells: int
    files: Mapping[str, Any]


def _check_profile(surface):
    check_instance("surface", surface, Surface, "a roughfe Surface")
    if surface.ndim != 1:
        raise InputError(f"the FEM body needs a 1D profile, got a surface of shape {surface.shape}")
    if surface.shape[0] < 3:
        raise InputError(f"a profile needs at least 3 samples for the FEM, got {surface.shape[0]}")
    return surface


def mesh_profile(surface: Surface, *, depth: float | None = None, growth: float = 0.1,
                 formulation: Formulation = "flat", size_max: float | None = None,
                 write_to: str | Path | None = None, name: str = "profile",
                 comm=None) -> ProfileMesh:
    """Mesh the plane-strain body below a profile with gmsh (see module docstring).

    Parameters
    ----------
    surface : Surface
        1D profile, heights (m); samples at ``x = i dx``, ``dx = surface.spacing[0]``.
    depth : float, optional
        Layer depth H_d (m). Default 2 W: one full wavelength of the evenly mirrored
        profile (period 2 W), whose longest mode then decays by exp(-2 pi) at the bottom.
        Shallower, a ResolutionWarning: the body is no longer the BEM's half-plane
        (measured on a cosine: p +1.8..3.3 % at W, +18..40 % at W/2;
        :mod:`roughfe.fem.limits`). A body thinner than dx is refused (InputError).
    growth : float
        Element-size growth with depth, ``size = dx + growth * distance`` (0 < growth <= 1).
    formulation : {"flat", "profile"}
        (a) flat top + rough rigid obstacle, or (b) the profile as the top boundary.
    size_max : float, optional
        Largest element size (m); default ``W / 4``.
    write_to : path, optional
        Folder (e.g. ``meshes/``, created if missing) where ``<name>.msh`` (gmsh, with the
        physical groups) and ``<name>.xdmf`` (meshio, inline XML data) are written
        atomically for inspection, both in metres (the solver's mesh stays in units of
        W); an existing file or a folder that cannot be created is an InputError.
    name : str
        File stem for ``write_to``: not empty, no ``/``.
    comm : MPI communicator, optional
        Default ``MPI.COMM_WORLD``; gmsh runs on rank 0 and dolfinx distributes the mesh.
    """
    ensure_jit_cache()
    import gmsh
    from dolfinx.io import gmshio
    from mpi4py import MPI

    surface = _check_profile(surface)
    if formulation not in FORMULATIONS:
        raise InputError(f"formulation must be one of {FORMULATIONS}, got {formulation!r}")
    if check_finite_positive("growth", growth) > 1.0:
        raise InputError(f"growth must lie in (0, 1], got {growth!r}")
    folder = None if write_to is None else _check_output(write_to, name)
    comm = MPI.COMM_WORLD if comm is None else comm
    h = np.asarray(surface.heights, dtype=float)
    n = h.size
    dx = surface.spacing[0]
    width = (n - 1) * dx
    depth = 2.0 * width if depth is None else check_finite_positive("depth", depth)
    size_max = width / 4 if size_max is None else check_finite_positive("size_max", size_max)
    size_max = max(size_max, dx)
    scale = width
    # the mesh's coordinates in units of W, unit-free: x / W and dx / W from the sample
    # index (i dx / ((n-1) dx) rounds with dx, and gmsh made a different interior mesh of
    # the same profile from the 1-ulp differences: p/E* 4.4e-5 apart at dx = 1 m and 1 mm)
    xs, d = np.arange(n) / (n - 1), 1.0 / (n - 1)
    H = depth / width                   # 2 exactly by default
    smax = d if size_max <= dx else size_max / width
    x = np.arange(n) * dx
    top_y = np.zeros(n) if formulation == "flat" else h - h.mean()
    if formulation == "profile" and -depth >= top_y.min():
        raise InputError(f"depth {depth!r} m does not reach below the lowest profile point")
    check_depth(depth, width, dx, depth + float(top_y.min()))
    check_mesh_size(width, depth + float(top_y.max()), dx, growth, size_max)

    files = {}
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        # never stop to ask on the terminal ("Do you really want to continue?" on a
        # large mesh: a batch job waited there for ever); the size is checked above
        gmsh.option.setNumber("General.ExpertMode", 1)
        gmsh.model.add(name)
        if comm.rank == 0:
            geo = gmsh.model.geo
            ys = top_y / scale
            p_bl = geo.addPoint(0.0, -H, 0.0, smax)
            p_br = geo.addPoint(1.0, -H, 0.0, smax)
            top_pts = [geo.addPoint(float(xi), float(yi), 0.0, d) for xi, yi in zip(xs, ys)]
            bottom = geo.addLine(p_bl, p_br)
            right = geo.addLine(p_br, top_pts[-1])
            top = [geo.addLine(top_pts[i + 1], top_pts[i]) for i in range(n - 2, -1, -1)]
            left = geo.addLine(top_pts[0], p_bl)
            loop = geo.addCurveLoop([bottom, right, *top, left])
            surf = geo.addPlaneSurface([loop])
            for c in top:
                geo.mesh.setTransfiniteCurve(c, 2)
            geo.synchronize()
            for key, curves in (("top", top), ("bottom", [bottom]), ("left", [left]),
                                ("right", [right])):
                gmsh.model.addPhysicalGroup(1, curves, FACET_TAGS[key])
                gmsh.model.setPhysicalName(1, FACET_TAGS[key], key)
            gmsh.model.addPhysicalGroup(2, [surf], DOMAIN_TAG)
            gmsh.model.setPhysicalName(2, DOMAIN_TAG, "body")
            field = gmsh.model.mesh.field.add("MathEval")
            ytop = float(ys.max())
            size = f"Min({d!r} + {float(growth)!r} * ({ytop!r} - y), {smax!r})"
            gmsh.model.mesh.field.setString(field, "F", size)
            gmsh.model.mesh.field.setAsBackgroundMesh(field)
            for opt in ("Mesh.CharacteristicLengthExtendFromBoundary",
                        "Mesh.CharacteristicLengthFromPoints",
                        "Mesh.CharacteristicLengthFromCurvature"):
                gmsh.option.setNumber(opt, 0)
            gmsh.option.setNumber("Mesh.Algorithm", 6)       # Frontal-Delaunay
            gmsh.model.mesh.generate(2)
        mesh, cell_tags, facet_tags = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=2)
        if comm.rank == 0 and folder is not None:
            files = _write_mesh_files(folder, name, scale)     # (rescales the gmsh model)
    finally:
        gmsh.finalize()
    files = comm.bcast(files, root=0)
    n_cells = comm.allreduce(mesh.topology.index_map(2).size_local, op=MPI.SUM)
    h_ro = h.copy()
    h_ro.setflags(write=False)
    x.setflags(write=False)
    return ProfileMesh(mesh, cell_tags, facet_tags, h_ro, x, float(width), float(depth),
                       float(dx), float(growth), float(scale), formulation, int(n_cells),
                       FrozenMapping(files))


def _check_output(write_to, name) -> Path:
    """The folder ``write_to`` of the mesh files, checked: ``name`` a non-empty file stem
    without ``/``, ``<name>.msh`` and ``<name>.xdmf`` writable there (the folder exists or
    can be created; :func:`roughfe.writers.output_file`); an InputError otherwise."""
    if not isinstance(name, str) or not name.strip() or "/" in name or "\0" in name:
        raise InputError(f"name (the file stem of the mesh files) must be a non-empty "
                         f"name without '/', got {name!r}")
    folder = Path(write_to)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"write_to must be a folder for {name}.msh and {name}.xdmf, got "
                         f"the existing file {str(folder)!r}")
    for suffix in (".msh", ".xdmf"):
        output_file(folder / f"{name}{suffix}", overwrite=True)
    return folder


def _write_mesh_files(folder: Path, name: str, scale: float) -> dict:
    """Write the current gmsh model in metres as ``.msh`` (gmsh) and XDMF (meshio).

    The model is built in units of ``scale`` (= W); its geometry and its mesh nodes are
    scaled by ``scale`` in place first (gmsh 4.8 has no mesh.affineTransform: node by
    node), so call this after the dolfinx mesh has been made from the model.
    """
    import gmsh
    import meshio

    gmsh.model.geo.dilate(gmsh.model.getEntities(0), 0.0, 0.0, 0.0, scale, scale, scale)
    gmsh.model.geo.synchronize()                      # the .msh entities' bounding boxes
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    coords = coords.reshape(-1, 3) * scale
    for tag, xyz in zip(node_tags.tolist(), coords.tolist()):
        gmsh.model.mesh.setNode(tag, xyz, [])
    msh = folder / f"{name}.msh"
    with atomic_path(msh) as tmp:
        gmsh.write(str(tmp))
    _, nodes = gmsh.model.mesh.getElementsByType(2)           # 3-node triangles
    index = np.empty(int(node_tags.max()) + 1, dtype=np.int64)
    index[node_tags.astype(np.int64)] = np.arange(node_tags.size)
    points = coords[:, :2]
    cells = index[nodes.astype(np.int64)].reshape(-1, 3)
    xdmf = folder / f"{name}.xdmf"
    with atomic_path(xdmf) as tmp:
        meshio.xdmf.write(str(tmp), meshio.Mesh(points, [("triangle", cells)]),
                          data_format="XML")
    return {"msh": str(msh), "xdmf": str(xdmf)}


def mirrored_profile(surface: Surface) -> Surface:
    """The evenly mirrored profile, periodic with period 2 W (W = (n-1) dx).

    Samples ``h_0, h_1, ..., h_{n-1}, h_{n-2}, ..., h_1`` (2 (n-1) values, spacing dx).
    Rollers (u_x = 0, zero shear) at x = 0 and x = W are exact symmetry planes of this
    periodic problem, so the periodic plane-strain BEM on the mirrored profile is the
    reference of the FEM body with rollers. Contact quantities of the FEM body equal
    those of one half period: interior samples appear twice in the mirror, end samples
    once, matching their tributary lengths dx and dx/2 in the FEM.
    """
    return _check_profile(surface).mirrored()
