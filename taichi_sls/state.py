"""The Taichi fields of one simulation: material points, background grid, and scalars.

Static configuration (sizes, feature switches, boundary kinds) is kept as plain Python
attributes so that kernels read it through ``ti.static`` and a case compiles only the physics it
uses. Everything that may change during a run (time step, laser settings) lives in fields.
"""

import math

import numpy as np
import taichi as ti

from .case import Case
from .constitutive import embed3, perzyna_update
from .materials import KELVIN, N_PARAMS, enthalpy, lerp_phase, material_row, solid_fraction
from .scene import Scene

TRANSFERS = {"flip": 0, "pic_flip": 1, "apic": 2}
WALL_MECH = {"slip": 0, "stick": 1, "open": 2}
LASER_PARAMS = ("on", "off", "x0", "speed", "x_end", "top", "amp", "r0", "eta", "sign")
LP = {n: i for i, n in enumerate(LASER_PARAMS)}


def parallel_layout(case: Case) -> bool:
    """One parallel kernel call per step (True) or many serialized steps per call (False)."""
    lay = case.solver.layout
    if lay == "auto":
        return case.solver.arch == "gpu"
    return lay == "parallel"


@ti.func
def active(st: ti.template(), shrink: ti.template() = 0):
    """Index ranges of the active region (``solver.active_region``) for ti.ndrange; ``shrink``
    drops that many nodes at the upper end (1: cells between active nodes)."""
    b = st.box[None]
    return (b[0], b[2] - shrink), (b[1], b[3] - shrink)


@ti.data_oriented
class State:
    def __init__(
        self, case: Case, scene: Scene, heat_every: int = 1, curvature_every: int = 1
    ) -> None:
        dim = 2
        self.dim = dim
        self.case = case
        self.scene = scene
        n = scene.n_points
        self.n_points = n
        self.nx, self.ny, self.off = scene.nx, scene.ny, scene.off
        self.h = scene.h
        self.inv_h = 1.0 / scene.h
        self.lp = scene.h / (2 * case.grid.points_per_cell)  # uGIMP half-width (h/4 for 2x2)
        self.ncx = int(round(scene.width / scene.h))
        self.ncy = int(round(scene.height / scene.h))

        self.parallel = parallel_layout(case)
        ph = case.physics
        self.mech = ph.mechanics
        self.thermal = ph.thermal
        self.surface = ph.surface_tension and ph.mechanics
        self.plastic = ph.plasticity
        self.paper_stress = case.solver.stress_reading == "paper"
        self.th_strain = ph.thermal_strain and ph.thermal
        self.gravity = tuple(ph.gravity_m_s2)
        self.has_gravity = any(g != 0.0 for g in self.gravity)
        self.n_lasers = len(case.lasers)
        self.laser = self.thermal and any(las.power_W > 0 for las in case.lasers)
        self.transfer = TRANSFERS[case.solver.transfer]
        self.musl = case.solver.update == "musl"
        self.flip_ratio = case.solver.flip_ratio
        b = case.boundary
        self.wall_mech = tuple(WALL_MECH[w.mechanical] for w in (b.left, b.right, b.bottom, b.top))
        self.wall_fixed = tuple(w.thermal == "fixed" for w in (b.left, b.right, b.bottom, b.top))
        self.wall_T = tuple(w.temperature_C + KELVIN for w in (b.left, b.right, b.bottom, b.top))
        self.any_fixed = self.thermal and any(self.wall_fixed)

        st = case.surface_tension
        self.r_p = st.point_radius_over_h * scene.h
        self.band = st.band_cells
        self.redistance = st.level_set == "redistanced"
        self.smooth_passes = st.smoothing_passes
        self.geom_every = curvature_every if self.surface else 1
        self.heat_every = heat_every if self.thermal else 1
        self.blur_passes = st.level_set_smoothing_passes
        self.zero_net_force = st.zero_net_force
        self.csf_c0 = st.colour_threshold
        self.kappa_cap = st.curvature_cap_h / scene.h if st.curvature_cap_h > 0 else 0.0
        self.phi_cap = (st.band_cells + 1) * scene.h
        self.active_region = case.solver.active_region
        # nodes beyond the points' footprint that the full-grid step would still change: the
        # level-set band and the blur's reach, plus one for the 3x3 fits
        self.box_margin = st.band_cells + st.level_set_smoothing_passes + 2 if self.surface else 0

        first = case.materials[case.bodies[0].material]
        self.rho_ref = first.density_kg_m3
        self.gamma = first.surface_tension_N_m
        self.cell_volume = scene.h**dim
        self.mass_cut = case.solver.small_mass * self.rho_ref * self.cell_volume

        vec = ti.types.vector(dim, float)
        mat2 = ti.types.matrix(dim, dim, float)
        mat3 = ti.types.matrix(3, 3, float)
        # ---- material points
        self.x = ti.Vector.field(dim, float, n)
        self.x0 = ti.Vector.field(dim, float, n)
        self.v = ti.Vector.field(dim, float, n)
        self.C = ti.Matrix.field(dim, dim, float, n)  # APIC affine velocity
        self.F = ti.Matrix.field(dim, dim, float, n)
        self.eps = ti.Matrix.field(dim, dim, float, n)  # accumulated small strain (eqs. 16-17)
        self.eps_pl = ti.Matrix.field(3, 3, float, n)  # plastic strain (plane strain: 3x3)
        self.alpha = ti.field(float, n)  # equivalent plastic strain (eq. 43)
        self.e_iso = ti.field(float, n)  # thermal + transformation strain, isotropic (eqs. 36-37)
        self.de_iso = ti.field(float, n)  # its increment per mechanical step
        self.sigma = ti.Matrix.field(3, 3, float, n)
        self.vol0 = ti.field(float, n)
        self.J = ti.field(float, n)
        self.mass = ti.field(float, n)
        self.mat = ti.field(ti.i32, n)
        self.H = ti.field(float, n)  # enthalpy (J/kg)
        self.T = ti.field(float, n)  # temperature (K)
        self.xi = ti.field(float, n)  # solid fraction (eq. 33)
        # ---- grid
        gs = (scene.nx, scene.ny)
        self.gm = ti.field(float, gs)
        self.gmv = ti.Vector.field(dim, float, gs)
        self.gf = ti.Vector.field(dim, float, gs)
        self.gvn = ti.Vector.field(dim, float, gs)  # v^n (for FLIP increments)
        self.gv = ti.Vector.field(dim, float, gs)  # v^{n+1}
        self.gcap = ti.field(float, gs)  # heat capacity c_i (eq. 28), J/K per depth
        self.gcT = ti.field(float, gs)
        self.gT = ti.field(float, gs)
        self.gQ = ti.field(float, gs)  # heat rate Q_int + Q_ext (eqs. 29-30)
        self.gdT = ti.field(float, gs)
        self.phi_raw = ti.field(float, gs)  # eq. 21
        self.phi = ti.field(float, gs)  # signed distance in the band
        self.phis = ti.field(float, gs)  # phi smoothed for the curvature fit
        self.kappa = ti.field(float, gs)
        self.ktmp = ti.field(float, gs)
        self.kvalid = ti.field(ti.i32, gs)
        self.iface = ti.Vector.field(2, ti.i32, scene.nx * scene.ny)  # interface nodes
        self.n_iface = ti.field(ti.i32, ())
        self.gradm = ti.Vector.field(dim, float, gs)
        self.seg = ti.Vector.field(8, float, (scene.nx - 1, scene.ny - 1))  # <= 2 segments/cell
        self.nseg = ti.field(ti.i32, (scene.nx - 1, scene.ny - 1))
        # ---- scalars and parameter tables
        self.t = ti.field(float, ())
        self.step = ti.field(ti.i32, ())  # steps taken: the phase of the heat and curvature clocks
        self.dt = ti.field(float, ())
        self.laser_energy = ti.field(float, ())
        self.heat_out = ti.field(float, ())
        self.T_peak = ti.field(float, ())
        self.nmat = len(scene.material_names)
        self.matp = ti.field(float, (self.nmat, N_PARAMS))
        self.lasp = ti.field(float, (max(self.n_lasers, 1), len(LASER_PARAMS)))
        self.fit = ti.Matrix.field(6, 9, float, ())  # least-squares fit of eq. 23
        self.red = ti.field(float, 12)  # reductions for monitors
        self.red_f = ti.Vector.field(3, float, ())  # CSF resultant and interface mass
        self.box = ti.Vector.field(4, ti.i32, ())  # active region [i0, j0, i1, j1)
        self._vec, self._mat2, self._mat3 = vec, mat2, mat3
        self._fill()

    # ------------------------------------------------------------------ initial values
    def _fill(self) -> None:
        case, sc = self.case, self.scene
        T_ref = case.thermal.enthalpy_reference_C
        rows = np.stack([material_row(case.materials[nm], T_ref) for nm in sc.material_names])
        self.matp.from_numpy(rows)
        rho = rows[:, 0][sc.material]
        self.x.from_numpy(sc.x)
        self.x0.from_numpy(sc.x)
        self.v.from_numpy(sc.v0)
        self.vol0.from_numpy(sc.vol)
        self.mass.from_numpy(sc.vol * rho)
        self.mat.from_numpy(sc.material)
        self.T.from_numpy(sc.T0_C + KELVIN)
        self.fit[None] = _fit_matrix()
        # outside the active region the grid keeps these: empty, and outside every body
        for f in (self.phi_raw, self.phi, self.phis):
            f.fill(self.phi_cap)
        full = [0, 0, self.nx, self.ny]
        self.box[None] = [self.nx, self.ny, 0, 0] if self.active_region else full
        if self.n_lasers:
            self.lasp.from_numpy(_laser_rows(case, sc))
        self.t[None] = 0.0
        self.T_peak[None] = float(np.max(sc.T0_C + KELVIN))
        self._init_points()
        if np.any(sc.p0 != 0.0):
            self._prestress(sc.p0)

    @ti.kernel
    def _init_points(self):
        for p in range(self.n_points):
            self.F[p] = ti.Matrix.identity(float, self.dim)
            self.J[p] = 1.0
            self.C[p] = ti.Matrix.zero(float, self.dim, self.dim)
            self.eps[p] = ti.Matrix.zero(float, self.dim, self.dim)
            self.eps_pl[p] = ti.Matrix.zero(float, 3, 3)
            self.sigma[p] = ti.Matrix.zero(float, 3, 3)
            self.alpha[p] = 0.0
            self.e_iso[p] = 0.0
            self.de_iso[p] = 0.0
            self.H[p] = enthalpy(self.matp, self.mat[p], self.T[p])
            self.xi[p] = solid_fraction(self.matp, self.mat[p], self.T[p])

    @ti.kernel
    def _prestress(self, p0: ti.types.ndarray()):
        """The elastic strain that carries an in-plane pressure p0 (plane strain, eps_zz = 0:
        eps_xx = eps_yy = -p0 / 2 (lambda + mu)) at each point's initial moduli, and its stress
        under the case's stress reading."""
        for p in range(self.n_points):
            if p0[p] != 0.0:
                m = self.mat[p]
                xi = self.xi[p]
                E = lerp_phase(self.matp, m, xi, "E_c", "E_m")
                nu = lerp_phase(self.matp, m, xi, "nu", "nu_m")
                lam_mu = E / (2.0 * (1.0 + nu) * (1.0 - 2.0 * nu))  # lambda + mu
                eps = ti.Matrix.identity(float, self.dim) * (-p0[p] / (2.0 * lam_mu))
                self.eps[p] = eps
                z = ti.Matrix.zero(float, 3, 3)
                self.sigma[p] = perzyna_update(
                    self.matp,
                    m,
                    embed3(eps),
                    z,
                    0.0,
                    0.0,
                    xi,
                    self.T[p],
                    1.0,
                    False,
                    self.paper_stress,
                )[0]

    def node_position(self, i: int, j: int) -> tuple[float, float]:
        return ((i - self.off) * self.h, (j - self.off) * self.h)


def _fit_matrix() -> np.ndarray:
    """(A^T A)^-1 A^T for the quadratic of eq. 23 on the 3x3 node stencil, offsets in cells.

    Rows give a0..a5 of a0 + a1 x + a2 y + a3 x^2 + a4 y^2 + a5 x y; columns are the nine nodes
    in the order (dx, dy) = ndrange(3, 3) - 1. The same for every node of a uniform grid.
    """
    A = []
    for a in range(3):
        for b in range(3):
            x, y = a - 1.0, b - 1.0
            A.append([1.0, x, y, x * x, y * y, x * y])
    A = np.array(A)
    return np.linalg.solve(A.T @ A, A.T)


def _laser_rows(case: Case, sc: Scene) -> np.ndarray:
    top = max(
        (b.center_um[1] + b.radius_um) if b.shape == "disc" else b.max_um[1] for b in case.bodies
    )
    rows = []
    for las in case.lasers:
        r0 = las.spot_radius_um * 1e-6
        eta = las.penetration_depth_um * 1e-6
        # eq. 31 read as power per unit volume (W/m^3), MODEL.md
        amp = 2 * las.absorptivity * las.power_W / (math.pi * r0 * r0 * eta) * las.depth_factor
        if las.source_units == "W_per_kg":  # eq. 3 as printed: rho * s_laser
            amp *= case.materials[case.bodies[0].material].density_kg_m3
        x_end = las.x_end_um if las.x_end_um is not None else 1e9
        y_top = las.top_um if las.top_um is not None else top
        vals = dict(
            on=las.on_s,
            off=las.off_s,
            x0=las.x_start_um * 1e-6,
            speed=las.speed_m_s,
            x_end=x_end * 1e-6,
            top=y_top * 1e-6,
            amp=amp,
            r0=r0,
            eta=eta,
            sign=1.0 if las.depth_sign == "decay" else -1.0,
        )
        rows.append([vals[k] for k in LASER_PARAMS])
    return np.array(rows)
