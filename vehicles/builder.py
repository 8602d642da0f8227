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
  are held by the stiff axle guides and the tyres;
* suspension: per axle side one Cartesian spring-damper between the spring seat on
  the frame and on the axle, vertical spring and damper of the suspension, stiff
  longitudinal and lateral guide;
* tyres: per tyre (two for a dual pair at +-dual_spacing/2) one Cartesian
  spring-damper from the contact point on the axle to the ground: vertical tyre
  stiffness and damping, lateral and longitudinal tyre stiffness.  The road enters
  as a force: a tyre force ``k (z_r - u) + c (dz_r/dt - du/dt)`` is the constant
  spring-damper ``-k u - c du/dt`` plus the known force ``k z_r + c dz_r/dt``; the
  road forces of all tyres of an axle are applied as one vertical force at the
  axle's contact line plus one roll moment (two loads per axle, set once per
  step).  This is exact for the linear (bilateral) tyre; tyre lift-off is not
  modelled (:attr:`SimResult.meta` reports when a tyre would have lifted);
* DCDC block (tractor): a rigid body on a 6-DOF mount spring-damper equivalent to
  four mounts at the corners of its base;
* gravity on every body; static equilibrium on a flat road by Exudyn's static
  solver, which is the reference (zero) of every output.

Coordinates: Euler-parameter nodes (``node_type="EP"``, 7 coordinates + 1
constraint per body, fastest here) or Tait-Bryan nodes (``"Rxyz"``, 6 coordinates,
no constraint; best for linearisation).  Degrees of freedom: 6 per body.
"""
from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError, SimulationError
from vehicles.frame import (SegmentMass, combine, frame_joints, segment_bounds, segment_index,
                            segment_masses)
from vehicles.params import VehicleParams

GRAVITY = 9.81
#: damping of the stiff axle guides, as a time constant times their stiffness [s]
GUIDE_DAMPING_TIME = 2e-3
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
        Contact point in axle body coordinates (relative to the axle cog) [m].
    stiffness, damping : float
        Vertical tyre stiffness [N/m] and damping [N s/m].
    obj : int
        Exudyn object number of the tyre spring-damper.
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
    """Suspension spring-damper of one axle side.

    ``u = z(axle seat) - z(frame seat)`` is the compression [m] (positive when the
    axle moves up relative to the frame), measured from the unloaded design
    position; ``static_compression`` is its value at static equilibrium.
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
        Exudyn objects of the frame joints (``FrameJoint`` data in ``frame_joints``).
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
    _keep: list = field(default_factory=list)   # symbolic user functions must stay alive

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
    def set_road_forces(self, force: np.ndarray, torque: np.ndarray) -> None:
        """Set the road forces of all axles (one call per load).

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
            i.e. ``Bf[a, c] = 1`` if contact c is on axle a, ``Bt[a, c] = y_c``.
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
        s.staticSolver.newton.relativeTolerance = 1e-10
        s.staticSolver.newton.absoluteTolerance = 1e-8
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
        """Static vertical tyre forces [N] (positive = pressing on the road), per contact."""
        out = []
        for ct in self.contacts:
            z = self.point_position(self.axles[ct.axle].name, ct.local)[2]
            out.append(-ct.stiffness * z)
        return np.array(out)


@contextlib.contextmanager
def _quiet():
    """Silence Exudyn console output of a solver call."""
    cfg = _exu().config
    old = cfg.printToConsole
    cfg.printToConsole = False
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            yield
    finally:
        cfg.printToConsole = old


def _rot_coords(node_type):
    return [1.0, 0.0, 0.0, 0.0] if node_type == "EP" else [0.0, 0.0, 0.0]


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
        for side in SIDES:
            sg = SIDE_SIGN[side]
            point = np.array([ax.x, sg * ax.spring_track / 2, ax.seat_height])
            k_guide = (ax.guide_longitudinal_stiffness, ax.guide_lateral_stiffness)
            stiff = [ax.guide_longitudinal_stiffness, ax.guide_lateral_stiffness, ax.spring_stiffness]
            damp = [GUIDE_DAMPING_TIME * k_guide[0], GUIDE_DAMPING_TIME * k_guide[1], ax.damping]
            m0, m1 = pos_marker(seg, point), pos_marker(body, point)
            obj = mbs.AddObject(ii.ObjectConnectorCartesianSpringDamper(
                markerNumbers=[m0, m1], stiffness=stiff, damping=damp))
            model.suspensions.append(Suspension(
                axle=a, side=side, point=point, segment=seg_i, local_frame=point - seg.cog,
                local_axle=point - body.cog, stiffness=ax.spring_stiffness, damping=ax.damping,
                spring_type=ax.spring_type, guide=(stiff, damp), obj=obj))
            offsets = [0.0] if ax.tyres_per_side == 1 else [-ax.dual_spacing / 2, ax.dual_spacing / 2]
            for o in offsets:
                y = sg * ya + o
                cp = np.array([ax.x, y, 0.0])
                mg, mw = ground_marker(cp), pos_marker(body, cp)
                obj = mbs.AddObject(ii.ObjectConnectorCartesianSpringDamper(
                    markerNumbers=[mg, mw],
                    stiffness=[ax.tyre_longitudinal_stiffness, ax.tyre_lateral_stiffness, ax.tyre_stiffness],
                    damping=[ax.tyre_damping, ax.tyre_damping, ax.tyre_damping]))
                model.contacts.append(Contact(a, side, y, cp - body.cog, ax.tyre_stiffness,
                                              ax.tyre_damping, obj))
        # road input: vertical force at the contact line and roll moment (global)
        mline = pos_marker(body, [ax.x, 0.0, 0.0])
        lf = mbs.AddLoad(ii.LoadForceVector(markerNumber=mline, loadVector=[0.0, 0.0, 0.0]))
        lt = mbs.AddLoad(ii.LoadTorqueVector(markerNumber=body.marker, loadVector=[0.0, 0.0, 0.0]))
        model.road_loads.append((lf, lt))

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


def install_suspension_terms(model: VehicleModel, suspension_terms) -> int:
    """Replace the linear suspension law by a symbolic user function with extra terms.

    Parameters
    ----------
    model : VehicleModel
        Must be at static equilibrium (``static_compression`` known).
    suspension_terms : callable
        ``f(suspension) -> list of term(u, v)`` (see :func:`build_model`).

    Returns
    -------
    int
        Number of suspension elements that got a user function.
    """
    exu = _exu()
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    n = 0
    for s in model.suspensions:
        terms = [t for t in (suspension_terms(s) or []) if t is not None]
        if not terms:
            continue
        s0 = float(s.static_compression)

        def uf(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset,
               _terms=terms, _s0=s0):
            u = displacement[2] - _s0
            v = velocity[2]
            fz = stiffness[2] * displacement[2] + damping[2] * v
            for term in _terms:
                fz = fz + term(u, v)
            return [stiffness[0] * displacement[0] + damping[0] * velocity[0],
                    stiffness[1] * displacement[1] + damping[1] * velocity[1], fz]

        sym = CreateSymbolicUserFunction(model.mbs, uf, "springForceUserFunction",
                                         itemTypeName="ObjectConnectorCartesianSpringDamper")
        model._keep.append(sym)
        model.mbs.SetObjectParameter(s.obj, "springForceUserFunction", sym)
        n += 1
    if n:
        model.mbs.Assemble()
    _ = exu
    return n
