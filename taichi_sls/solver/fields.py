"""The Taichi fields of one simulation: material points, grid nodes, the run's scalars, the
parameter tables and the surface-tension scratch, each a named struct field.

Points (``points``, one element per material point; SI):
  x, x0 position now and at the start; v velocity; C APIC affine velocity; F deformation
  gradient; J its determinant; strain the accumulated small strain (eqs. 16-17); plastic_strain
  (3x3, plane strain); equivalent_plastic_strain (eq. 43); iso_strain the isotropic thermal and
  transformation strain (eqs. 36-37) and iso_strain_step its increment per mechanical step;
  stress (3x3, Cauchy); elastic_stretch the 3x3 elastic left stretch V_e of solver.strain =
  "finite" (identity at rest) and stress_phase the solid fraction at which its strain was last
  turned into stress (physics/constitutive.py, hencky_update); viscous_stress the melt's solvent
  stress (force only); volume0; mass; material (index); enthalpy (J/kg); T (K); solid_fraction
  (eq. 33); time_molten (s above T_m, the fusion verdict's input).
Nodes (``nodes``, the grid of ``nx x ny``):
  mass, momentum, force; v_old = v^n and v = v^{n+1}; heat_capacity (eq. 28), capacity_T
  (sum c T), T, heat_rate (eqs. 29-30), dT, deviation and deviation_capacity (the sub-grid
  filter, physics/thermal.py); the CSF method's phi_raw (eq. 21), phi (signed
  distance), phi_smooth, kappa, scratch, flags (NodeFlag bits) and mass_gradient (eq. 20); the
  surface-energy method's volume (the volume colour), colour (the contoured one) and
  surface_force (before the mass floor).
Scalars (``scalars``): t, step (steps taken: the phase of the clocks), dt, dt_heat (the heat
  substep of the implicit step), laser_energy,
  heat_out (heat through fixed-temperature walls, and the heat a held temperature takes),
  T_peak (running maximum), and for each of WATCHED the first step at which a point showed it
  (NEVER if none), so that the guard, which looks once per frame, can name what broke first.
Totals (``totals``): the monitors' reductions over the points (solver/monitor.py).
Imposed (``imposed``): the rows (t in s, T in K) of the temperature history every point is held
at (``thermal.imposed_temperature_csv``; physics/thermal.py ``hold_temperature``).
"""

import numpy as np

from taichi_sls.backend import ti

from ..physics.beam_surface import column_shape
from ..physics.constitutive import embed3, moduli, perzyna_update
from ..physics.curvature import fit_matrix
from ..physics.laser import laser_struct
from ..physics.materials import (
    KELVIN,
    enthalpy,
    enthalpy_history,
    material_struct,
    solid_fraction,
)
from ..physics.small_matrix import IDENTITY, ZERO_MATRIX
from ..physics.stiffness import WIDTH
from . import struct_copy
from .scene import Scene
from .step_config import StepConfig

# what the step watches at every point (solver/step.py, watch): a runaway temperature, an
# inverted point, NaN; the first step at which each was seen is kept in the scalars
WATCHED = ("hot", "inverted", "nan")
NEVER = 2**31 - 1

# reductions over the points, read once per output frame (solver/monitor.py)
TOTALS = (
    "T_max",
    "mass_T",
    "mass",
    "molten_mass",
    "enthalpy",
    "kinetic_energy",
    "J_min",
    "J_max",
    "T_min",
    "v_max",
    "trouble",  # a Trouble code: NaN, a point off the grid
)


POINT_MEMBERS = {
    "x": "vector",
    "x0": "vector",
    "v": "vector",
    "C": "matrix",
    "F": "matrix",
    "strain": "matrix",
    "plastic_strain": "matrix3",
    "equivalent_plastic_strain": "scalar",
    "iso_strain": "scalar",
    "iso_strain_step": "scalar",
    "stress": "matrix3",
    "elastic_stretch": "matrix3",
    "stress_phase": "scalar",
    "viscous_stress": "matrix",
    "volume0": "scalar",
    "J": "scalar",
    "mass": "scalar",
    "material": "index",
    "enthalpy": "scalar",
    "T": "scalar",
    "solid_fraction": "scalar",
    "time_molten": "scalar",
}
NODE_MEMBERS = {
    "mass": "scalar",
    "momentum": "vector",
    "force": "vector",
    "v_old": "vector",
    "v": "vector",
    "heat_capacity": "scalar",
    "capacity_T": "scalar",
    "T": "scalar",
    "heat_rate": "scalar",
    "dT": "scalar",
    "deviation": "scalar",
    "deviation_capacity": "scalar",
    "phi_raw": "scalar",
    "phi": "scalar",
    "phi_smooth": "scalar",
    "kappa": "scalar",
    "scratch": "scalar",
    "flags": "index",
    "mass_gradient": "vector",
    "colour": "scalar",
    "surface_force": "vector",
    "pressure_force": "vector",  # solver.dilatation = "cell": before its mass floor
}


# the node members the host ever copies (the level-set fill, checkpoints, the neck measures):
# the nodes' copy kernels range over these alone (solver/struct_copy.py)
NODE_COPIES = ("phi_raw", "phi", "phi_smooth", "kappa", "flags", "colour", "mass")


def struct_type(members: dict[str, str], dim: int):
    """A Taichi struct type from member kinds (after ti.init: ``float`` is the precision)."""
    kinds = {
        "scalar": float,
        "index": ti.i32,
        "vector": ti.types.vector(dim, float),
        "matrix": ti.types.matrix(dim, dim, float),
        "matrix3": ti.types.matrix(3, 3, float),
    }
    return ti.types.struct(**{k: kinds[v] for k, v in members.items()})


@ti.data_oriented
class SurfaceScratch:
    """Per-rebuild data of the CSF method: contour segments (up to two per cell, end points in
    metres), the list of interface nodes, the eq. 23 fit matrix and the force resultant."""

    def __init__(self, nx: int, ny: int) -> None:
        self.ends = ti.Vector.field(8, float, (nx - 1, ny - 1))
        self.count = ti.field(ti.i32, (nx - 1, ny - 1))
        self.iface = ti.Vector.field(2, ti.i32, nx * ny)
        self.n_iface = ti.field(ti.i32, ())
        self.fit = ti.Matrix.field(6, 9, float, ())
        self.resultant = ti.Vector.field(3, float, ())  # force x, y and interface mass


ROW_BLOCK = 4  # nodes along each edge of a block of 3D rows (time.implicit_rows = "blocks")


def row_field(grid: tuple[int, ...], row: tuple[int, ...], sparse: bool) -> ti.Field:
    """A field of one row per grid node (``row`` its shape): dense over the grid, or (3D,
    ``sparse``) a pointer over blocks of ROW_BLOCK^3 nodes, each block allocated when the step
    first writes into it, so that the rows' memory follows the nodes near material and not the
    whole grid. An unwritten row reads 0."""
    if not sparse:
        return ti.field(float, grid + row)
    f = ti.field(float)
    blocks = tuple(-(-n // ROW_BLOCK) for n in grid)
    nodes = ti.root.pointer(ti.ijk, blocks).dense(ti.ijk, ROW_BLOCK)
    nodes.dense(ti.axes(*range(len(grid), len(grid) + len(row))), row).place(f)
    return f


def allocated_row_nodes(K, dim: int) -> int:
    """How many grid nodes a row field holds storage for: all of them when dense, those of
    the blocks written so far when sparse (their bytes: this times the row's)."""
    return int(_count_allocated(K)) // int(np.prod(K.shape[dim:]))


@ti.kernel
def _count_allocated(K: ti.template()) -> ti.i64:
    n = ti.i64(0)
    for _ in ti.grouped(K):
        n += 1
    return n


@ti.kernel
def clear_rows(K: ti.template()):
    """Zero the allocated blocks of a sparse row field (solver/fields.py ``row_field``): a
    struct-for visits only those, where the dense rows are cleared node by node over the box."""
    for idx in ti.grouped(K):
        K[idx] = 0.0


@ti.data_oriented
class ImplicitFields:
    """The implicit step's grid data (solver/implicit.py, physics/stiffness.py): the fixed part
    of its matrix (inertia, capillary stiffness) and the points' tangent, both as node i's row
    over the WIDTH^dim nodes around it; the internal force; which velocity components are free
    (1) and their unknown's index (-1: none). The fixed part is a scalar times the identity in
    the components (one value per neighbour, not dim x dim: 1 kB of a node's 10 in 3D, where
    the full rows would take 18)."""

    def __init__(self, cfg: StepConfig) -> None:
        grid = tuple(cfg.shape)
        row = grid + (WIDTH,) * cfg.dim
        # 3D, time.implicit_rows: the rows by blocks of nodes that the step writes
        # (clear_rows below empties them)
        self.fixed = row_field(grid, (WIDTH,) * cfg.dim, cfg.sparse_rows)
        if cfg.matrix_free:  # the tangent is applied through the points (solver/multigrid.py)
            self.tangent = ti.field(float, (1,) * (2 * cfg.dim + 2))
            # each point's tangent, (V, a_lambda, a_mu) (physics/tangent_operator.py)
            self.moduli = ti.Vector.field(3, float, cfg.n_points)
        else:
            self.tangent = row_field(grid, (WIDTH,) * cfg.dim + (cfg.dim, cfg.dim), cfg.sparse_rows)
        self.internal = ti.Vector.field(cfg.dim, float, grid)
        self.with_tangent = ti.field(ti.i32, ())  # internal_force assembles the tangent too
        # which nodes are unknowns and their numbers, one struct: the host reads the kinds and
        # writes the numbers through one copy kernel each way (solver/struct_copy.py)
        numbering = {
            "free": ti.types.vector(cfg.dim, ti.i32),
            "dof": ti.types.vector(cfg.dim, ti.i32),
        }
        if cfg.heat_implicit:  # backward-Euler heat (solver/implicit_heat.py)
            self.conductance = ti.field(float, row)
            numbering["heat_node"] = ti.i32  # physics.codes.HeatNode
            numbering["heat_dof"] = ti.i32  # a free node's unknown (-1: none)
        self.numbering = ti.types.struct(**numbering).field(shape=grid, layout=ti.Layout.SOA)
        self.free, self.dof = self.numbering.free, self.numbering.dof
        if cfg.heat_implicit:
            self.heat_node, self.heat_dof = self.numbering.heat_node, self.numbering.heat_dof


@ti.data_oriented
class State:
    """Every field of a run; ``cfg`` (StepConfig) is the compile-time configuration."""

    def __init__(
        self,
        cfg: StepConfig,
        scene: Scene,
        materials: dict[str, np.ndarray],
        lasers: dict[str, np.ndarray],
        blocks=None,
        imposed: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> None:
        self.cfg = cfg
        self.blocks = blocks  # the blocks layout's plan (solver/blocks.py), else None
        self.scene = scene
        self.points = struct_type(POINT_MEMBERS, cfg.dim).field(
            shape=scene.n_points, layout=ti.Layout.SOA
        )
        self.nodes = struct_type(NODE_MEMBERS, cfg.dim).field(shape=cfg.shape, layout=ti.Layout.SOA)
        struct_copy.copies_among(self.nodes, NODE_COPIES)
        self.scalars = ti.types.struct(
            t=float,
            step=ti.i32,
            dt=float,
            dt_heat=float,
            laser_energy=float,
            heat_out=float,
            T_peak=float,
            **{f"first_{k}": ti.i32 for k in WATCHED},
        ).field(shape=())
        n_mat = len(scene.material_names)
        self.materials = material_struct().field(shape=n_mat, layout=ti.Layout.SOA)
        self.lasers = laser_struct().field(shape=max(cfg.n_lasers, 1), layout=ti.Layout.SOA)
        self.surf = SurfaceScratch(cfg.nx, cfg.ny)
        # the beam's local surface per column (physics/beam_surface.py); one cell when unused
        self.column_top = ti.field(float, column_shape(cfg) if cfg.local_surface else (1,))
        # active region [i0, j0, i1, j1) ([i0, j0, k0, i1, j1, k1) in 3D): lower corner, upper
        self.box = ti.Vector.field(2 * cfg.dim, ti.i32, ())
        self.totals = ti.types.struct(**{k: float for k in TOTALS}).field(shape=())
        # the held temperature history (thermal.imposed_temperature_csv): t (s), T (K) per row;
        # one unused row when none
        self.imposed = ti.types.struct(t=float, T=float).field(shape=max(cfg.imposed, 1))
        self.implicit = ImplicitFields(cfg) if cfg.implicit else None
        structs = [self.points, self.nodes, self.scalars, self.materials, self.lasers, self.totals]
        if self.implicit is not None:
            structs.append(self.implicit.numbering)
        struct_copy.share_kernel(*structs)  # one copy kernel for all of them
        self._fill(materials, lasers, imposed)

    @property
    def n_points(self) -> int:
        return self.cfg.n_points

    def _fill(
        self,
        materials: dict[str, np.ndarray],
        lasers: dict[str, np.ndarray],
        imposed: tuple[np.ndarray, np.ndarray] | None,
    ) -> None:
        cfg, sc = self.cfg, self.scene
        struct_copy.from_numpy(self.materials, materials)
        rho = materials["density_kg_m3"][sc.material]
        pt = ti.static(self.points)
        seeded = {"x": sc.x, "x0": sc.x, "v": sc.v0, "volume0": sc.vol, "mass": sc.vol * rho}
        seeded.update(material=sc.material, T=sc.T0_C + KELVIN)
        struct_copy.from_numpy(pt, seeded)
        self.surf.fit[None] = fit_matrix()
        # outside the active region the grid keeps these: empty, and outside every body
        cap = np.full(cfg.shape, cfg.phi_cap)
        struct_copy.from_numpy(self.nodes, {"phi_raw": cap, "phi": cap, "phi_smooth": cap})
        full = [0] * cfg.dim + list(cfg.shape)
        self.box[None] = list(cfg.shape) + [0] * cfg.dim if cfg.active_region else full
        if cfg.n_lasers:
            struct_copy.from_numpy(self.lasers, lasers)
        if cfg.imposed:
            t_s, T_K = imposed
            self.imposed.t.from_numpy(np.asarray(t_s, dtype=np.float64))
            self.imposed.T.from_numpy(np.asarray(T_K, dtype=np.float64))
        self.scalars.t[None] = 0.0
        self.scalars.T_peak[None] = float(np.max(sc.T0_C + KELVIN))
        for k in WATCHED:
            getattr(self.scalars, f"first_{k}")[None] = NEVER
        self._init_points(np.ascontiguousarray(sc.p0, dtype=np.float64))
        if sc.carried is not None:  # a previous layer's points keep their deformation and stress
            now = struct_copy.to_numpy(pt, sc.carried_state.keys())
            for name, values in sc.carried_state.items():
                now[name][sc.carried] = values[sc.carried]
            struct_copy.from_numpy(pt, now)
            if "solid_fraction" in sc.carried_state:  # a melt restarts molten: H(T, xi)
                self._enthalpy_at_fraction()

    @ti.kernel
    def _init_points(self, p0: ti.types.ndarray()):
        """Each point's initial state: undeformed, unstressed, its enthalpy and solid fraction
        at its temperature; prestressed where p0 (Pa) is not zero (:meth:`_prestress`). One
        kernel for both (a kernel's compilation costs tens of ms whatever its size)."""
        pt = ti.static(self.points)
        for p in range(self.cfg.n_points):
            pt.F[p] = ti.Matrix(IDENTITY[self.cfg.dim])
            pt.J[p] = 1.0
            pt.C[p] = ti.Matrix(ZERO_MATRIX[self.cfg.dim, self.cfg.dim])
            pt.strain[p] = ti.Matrix(ZERO_MATRIX[self.cfg.dim, self.cfg.dim])
            pt.plastic_strain[p] = ti.Matrix(ZERO_MATRIX[3, 3])
            pt.stress[p] = ti.Matrix(ZERO_MATRIX[3, 3])
            pt.elastic_stretch[p] = ti.Matrix(IDENTITY[3])
            pt.viscous_stress[p] = ti.Matrix(ZERO_MATRIX[self.cfg.dim, self.cfg.dim])
            pt.equivalent_plastic_strain[p] = 0.0
            pt.iso_strain[p] = 0.0
            pt.iso_strain_step[p] = 0.0
            pt.enthalpy[p] = enthalpy(self.materials[pt.material[p]], pt.T[p])
            pt.solid_fraction[p] = solid_fraction(self.materials[pt.material[p]], pt.T[p])
            pt.stress_phase[p] = pt.solid_fraction[p]
            if p0[p] != 0.0:
                self._prestress(p, p0[p])

    @ti.kernel
    def _enthalpy_at_fraction(self):
        """Each point's enthalpy at its temperature and its (carried) solid fraction; the
        points seeded here hold their temperature's fraction, so theirs is unchanged."""
        pt = ti.static(self.points)
        for p in range(self.cfg.n_points):
            mp = self.materials[pt.material[p]]
            pt.enthalpy[p] = enthalpy_history(mp, pt.T[p], pt.solid_fraction[p])

    @ti.func
    def _prestress(self, p, p0):
        """The elastic strain that carries a pressure p0 (plane strain, eps_zz = 0:
        eps_xx = eps_yy = -p0 / 2 (lambda + mu); 3D: -p0 / 3 K on each axis) at the point's
        initial moduli, and its stress under the case's stress reading; finite strain: the
        elastic stretch Fe = exp(eps) of the same strain, whose Hencky stress at J = 1 is the
        same."""
        pt = ti.static(self.points)
        mp = self.materials[pt.material[p]]
        xi = pt.solid_fraction[p]
        E, nu = moduli(mp, xi)
        lam_mu = E / (2.0 * (1.0 + nu) * (1.0 - 2.0 * nu))  # lambda + mu
        stiff = 2.0 * lam_mu  # plane strain: eps_xx = eps_yy = eps carries 2 (lambda + mu) eps
        if ti.static(self.cfg.dim == 3):
            stiff = E / (1.0 - 2.0 * nu)  # a sphere's isotropic eps carries 3 K eps
        eps = ti.Matrix(IDENTITY[self.cfg.dim]) * (-p0 / stiff)
        pt.strain[p] = eps
        for a in ti.static(range(self.cfg.dim)):
            pt.elastic_stretch[p][a, a] = ti.exp(eps[a, a])
        z = ti.Matrix(ZERO_MATRIX[3, 3])
        pt.stress[p] = perzyna_update(
            mp, embed3(eps), z, 0.0, 0.0, xi, pt.T[p], 1.0, False, self.cfg.stress_reading
        )[0]

    def node_position(self, *idx: int) -> tuple[float, ...]:
        """The position (m) of the node with array indices ``idx`` (one per axis)."""
        return tuple((i - self.cfg.off) * self.cfg.h for i in idx)
