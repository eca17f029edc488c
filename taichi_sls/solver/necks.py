"""The interface and neck measures of a simulation's state: the level set and colour on the
nodes, the contact line of the paper's pair, the neck of every contact."""

from __future__ import annotations

import numpy as np

from ..config import Case
from . import struct_copy
from .contacts import point_colour
from .fields import State
from .grid_views import interface_fields
from .kernel_colour import kernel_neck
from .monitor import neck_measures
from .neck_section import equivalent_radii, filtered_colour, neck_section, pair_reach

# what the host reads of the points and of the nodes, each copied by one kernel (a member's
# own to_numpy is a kernel of its own, compiled in every process: docs/record/compile.md)
HOST_POINT_MEMBERS = ("x", "x0", "v", "mass", "volume0", "J", "time_molten")
HOST_NODE_MEMBERS = ("phi", "colour", "mass")


def point_arrays(st: State, keys: tuple[str, ...] = HOST_POINT_MEMBERS) -> dict[str, np.ndarray]:
    """The points' members the host reads (default HOST_POINT_MEMBERS), copied by the one
    kernel that copies any of them."""
    return struct_copy.to_numpy(st.points, keys)


class Necks:
    """The neck measures of ``st`` (its points in the order of ``st.scene``, which the blocks
    layout sorts again: :meth:`reorder` follows) for ``contacts``, the pairs of touching bodies
    as seeded."""

    def __init__(self, case: Case, st: State, contacts: list[tuple[int, int]]) -> None:
        self.case = case
        self.state = st
        self.contacts = contacts
        self.pair = len(case.bodies) >= 2  # a contact line to read: the paper's pair
        self.mass = point_arrays(st)["mass"]  # each point's, in the points' order
        sc = st.scene
        # each body's equivalent radius as seeded, sqrt(area / pi) (3D: (3 V / 4 pi)^(1/3)):
        # its reach for a neck (m)
        self.body_radii_m = equivalent_radii(sc.body, sc.vol, case.domain.dim)

    def reorder(self, order: np.ndarray) -> None:
        """The points were put in the order ``order`` (the state's scene with them)."""
        self.mass = self.mass[order]

    def node_arrays(self) -> dict[str, np.ndarray]:
        """The node fields the neck measures read (HOST_NODE_MEMBERS), copied by one kernel."""
        return struct_copy.to_numpy(self.state.nodes, HOST_NODE_MEMBERS)

    def phi(self) -> np.ndarray:
        """Level set of eq. 21 on the nodes (m) of the current points."""
        interface_fields(self.state)
        return self.node_arrays()["phi"]

    def colour(self) -> np.ndarray:
        """The surface-energy colour c_i of the current points on the nodes (the contoured
        one: filtered when the case filters it)."""
        interface_fields(self.state)
        return self.node_arrays()["colour"]

    def neck_measure(self) -> str:
        """The interface the contact line is read on: the force's own (``output.neck_measure =
        "auto"``: the colour for the surface-energy force, eq. 21 for the CSF and for frozen
        points), or the one the case names."""
        m = self.case.output.neck_measure
        if self.state.cfg.dim == 3:  # eq. 21's level set is 2D: the colour, whatever the force
            return "colour"
        if m == "auto":
            energy = self.case.surface_tension.method == "surface_energy"
            m = "colour" if energy and self.case.physics.mechanics else "level_set"
        return m

    def contact_line_m(self, measure: str | None = None) -> tuple[float, float]:
        """(contact line, neck span) in metres of the first contact (the paper's pair) on
        ``measure`` (default: :meth:`neck_measure`), sectioned as ``contact.neck_section`` says
        (:meth:`necks_m`; the column: :mod:`taichi_sls.solver.monitor`)."""
        if not self.pair:
            return float("nan"), float("nan")
        measure = measure or self.neck_measure()
        if measure == "level_set" and self.state.cfg.dim == 3:
            return float("nan"), float("nan")  # eq. 21's level set is 2D
        # 3D: the section across the centres (solver/neck_section.py), a column has no meaning
        if self.case.contact.neck_section == "centres" or self.state.cfg.dim == 3:
            if not self.contacts:
                return 0.0, 0.0
            w = self.necks_m(measure, self.contacts[:1])[0]  # the first contact's alone
            return w, w
        lo, hi = sorted(self.body_centres_m()[:2, 0])
        cfg = self.state.cfg
        return neck_measures(-self.material_field(measure, "column"), cfg.h, cfg.off, lo, hi)

    def raw_colour(self) -> np.ndarray:
        """The colour c_i of the current points before any filter: the cell fraction that
        material fills, from the node mass."""
        self.colour()  # the grid's mass of the current points
        cfg, nd = self.state.cfg, self.node_arrays()
        return nd["mass"] / (cfg.rho_ref * cfg.cell_volume)

    def material_field(self, measure: str, section: str) -> np.ndarray:
        """The interface field on the nodes, material where it is >= 0: -phi of eq. 21, or
        c - 1/2 of the colour. The column reads the colour the force contours; the sections
        across the centres the colour ``contact.neck_colour`` names (:meth:`section_colour`)."""
        if measure != "colour":
            return -self.phi()
        if section == "centres":
            return self.section_colour(self.raw_colour()) - 0.5
        return self.colour() - 0.5

    def section_colour(self, raw: np.ndarray) -> np.ndarray:
        """The colour a section across the centres reads, from a raw colour: the force's filter
        of it (``contact.neck_colour = "filtered"``, closing the notch along a node-line
        mid-plane) or itself (``"raw"``: the seeded outline, a concave neck unwidened;
        ``"kernel"``, whose sections read a raster of the points instead (:meth:`necks_m`):
        its samples at the nodes)."""
        if self.case.contact.neck_colour != "filtered":
            return raw
        return filtered_colour(raw)

    def necks_m(
        self, measure: str | None = None, contacts: list[tuple[int, int]] | None = None
    ) -> list[float]:
        """The neck of every contact (m), in the order of ``contacts`` (default: all the
        seeded ones): the narrowest section across the line of the two bodies' mass centres,
        between the outermost crossings of the interface
        (:func:`taichi_sls.solver.neck_section.neck_section`), out to the pair's reach."""
        contacts = self.contacts if contacts is None else contacts
        if not contacts:
            return []
        measure = measure or self.neck_measure()
        if self.reads_kernel(measure):
            everyone = np.arange(len(self.mass))
            return self._kernel_necks(lambda a, b: everyone, contacts)
        field = self.material_field(measure, "centres")
        return self._contact_necks(lambda a, b: field, contacts)

    def reads_kernel(self, measure: str) -> bool:
        """Whether the sections across the centres read the points' own kernel colour
        (``contact.neck_colour = "kernel"``, on the colour measure): a raster per contact,
        no node field (solver/kernel_colour.py)."""
        return measure == "colour" and self.case.contact.neck_colour == "kernel"

    def _kernel_necks(self, members_of, contacts: list[tuple[int, int]]) -> list[float]:
        """The neck of each of ``contacts`` on the kernel colour of the points
        ``members_of(a, b)`` (indices), rastered over the box the contact's sections span."""
        centre, r, cfg = self.body_centres_m(), self.body_radii_m, self.state.cfg
        pts = point_arrays(self.state, ("x", "volume0", "J"))
        x, volume = pts["x"], pts["volume0"] * pts["J"]
        necks = []
        for a, b in contacts:
            sel = members_of(a, b)
            reach = pair_reach(r[a], r[b], cfg.dim)
            necks.append(
                kernel_neck(x[sel], volume[sel], cfg.h, cfg.lp, centre[a], centre[b], reach)
            )
        return necks

    def _contact_necks(self, field_of, contacts: list[tuple[int, int]]) -> list[float]:
        """neck_section of each of ``contacts`` on ``field_of(a, b)``, sampled out to
        :func:`~taichi_sls.solver.neck_section.pair_reach`: the coalesced end state of the
        pair, so a neck is followed past the bodies' initial diameter. 3D:
        the diameter 2 sqrt(A / pi) of the section."""
        centre, r, cfg = self.body_centres_m(), self.body_radii_m, self.state.cfg
        return [
            neck_section(
                field_of(a, b),
                cfg.h,
                cfg.off,
                centre[a],
                centre[b],
                pair_reach(r[a], r[b], cfg.dim),
            )[0]
            for a, b in contacts
        ]

    def body_centres_m(self, initial: bool = False) -> np.ndarray:
        """Each body's mass centre (m), (bodies, dim): of the current points, or (``initial``) of
        their start positions."""
        x = point_arrays(self.state)["x0" if initial else "x"]
        body, m = self.state.scene.body, self.mass
        n_b = len(self.body_radii_m)
        return (
            np.stack(
                [np.bincount(body, weights=m * x[:, k], minlength=n_b) for k in range(x.shape[1])],
                axis=1,
            )
            / np.bincount(body, weights=m, minlength=n_b)[:, None]
        )

    def colour_weights(self) -> np.ndarray:
        """Each point's share of the colour the force contours, per node of its stencil's
        unit weight: m / (rho V_cell)."""
        cfg = self.state.cfg
        return self.mass / (cfg.rho_ref * cfg.cell_volume)

    def pair_necks_m(self) -> list[float]:
        """The neck of every contact (m), in the order of ``contacts``, read as :meth:`necks_m`
        reads it but on the colour of the contact's two bodies alone (raw or filtered as
        ``contact.neck_colour`` says): in a bed a section across one contact also crosses the
        neighbours, whose material the outermost crossings would count. Mass colour
        m_i / (rho V_cell), or the volume colour where the force uses it; equal to
        :meth:`necks_m` on the colour for a case of two bodies."""
        if not self.contacts:
            return []
        cfg = self.state.cfg
        body = self.state.scene.body
        order = np.argsort(body, kind="stable")
        bounds = np.searchsorted(body[order], np.arange(len(self.body_radii_m) + 1))
        members = [order[bounds[b] : bounds[b + 1]] for b in range(len(self.body_radii_m))]
        if self.reads_kernel("colour"):
            return self._kernel_necks(
                lambda a, b: np.concatenate([members[a], members[b]]), self.contacts
            )
        x, weight = point_arrays(self.state, ("x",))["x"], self.colour_weights()
        shape = (cfg.nx, cfg.ny) if cfg.dim == 2 else (cfg.nx, cfg.ny, cfg.nz)

        def colour(a: int, b: int) -> np.ndarray:
            sel = np.concatenate([members[a], members[b]])
            raw = point_colour(x[sel], weight[sel], cfg.h, cfg.lp, cfg.off, shape)
            return self.section_colour(raw) - 0.5

        return self._contact_necks(colour, self.contacts)
