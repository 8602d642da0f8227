"""Exudyn multibody model of a heavy vehicle for vertical dynamics on a road.

What it is for: turning :class:`vehicles.params.VehicleParams` into an Exudyn system
(``model.mbs``) with named bodies, force elements and the road input, at static
equilibrium.  :func:`vehicles.simulate.simulate` drives it over a road; the modal
analysis and the linear frequency response linearise it (``model.mbs`` with
:meth:`VehicleModel.coordinate_indices`, :meth:`VehicleModel.linearized_mass_stiffness`
and the tyre contacts in ``model.contacts``).

What it is not: the time integration and the outputs (:mod:`vehicles.simulate`),
the effects (:mod:`vehicles.effects`, which add terms through the hooks here).

Model (vehicle coordinates: x forward, 0 at the first axle, y left, z up from the
road; the vehicle does not move along x: the road moves under it):

* chassis: one rigid 6-DOF body (``chassis="rigid"``) or ``n`` rigid frame
  segments joined by 6-DOF spring-dampers that are quasi-rigid in translation and
  elastic in torsion (about x), vertical bending (about y) and lateral bending
  (about z) (``chassis="flexible"``, :mod:`vehicles.frame`);
* axles: rigid 6-DOF bodies; bounce and roll are the soft motions, the other four
  are held by the stiff axle guides, the wind-up spring and the tyres;
* suspension: per axle side a vertical spring and damper (and a stiff longitudinal
  and lateral guide) between the spring seat on the frame and on the axle, plus
  the axle's wind-up (pitch relative to the frame: leaf-spring bending, torque
  rods).  Both sides and the wind-up of an axle are one 6-DOF spring-damper
  (``ObjectConnectorRigidBodySpringDamper``) at the centre of the seats whose 6x6
  stiffness and damping are those of the point springs (:func:`equivalent_6x6`,
  exact for small motions): one element per axle instead of three, which halves
  the cost of a time step.  ``model.suspensions`` keeps the per-side data;
  nonlinear effects add their per-side forces as separate elements
  (:func:`install_suspension_terms`);
* tyres: the tyres of an axle (per side one, or two for a dual pair at
  +-dual_spacing/2) are likewise one 6-DOF spring-damper from the axle centre to
  the ground, equivalent to a vertical (stiffness, damping) and lateral
  (stiffness) spring at every wheel centre; no longitudinal stiffness: the wheels
  roll.  At the wheel centre, because the contact of a rolling wheel stays below
  the wheel centre whatever the wheel's spin (a body-fixed contact point would let
  the preloaded tyre force destabilise the axle's pitch; the lever arm of the
  lateral tyre force, radius x lateral force, is neglected).  The road enters as a
  force: a tyre force ``k (z_r - u) + c (dz_r/dt - du/dt)`` is the constant
  spring-damper ``-k u - c du/dt`` plus the known force ``k z_r + c dz_r/dt``; the
  road forces of all tyres of an axle are one vertical force at the wheel-centre
  line plus one roll moment (``road_loads``, two loads per axle).  In the time
  simulation the same generalised forces are applied through one
  ``ObjectGenericODE2`` over all axle nodes (``injector``, mapping
  :meth:`VehicleModel.road_input_matrix` at static equilibrium), set with a single
  call per step.  This is exact for the linear (bilateral) tyre up to the
  rotation of the axles from static (the force directions are frozen at
  equilibrium; axle rotations are ~1e-3 rad).  A tyre off the road carries no
  force: :mod:`vehicles.tyre_contact` adds, per step, the force that cancels the
  linear tyre's pull (:func:`vehicles.simulate.simulate`, ``tyres="unilateral"``);
* DCDC block (tractor): a rigid body on a 6-DOF mount spring-damper equivalent to
  four mounts at the corners of its base;
* surge: wheels roll freely, so nothing ties the vehicle to the road along x but
  its speed control; a longitudinal spring-damper (3 Hz, damping ratio 0.5, whole
  vehicle mass) from the moving reference to the chassis at its centre of gravity
  stands for it (at the centre of gravity it does not couple with pitch);
* gravity on every body; static equilibrium on a flat road by Exudyn's static
  solver, which is the reference (zero) of every output.

Coordinates: Euler-parameter nodes (``node_type="EP"``, 7 coordinates + 1
constraint per body, fastest here) or Tait-Bryan nodes (``"Rxyz"``, 6 coordinates,
no constraint; best for linearisation).  Degrees of freedom: 6 per body.
"""
from __future__ import annotations

import contextlib
import sys
import threading
from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError, SimulationError
from vehicles.frame import (SegmentMass, combine, frame_joints, segment_bounds, segment_index,
                            segment_masses)
from vehicles.params import VehicleParams

GRAVITY = 9.81
#: damping of the stiff axle guides, as a time constant times their stiffness [s]
GUIDE_DAMPING_TIME = 2e-3
#: frequency [Hz] and damping ratio [-] of the vehicle's surge on its speed control
SURGE_HZ = 3.0
SURGE_DAMPING = 0.5
SIDES = ("L", "R")
SIDE_SIGN = {"L": 1.0, "R": -1.0}
#: node outputs recorded for every body (world frame)
NODE_OUTPUTS = ("Position", "RotationMatrix", "Acceleration", "AngularVelocity",
                "AngularAcceleration")


def _exu():
    import exudyn
    return exudyn


@dataclass
class Body:
    """One rigid body of the model.

    Attributes
    ----------
    name : str
        ``"chassis"``, ``"segment<i>"``, ``"axle<a>"`` or ``"dcdc"``.
    node, body : int
        Exudyn node and object numbers.
    cog : ndarray (3,)
        Reference position of the centre of gravity [m] (= node reference position).
    mass : float
        [kg]
    inertia : ndarray (3, 3)
        About the centre of gravity [kg m^2].
    marker : int
        MarkerBodyRigid at the centre of gravity.
    """

    name: str
    node: int
    body: int
    cog: np.ndarray
    mass: float
    inertia: np.ndarray
    marker: int = -1


@dataclass
class Contact:
    """A tyre contact (one tyre).

    Attributes
    ----------
    axle : int
        0-based axle index.
    side : str
        ``"L"`` or ``"R"``.
    y : float
        Lateral position in vehicle coordinates [m] (road lateral position is
        ``y_offset + y``).
    local : ndarray (3,)
        Tyre attachment point (wheel centre) in axle body coordinates, relative to
        the axle's centre of gravity [m].
    stiffness, damping : float
        Vertical tyre stiffness [N/m] and damping [N s/m].
    obj : int
        Exudyn object number of the axle's tyre spring-damper (shared by its tyres).
    """

    axle: int
    side: str
    y: float
    local: np.ndarray
    stiffness: float
    damping: float
    obj: int = -1


@dataclass
class Suspension:
    """Suspension of one axle side.

    ``u = z(axle seat) - z(frame seat)`` is the compression [m] (positive when the
    axle moves up relative to the frame), measured from the unloaded design
    position; ``static_compression`` is its value at static equilibrium.

    Attributes
    ----------
    axle, side
        Axle index (0-based) and ``"L"``/``"R"``.
    point : ndarray (3,)
        Spring seat in vehicle coordinates (design position) [m].
    segment : int
        Index of the frame segment (0 for the rigid chassis) carrying the seat.
    local_frame, local_axle : ndarray (3,)
        The seat relative to the segment's / axle's centre of gravity [m].
    stiffness, damping : float
        Vertical spring [N/m] and (mean) damping [N s/m].
    spring_type : str
        ``"leaf"`` or ``"air"``.
    guide : tuple
        ([kx, ky, kz], [cx, cy, cz]) of the side's point spring-damper.
    obj : int
        The axle's 6-DOF suspension element (shared by both sides).
    effect_obj : int
        The side's effect element (nonlinear effects), or -1.
    """

    axle: int
    side: str
    point: np.ndarray
    segment: int
    local_frame: np.ndarray
    local_axle: np.ndarray
    stiffness: float
    damping: float
    spring_type: str
    guide: tuple
    obj: int = -1
    effect_obj: int = -1
    static_compression: float = float("nan")


@dataclass
class VehicleModel:
    """An assembled Exudyn vehicle model at static equilibrium.

    Attributes
    ----------
    SC, mbs
        Exudyn SystemContainer and MainSystem.
    vp : VehicleParams
    chassis : str
        ``"rigid"`` or ``"flexible"``.
    node_type : str
        ``"EP"`` or ``"Rxyz"``.
    stiffness_factor : float
        Frame stiffness scale (flexible chassis).
    segments : list of Body
        Frame segments front to rear (one body ``"chassis"`` when rigid).
    axles : list of Body
        Axles front to rear.
    dcdc : Body or None
        DCDC block (tractor).
    contacts : list of Contact
    suspensions : list of Suspension
    joints : list of int
        Exudyn objects of the frame joints (``FrameJoint`` data in ``frame_joints``),
        the axle wind-up springs and the DCDC mount.
    road_loads : list of (int, int)
        Per axle: (vertical force load, roll torque load) carrying the road input.
    sensors : dict
        ``{body name: {output name: sensor number}}``.
    static : dict
        ``{body name: (position (3,), rotation matrix (3, 3))}`` at static
        equilibrium on a flat road (the reference of all outputs).
    """

    SC: object
    mbs: object
    vp: VehicleParams
    chassis: str
    node_type: str
    stiffness_factor: float
    segments: list = field(default_factory=list)
    axles: list = field(default_factory=list)
    dcdc: Body | None = None
    contacts: list = field(default_factory=list)
    suspensions: list = field(default_factory=list)
    joints: list = field(default_factory=list)
    frame_joints: list = field(default_factory=list)
    road_loads: list = field(default_factory=list)
    sensors: dict = field(default_factory=dict)
    static: dict = field(default_factory=dict)
    ground: int = -1
    surge: int = -1
    injector: int = -1
    _keep: list = field(default_factory=list)   # symbolic user functions must stay alive

    def release(self) -> None:
        """Free the Exudyn system.  A Python user function stored in the C++ system that
        refers back to it (the PreStep road feed, the symbolic suspension terms) makes a
        reference cycle the garbage collector cannot see: without this every simulation
        leaked its whole system (about 4 MB for the 8x4 truck).  The model is unusable
        afterwards."""
        self.SC.Reset()
        self._keep.clear()

    # ------------------------------------------------------------------ geometry
    @property
    def bodies(self) -> list:
        """All bodies: segments, axles, DCDC."""
        return self.segments + self.axles + ([self.dcdc] if self.dcdc is not None else [])

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    @property
    def segment_bounds(self) -> list:
        if self.chassis == "rigid":
            return [(self.vp.frame.x_front, self.vp.frame.x_rear)]
        return segment_bounds(self.vp.frame, len(self.segments))

    def segment_of(self, x: float) -> int:
        """Index of the frame segment at position ``x`` [m]."""
        return segment_index(self.segment_bounds, x)

    @property
    def n_dof(self) -> int:
        """Mechanical degrees of freedom (6 per body)."""
        return 6 * len(self.bodies)

    def coordinate_indices(self) -> dict:
        """Global ODE2 coordinate indices of every body's node (after assembly).

        Returns
        -------
        dict
            ``{body name: ndarray of int}``: 7 indices (position, Euler parameters)
            for EP nodes, 6 (position, Tait-Bryan angles) for Rxyz nodes.
        """
        out = {}
        for b in self.bodies:
            i0 = self.mbs.GetNodeODE2Index(b.node)
            n = 7 if self.node_type == "EP" else 6
            out[b.name] = np.arange(i0, i0 + n)
        return out

    def linearized_mass_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        """Mass and (symmetrised) stiffness matrix at the current (static) state.

        Only for ``node_type="Rxyz"`` (no constraints).

        Returns
        -------
        (M, K) : ndarrays (n, n)
        """
        if self.node_type != "Rxyz":
            raise ValueError("linearized_mass_stiffness needs node_type='Rxyz'")
        M, K, _D = self.linearized_system()
        return M, 0.5 * (K + K.T)

    def linearized_system(self):
        """Exudyn's linearisation [M, K, D] at the current state (see
        ``exudyn.solver.ComputeLinearizedSystem``; constraints not projected)."""
        exu = _exu()
        from exudyn.solver import ComputeLinearizedSystem

        with _quiet():
            M, K, D = ComputeLinearizedSystem(self.mbs, exu.SimulationSettings())
        return np.asarray(M), np.asarray(K), np.asarray(D)

    def joint_rotation_indices(self) -> dict:
        """Coordinate index pairs and stiffness of the frame joint rotations.

        Returns
        -------
        dict
            ``{"torsion": [((i_a, i_b), k), ...], "bending": [...]}`` with i_a, i_b the
            Rxyz angle coordinates (about x for torsion, y for bending) of the two
            joined segments (small-angle relative rotation = difference).
        """
        idx = self.coordinate_indices()
        out = {"torsion": [], "bending": []}
        for j in self.frame_joints:
            a = idx[self.segments[j.index].name]
            b = idx[self.segments[j.index + 1].name]
            out["torsion"].append(((a[3], b[3]), j.stiffness[3]))
            out["bending"].append(((a[4], b[4]), j.stiffness[4]))
        return out

    # ------------------------------------------------------------------ road input
    def road_input_matrix(self) -> np.ndarray:
        """Generalised forces of unit road forces, at the current (static) state.

        A road force ``f_c = k_c z_r + c_c dz_r/dt`` [N] (upwards) at the wheel centre of
        tyre ``c`` acts on the axle node's coordinates as ``Q = B[:, c] f_c``:
        translation ``e_z``, rotation ``G^T (d x e_z)`` with ``d`` the lateral offset of
        the wheel from the axle centre and ``G`` the node's angular-velocity matrix
        (omega = G dq/dt).

        Returns
        -------
        ndarray (n_inj, n_contacts)
            Rows ordered like the injector's ``forceVector``: the coordinates of the
            axle nodes, axle by axle (7 per EP node, 6 per Rxyz node).  Global ODE2
            rows: ``coordinate_indices()[axle name]``.
        """
        from exudyn import rigidBodyUtilities as rbu

        exu = _exu()
        nq = 7 if self.node_type == "EP" else 6
        B = np.zeros((nq * len(self.axles), len(self.contacts)))
        G = []
        for b in self.axles:
            q = np.asarray(self.mbs.GetNodeOutput(b.node, exu.OutputVariableType.Coordinates)) + \
                np.asarray(self.mbs.GetNode(b.node)["referenceCoordinates"])
            G.append(rbu.EulerParameters2G(q[3:7]) if self.node_type == "EP" else rbu.RotXYZ2G(q[3:6]))
        for c, ct in enumerate(self.contacts):
            a = ct.axle
            R = np.asarray(self.mbs.GetNodeOutput(self.axles[a].node,
                                                  exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
            d = R @ ct.local
            ez = np.array([0.0, 0.0, 1.0])
            B[a * nq + 2, c] = 1.0
            B[a * nq + 3:(a + 1) * nq, c] = G[a].T @ np.cross(d, ez)
        return B

    def road_input_matrix_global(self) -> np.ndarray:
        """:meth:`road_input_matrix` scattered to the global ODE2 coordinates (n, nc)."""
        B = self.road_input_matrix()
        idx = self.coordinate_indices()
        n = sum(len(v) for v in idx.values())
        Bg = np.zeros((n, B.shape[1]))
        nq = 7 if self.node_type == "EP" else 6
        for a, b in enumerate(self.axles):
            Bg[idx[b.name]] = B[a * nq:(a + 1) * nq]
        return Bg

    def set_injector(self, q) -> None:
        """Set the road generalised forces (``road_input_matrix() @ f_contacts``)."""
        self.mbs.SetObjectParameter(self.injector, "forceVector", np.asarray(q, float))

    def set_road_forces(self, force: np.ndarray, torque: np.ndarray) -> None:
        """Set the road forces of all axles through the road loads (one call per load).

        The loads define the road input exactly (vertical force at the wheel-centre
        line, roll moment); :func:`vehicles.simulate.simulate` leaves them at zero and
        applies the same generalised forces through the injector.

        Parameters
        ----------
        force : (n_axles,) vertical road force per axle [N]
        torque : (n_axles,) roll moment of the road forces per axle [N m]
        """
        mbs = self.mbs
        for a, (lf, lt) in enumerate(self.road_loads):
            mbs.SetLoadParameter(lf, "loadVector", [0.0, 0.0, float(force[a])])
            mbs.SetLoadParameter(lt, "loadVector", [float(torque[a]), 0.0, 0.0])

    def road_force_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Maps from tyre road heights to the axle road loads.

        Returns
        -------
        (Bf, Bt) : ndarrays (n_axles, n_contacts)
            ``force = Bf @ (k z_r + c dz_r/dt)`` per contact, likewise the torque;
            i.e. ``Bf[a, c] = 1`` if contact c is on axle a, ``Bt[a, c] = y_c`` (the
            lateral position of the tyre relative to the axle centre).
        """
        na, nc = len(self.axles), len(self.contacts)
        Bf, Bt = np.zeros((na, nc)), np.zeros((na, nc))
        for c, ct in enumerate(self.contacts):
            Bf[ct.axle, c] = 1.0
            Bt[ct.axle, c] = ct.local[1]
        return Bf, Bt

    # ------------------------------------------------------------------ statics
    def solve_static(self) -> None:
        """Static equilibrium under gravity and the current road loads; becomes the
        initial state.  Raises SimulationError if the static solver fails."""
        exu = _exu()
        s = exu.SimulationSettings()
        s.staticSolver.verboseMode = 0
        # residual forces below 1e-3 N are round-off next to the 1e10 N/m frame joints
        s.staticSolver.newton.relativeTolerance = 1e-9
        s.staticSolver.newton.absoluteTolerance = 1e-3
        s.solution.file.write = False
        s.solution.sensors.active = False
        s.linearSolver.ignoreSingularJacobian = False
        solver = exu.MainSolverStatic()
        try:
            with _quiet():
                ok = solver.SolveSystem(self.mbs, s)
        except Exception as exc:  # noqa: BLE001 - Exudyn raises various types
            raise SimulationError(f"static equilibrium not found ({exc}); likely cause: a "
                                  "missing or zero stiffness in the vehicle parameters") from None
        if not ok:
            raise SimulationError("static equilibrium not found (static solver did not converge); "
                                  "likely cause: a missing or zero stiffness in the vehicle parameters")
        state = self.mbs.systemData.GetSystemState()
        self.mbs.systemData.SetSystemState(systemStateList=state, configuration=exu.ConfigurationType.Initial)

    def record_static_reference(self) -> None:
        """Store positions and rotations of all bodies as the output reference and the
        static suspension compressions."""
        exu = _exu()
        ov = exu.OutputVariableType
        for b in self.bodies:
            p = np.asarray(self.mbs.GetNodeOutput(b.node, ov.Position))
            R = np.asarray(self.mbs.GetNodeOutput(b.node, ov.RotationMatrix)).reshape(3, 3)
            self.static[b.name] = (p, R)
        for s in self.suspensions:
            s.static_compression = (self.point_position(self.axles[s.axle].name, s.local_axle)[2]
                                    - self.point_position(self.segments[s.segment].name,
                                                          s.local_frame)[2])

    def point_position(self, body_name: str, local) -> np.ndarray:
        """Current world position of a body-fixed point [m]."""
        exu = _exu()
        b = self.body(body_name)
        p = np.asarray(self.mbs.GetNodeOutput(b.node, exu.OutputVariableType.Position))
        R = np.asarray(self.mbs.GetNodeOutput(b.node, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
        return p + R @ np.asarray(local, float)

    def static_tyre_loads(self) -> np.ndarray:
        """Static vertical tyre forces [N] (positive = pressing on the road), per contact.

        From the static reference (:meth:`record_static_reference`) when it has been
        recorded, so that the answer after a simulation is still the static one (the current
        node positions are then those of the run's last step); before that, from the current
        state (the static solve's).
        """
        out = []
        for ct in self.contacts:
            ab = self.axles[ct.axle]
            if ab.name in self.static:
                p, R = self.static[ab.name]
                zc = (p + R @ np.asarray(ct.local, float))[2]
            else:
                zc = self.point_position(ab.name, ct.local)[2]
            out.append(-ct.stiffness * (zc - (ab.cog[2] + ct.local[2])))
        return np.array(out)


class _QuietStdout:
    """Stand-in for ``sys.stdout`` while some thread is in :func:`_quiet`: it drops what the
    quiet threads write and passes every other thread's writes to the stream it replaced."""

    def __init__(self, real):
        self.real = real

    def write(self, text):
        return len(text) if getattr(_QUIET_TLS, "depth", 0) else self.real.write(text)

    def __getattr__(self, name):
        return getattr(self.real, name)


_QUIET_LOCK = threading.Lock()
_QUIET_TLS = threading.local()
#: [threads inside _quiet, the stdout and Exudyn printToConsole they replaced]
_QUIET_STATE = [0, None, None]


@contextlib.contextmanager
def _quiet():
    """Silence Exudyn console output of a solver call, in this thread only.

    ``contextlib.redirect_stdout`` swaps the process-wide ``sys.stdout``; two threads that
    overlap (the inversion's selection thread and the main thread both build and solve
    models) then restore each other's stand-ins, and ``sys.stdout`` stays a StringIO for the
    rest of the run: the CLI's closing lines vanished intermittently (seen on ``eroad invert
    --effects auto`` with stdout and stderr in one file). Here the first thread in installs
    one stand-in (:class:`_QuietStdout`) and the last one out restores what was there; the
    stand-in drops only the quiet threads' writes.
    """
    cfg = _exu().config
    with _QUIET_LOCK:
        if _QUIET_STATE[0] == 0:
            _QUIET_STATE[1], _QUIET_STATE[2] = sys.stdout, cfg.printToConsole
            sys.stdout = _QuietStdout(sys.stdout)
            cfg.printToConsole = False
        _QUIET_STATE[0] += 1
    _QUIET_TLS.depth = getattr(_QUIET_TLS, "depth", 0) + 1
    try:
        yield
    finally:
        _QUIET_TLS.depth -= 1
        with _QUIET_LOCK:
            _QUIET_STATE[0] -= 1
            if _QUIET_STATE[0] == 0:
                sys.stdout, cfg.printToConsole = _QUIET_STATE[1], _QUIET_STATE[2]
                _QUIET_STATE[1] = _QUIET_STATE[2] = None


def _rot_coords(node_type):
    return [1.0, 0.0, 0.0, 0.0] if node_type == "EP" else [0.0, 0.0, 0.0]


def equivalent_6x6(points, k3) -> np.ndarray:
    """6x6 stiffness (or damping) of parallel point springs, for small motions.

    Springs with diagonal stiffness ``k3[i]`` (x, y, z, global axes) at positions
    ``points[i]`` relative to a reference point act on the relative displacement
    ``u`` and small rotation ``theta`` of two bodies as one 6-DOF spring:
    ``K = sum T_i^T diag(k_i) T_i`` with ``T_i = [I, -[r_i]x]`` (the point moves by
    ``u + theta x r_i``).  Exact for the linearised system.

    Parameters
    ----------
    points : sequence of (3,) [m]
    k3 : sequence of (3,) [N/m] (or [N s/m])

    Returns
    -------
    ndarray (6, 6) [N/m, N/rad, N m/rad]
    """
    K = np.zeros((6, 6))
    for r, k in zip(points, k3):
        r = np.asarray(r, float)
        rx = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
        T = np.hstack([np.eye(3), -rx])
        K += T.T @ np.diag(np.asarray(k, float)) @ T
    return K


def build_model(vp: VehicleParams, chassis: str = "rigid", frame_segments: int | None = None,
                stiffness_factor: float = 1.0, node_type: str = "EP",
                suspension_terms=None, static: bool = True) -> VehicleModel:
    """Build the Exudyn model of a vehicle, assembled and at static equilibrium.

    Parameters
    ----------
    vp : VehicleParams
    chassis : {"rigid", "flexible"}
    frame_segments : int, optional
        Number of frame segments of the flexible chassis (default ``vp.frame.segments``).
    stiffness_factor : float
        Scale of the frame's torsion and bending stiffness [-] (flexible chassis).
    node_type : {"EP", "Rxyz"}
        Rigid-body node type (Euler parameters or Tait-Bryan angles).
    suspension_terms : callable, optional
        ``f(suspension) -> list of callables term(u, v) -> symbolic force`` giving
        extra suspension forces [N] (positive = pushing axle and frame apart) as
        functions of the dynamic compression ``u`` [m] (zero at static equilibrium)
        and compression velocity ``v`` [m/s].  Installed as Exudyn symbolic user
        functions after the static solution is known (effects use this).
    static : bool
        Solve for static equilibrium on a flat road and record the reference.

    Returns
    -------
    VehicleModel
    """
    exu = _exu()
    from exudyn import itemInterface as ii

    if chassis not in ("rigid", "flexible"):
        raise EroadInputError(f"chassis must be 'rigid' or 'flexible', got {chassis!r}")
    if node_type not in ("EP", "Rxyz"):
        raise ValueError(f"node_type must be 'EP' or 'Rxyz', got {node_type!r}")
    if not (np.isfinite(stiffness_factor) and stiffness_factor > 0):
        raise EroadInputError(f"frame stiffness factor must be positive, got {stiffness_factor!r}")
    n_seg = 1 if chassis == "rigid" else int(frame_segments or vp.frame.segments)
    if chassis == "flexible" and n_seg < 2:
        raise EroadInputError(f"a flexible frame needs at least 2 segments, got {n_seg}")

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    model = VehicleModel(SC=SC, mbs=mbs, vp=vp, chassis=chassis, node_type=node_type,
                         stiffness_factor=float(stiffness_factor))
    model.ground = mbs.AddObject(ii.ObjectGround())
    rot0 = _rot_coords(node_type)
    Node = ii.NodeRigidBodyEP if node_type == "EP" else ii.NodeRigidBodyRxyz

    def add_body(name, mass, cog, J):
        cog = np.asarray(cog, float)
        n = mbs.AddNode(Node(referenceCoordinates=list(cog) + rot0))
        J6 = [J[0, 0], J[1, 1], J[2, 2], J[1, 2], J[0, 2], J[0, 1]]
        b = mbs.AddObject(ii.ObjectRigidBody(mass=float(mass), inertia=J6, nodeNumber=n))
        mm = mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=b))
        mbs.AddLoad(ii.LoadMassProportional(markerNumber=mm, loadVector=[0.0, 0.0, -GRAVITY]))
        body = Body(name, n, b, cog, float(mass), np.asarray(J, float))
        body.marker = mbs.AddMarker(ii.MarkerBodyRigid(bodyNumber=b, localPosition=[0.0, 0.0, 0.0]))
        return body

    def pos_marker(body: Body, point):
        return mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=body.body,
                                                   localPosition=list(np.asarray(point) - body.cog)))

    def rigid_marker(body: Body, point):
        return mbs.AddMarker(ii.MarkerBodyRigid(bodyNumber=body.body,
                                                localPosition=list(np.asarray(point) - body.cog)))

    # ---- chassis
    bounds = segment_bounds(vp.frame, n_seg)
    segs = segment_masses(vp.sprung, bounds)
    if chassis == "rigid":
        M, c, J = combine([(s.mass, s.cog, s.inertia) for s in segs])
        segs = [SegmentMass(vp.frame.x_front, vp.frame.x_rear, M, c, J)]
    for i, s in enumerate(segs):
        name = "chassis" if chassis == "rigid" else f"segment{i + 1}"
        model.segments.append(add_body(name, s.mass, s.cog, s.inertia))
    if chassis == "flexible":
        model.frame_joints = frame_joints(vp.frame, segs, stiffness_factor)
        for j in model.frame_joints:
            m0 = rigid_marker(model.segments[j.index], j.point)
            m1 = rigid_marker(model.segments[j.index + 1], j.point)
            model.joints.append(mbs.AddObject(ii.ObjectConnectorRigidBodySpringDamper(
                markerNumbers=[m0, m1], stiffness=np.diag(j.stiffness), damping=np.diag(j.damping))))

    # ---- surge: the vehicle follows the prescribed speed; a longitudinal spring from
    # the moving reference to the chassis at its centre of gravity (no pitch coupling)
    # holds the otherwise free rolling motion (wheel spin is not modelled)
    total = combine([(s.mass, s.cog, s.inertia) for s in segs])
    surge_seg = model.segments[segment_index(bounds, float(total[1][0])) if chassis == "flexible" else 0]
    m_veh = vp.total_mass
    k_surge = m_veh * (2 * np.pi * SURGE_HZ) ** 2
    mg0 = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=model.ground,
                                              localPosition=list(surge_seg.cog)))
    model.surge = mbs.AddObject(ii.ObjectConnectorCartesianSpringDamper(
        markerNumbers=[mg0, pos_marker(surge_seg, surge_seg.cog)], stiffness=[k_surge, 0.0, 0.0],
        damping=[2 * SURGE_DAMPING * np.sqrt(k_surge * m_veh), 0.0, 0.0]))

    # ---- axles, suspension, tyres, road loads
    gm = {}

    def ground_marker(point):
        key = tuple(np.round(point, 9))
        if key not in gm:
            gm[key] = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=model.ground,
                                                          localPosition=list(point)))
        return gm[key]

    for a, ax in enumerate(vp.axles):
        r = ax.tyre_radius
        ya = ax.track / 2
        Jx, Jy, Jz = ax.roll_inertia, ax.pitch_inertia, ax.yaw_inertia
        body = add_body(f"axle{a + 1}", ax.unsprung_mass, [ax.x, 0.0, r], np.diag([Jx, Jy, Jz]))
        model.axles.append(body)
        seg_i = segment_index(bounds, ax.x) if chassis == "flexible" else 0
        seg = model.segments[seg_i]
        centre = np.array([ax.x, 0.0, r])
        seat_c = np.array([ax.x, 0.0, ax.seat_height])
        k_susp, c_susp, pts_susp = [], [], []
        k_tyre, c_tyre, pts_tyre = [], [], []
        first_contact = len(model.contacts)
        for side in SIDES:
            sg = SIDE_SIGN[side]
            point = np.array([ax.x, sg * ax.spring_track / 2, ax.seat_height])
            stiff = [ax.guide_longitudinal_stiffness, ax.guide_lateral_stiffness, ax.spring_stiffness]
            damp = [GUIDE_DAMPING_TIME * stiff[0], GUIDE_DAMPING_TIME * stiff[1], ax.damping]
            k_susp.append(stiff)
            c_susp.append(damp)
            pts_susp.append(point - seat_c)
            model.suspensions.append(Suspension(
                axle=a, side=side, point=point, segment=seg_i, local_frame=point - seg.cog,
                local_axle=point - body.cog, stiffness=ax.spring_stiffness, damping=ax.damping,
                spring_type=ax.spring_type, guide=(stiff, damp)))
            offsets = [0.0] if ax.tyres_per_side == 1 else [-ax.dual_spacing / 2, ax.dual_spacing / 2]
            for o in offsets:
                y = sg * ya + o
                cp = np.array([ax.x, y, r])   # wheel centre: a rolling wheel's contact stays below it
                k_tyre.append([0.0, ax.tyre_lateral_stiffness, ax.tyre_stiffness])
                c_tyre.append([0.0, ax.tyre_damping, ax.tyre_damping])
                pts_tyre.append(cp - centre)
                model.contacts.append(Contact(a, side, y, cp - body.cog, ax.tyre_stiffness,
                                              ax.tyre_damping))
        # all tyres of the axle: one 6-DOF spring-damper to the ground at the axle centre
        Kt, Ct = equivalent_6x6(pts_tyre, k_tyre), equivalent_6x6(pts_tyre, c_tyre)
        obj = mbs.AddObject(ii.ObjectConnectorRigidBodySpringDamper(
            markerNumbers=[mbs.AddMarker(ii.MarkerBodyRigid(bodyNumber=model.ground,
                                                            localPosition=list(centre))),
                           rigid_marker(body, centre)], stiffness=Kt, damping=Ct))
        for ct in model.contacts[first_contact:]:
            ct.obj = obj
        # suspension (both sides, guides) and axle wind-up (pitch relative to the frame:
        # leaf-spring bending or torque rods): one 6-DOF spring-damper at the seat centre
        Kw = np.zeros((6, 6))
        Kw[4, 4] = ax.windup_stiffness
        Ks = equivalent_6x6(pts_susp, k_susp) + Kw
        Cs = equivalent_6x6(pts_susp, c_susp) + GUIDE_DAMPING_TIME * Kw
        obj = mbs.AddObject(ii.ObjectConnectorRigidBodySpringDamper(
            markerNumbers=[rigid_marker(seg, seat_c), rigid_marker(body, seat_c)],
            stiffness=Ks, damping=Cs))
        model.joints.append(obj)
        for su in model.suspensions[-2:]:
            su.obj = obj
        # road input: vertical force at the wheel-centre line and roll moment (global)
        mline = pos_marker(body, [ax.x, 0.0, r])
        lf = mbs.AddLoad(ii.LoadForceVector(markerNumber=mline, loadVector=[0.0, 0.0, 0.0]))
        lt = mbs.AddLoad(ii.LoadTorqueVector(markerNumber=body.marker, loadVector=[0.0, 0.0, 0.0]))
        model.road_loads.append((lf, lt))

    # ---- road input injector: one generalised-force object over all axle nodes, so
    # that the road forces of a time step are set with one call (see road_input_matrix)
    model.injector = mbs.AddObject(ii.ObjectGenericODE2(
        nodeNumbers=[b.node for b in model.axles],
        forceVector=np.zeros(len(model.axles) * (7 if node_type == "EP" else 6))))

    # ---- DCDC block on four mounts (equivalent 6-DOF spring-damper at the base centre)
    d = vp.dcdc
    if d is not None:
        cog = np.array([d.x, d.y, d.z_base + d.cog_height])
        J = d.mass / 12.0 * np.diag([d.width ** 2 + d.height ** 2, d.length ** 2 + d.height ** 2,
                                      d.length ** 2 + d.width ** 2])
        model.dcdc = add_body("dcdc", d.mass, cog, J)
        seg = model.segments[segment_index(bounds, d.x) if chassis == "flexible" else 0]
        base = np.array([d.x, d.y, d.z_base])
        f = d.mount_stiffness_factor
        kx, ky, kz = 4 * f * d.mount_longitudinal_stiffness, 4 * f * d.mount_lateral_stiffness, \
            4 * f * d.mount_vertical_stiffness
        ax_, ay_ = d.mount_x_spacing / 2, d.mount_y_spacing / 2
        krx = kz * ay_ ** 2
        kry = kz * ax_ ** 2
        krz = kx * ay_ ** 2 + ky * ax_ ** 2
        k6 = np.array([kx, ky, kz, krx, kry, krz])
        # damping: ratio mount_damping_ratio at each direction's own uncoupled frequency
        m6 = np.array([d.mass, d.mass, d.mass, J[0, 0] + d.mass * d.cog_height ** 2,
                       J[1, 1] + d.mass * d.cog_height ** 2, J[2, 2]])
        c6 = 2 * d.mount_damping_ratio * np.sqrt(k6 * m6)
        m0, m1 = rigid_marker(seg, base), rigid_marker(model.dcdc, base)
        model.joints.append(mbs.AddObject(ii.ObjectConnectorRigidBodySpringDamper(
            markerNumbers=[m0, m1], stiffness=np.diag(k6), damping=np.diag(c6))))

    # ---- sensors (world-frame node outputs; points follow by rigid-body kinematics)
    for b in model.bodies:
        model.sensors[b.name] = {
            out: mbs.AddSensor(ii.SensorNode(nodeNumber=b.node, storeInternal=True, writeToFile=False,
                                             outputVariableType=getattr(exu.OutputVariableType, out)))
            for out in NODE_OUTPUTS}

    mbs.Assemble()
    if static:
        model.solve_static()
        model.record_static_reference()
        if suspension_terms is not None:
            install_suspension_terms(model, suspension_terms)
    return model


def _suspension_uf(terms, s0):
    """Symbolic-recordable spring-force function of one effect element."""
    def uf(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        u = displacement[2] - s0
        v = velocity[2]
        fz = terms[0](u, v)
        for term in terms[1:]:
            fz = fz + term(u, v)
        return [0.0 * u, 0.0 * u, fz]
    return uf


def install_suspension_terms(model: VehicleModel, suspension_terms) -> int:
    """Add the extra (nonlinear) suspension forces of effects, one element per side.

    Each axle side with terms gets a Cartesian spring-damper with zero stiffness and
    damping between its frame and axle spring seats, whose force is a symbolic user
    function (recorded once, evaluated in C++) of the dynamic compression ``u``
    (zero at static equilibrium) and the compression velocity ``v``.  The linear
    suspension stays in the axle's 6-DOF spring-damper, so switching an effect on
    changes nothing but the effect's own force.  Positive forces push axle and frame
    apart (like the spring in compression).

    Parameters
    ----------
    model : VehicleModel
        At static equilibrium (``static_compression`` known).
    suspension_terms : callable
        ``f(suspension) -> list of term(u, v)`` (see :func:`build_model`).

    Returns
    -------
    int
        Number of effect elements added.
    """
    from exudyn import itemInterface as ii
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    mbs = model.mbs
    n = 0
    for su in model.suspensions:
        terms = [t for t in (suspension_terms(su) or []) if t is not None]
        if not terms:
            continue
        sym = CreateSymbolicUserFunction(mbs, _suspension_uf(terms, float(su.static_compression)),
                                         "springForceUserFunction",
                                         itemTypeName="ObjectConnectorCartesianSpringDamper")
        model._keep.append(sym)
        seg, ax = model.segments[su.segment], model.axles[su.axle]
        m0 = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=seg.body, localPosition=list(su.local_frame)))
        m1 = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=ax.body, localPosition=list(su.local_axle)))
        su.effect_obj = mbs.AddObject(ii.ObjectConnectorCartesianSpringDamper(
            markerNumbers=[m0, m1], stiffness=[0.0, 0.0, 0.0], damping=[0.0, 0.0, 0.0],
            springForceUserFunction=sym))
        n += 1
    if n:
        mbs.Assemble()
        model.solve_static()
    return n
