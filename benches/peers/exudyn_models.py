"""Exudyn models of the mbd validation problems, the same physics as models/*.mbd.

Each builder returns (mbs, sensors, keep): the Exudyn main system (assembled), a dict
channel -> (sensor number, post-processing function of the sensor's value columns) and a list
of objects (symbolic user functions) that must stay alive while the system is solved.

Problem statements: /work/shared/problems/PROBLEMS.md (P2, P3, P5); the .mbd files they copy are
named in each builder. Loads that vary in time are Exudyn *symbolic* user functions, which are
evaluated in C++ (a Python user function would charge the interpreter to Exudyn's solve time).
"""

import math

import numpy as np
import exudyn as exu
import exudyn.itemInterface as ei
from exudyn.advancedUtilities import CreateSymbolicUserFunction

esym = exu.symbolic


def _position_sensor(mbs, body, local=(0.0, 0.0, 0.0)):
    return mbs.AddSensor(ei.SensorBody(bodyNumber=body, localPosition=list(local),
                                       outputVariableType=exu.OutputVariableType.Position,
                                       storeInternal=True, writeToFile=False))


def pendulum(m=1.0, L=0.5, V0=1.5, e=0.1, g=9.81):
    """P2, models/pendulum.mbd: a point mass on a massless rigid link to a pivot at (e, 0, 0),
    started at the bottom (e, -L, 0) with velocity V0 along +x; gravity -g along y."""
    mbs = exu.SystemContainer().AddSystem()
    ground = mbs.AddObject(ei.ObjectGround())
    node = mbs.AddNode(ei.NodePoint(referenceCoordinates=[e, -L, 0.0],
                                    initialVelocities=[V0, 0.0, 0.0]))
    bob = mbs.AddObject(ei.ObjectMassPoint(physicsMass=m, nodeNumber=node))
    pivot = mbs.AddMarker(ei.MarkerBodyPosition(bodyNumber=ground, localPosition=[e, 0.0, 0.0]))
    at_bob = mbs.AddMarker(ei.MarkerBodyPosition(bodyNumber=bob, localPosition=[0.0, 0.0, 0.0]))
    mbs.AddObject(ei.ObjectConnectorDistance(markerNumbers=[pivot, at_bob], distance=L))
    mass = mbs.AddMarker(ei.MarkerBodyMass(bodyNumber=bob))
    mbs.AddLoad(ei.LoadMassProportional(markerNumber=mass, loadVector=[0.0, -g, 0.0]))
    s = _position_sensor(mbs, bob)
    mbs.Assemble()
    return mbs, {"x": (s, lambda v: v[:, 0]), "y": (s, lambda v: v[:, 1])}, []


def _bracket_load(mbs, load, scale):
    """Load vector scale * <t>, <t> = t (0-10 s), 20 s - t (10-20 s), 0 after (two_bar.mbd's
    `piecewise { 0 s: 0 s, 10 s: 10 s, 20 s: 0 s }`), as a symbolic user function."""

    def uf(mbs, t, loadVector):
        return loadVector * esym.max(0.0, esym.min(t, 20.0 - t))

    f = CreateSymbolicUserFunction(mbs, uf, "loadVectorUserFunction", load)
    mbs.SetLoadParameter(load, "loadVectorUserFunction", f)
    return f


def _rod_inertia(m, l, n):
    """Inertia tensor about the centre of a uniform slender rod of mass m, length l, along the
    unit vector n: m l^2/12 (I - n n^T), no rotary inertia about its own axis (as mbd's
    rigid_rod). Exudyn's order: [Jxx, Jyy, Jzz, Jyz, Jxz, Jxy]."""
    J = m * l * l / 12.0 * (np.eye(3) - np.outer(n, n))
    return [J[0, 0], J[1, 1], J[2, 2], J[1, 2], J[0, 2], J[0, 1]]


# Rotation matrix whose third column (the joint's z axis, the axis of ObjectJointRevoluteZ) is
# the body's x axis: columns (y, z, x), a cyclic permutation.
_Z_TO_X = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]


def two_bar(theta2_0=0.0, F0=0.1, T0=0.01, l1=0.5, l2=0.5, m1=1.6, m2=1.6):
    """P3, models/two_bar.mbd: bar 1 along +x from the origin, revolute about z at the origin;
    bar 2 hinged at J = (l1, 0, 0) about e1 (bar 1's axis), pointing along
    n = (0, cos theta2_0, sin theta2_0). Force F0 <t> along +y at J (on bar 1), torque T0 <t>
    on bar 2 about e1, reacted on bar 1. No gravity. Rigid bodies with Euler parameters; each
    body's frame is the inertial frame at t = 0 (its node at the centre of mass)."""
    mbs = exu.SystemContainer().AddSystem()
    ground = mbs.AddObject(ei.ObjectGround())
    n = np.array([0.0, math.cos(theta2_0), math.sin(theta2_0)])

    def rod(centre, m, l, axis):
        node = mbs.AddNode(ei.NodeRigidBodyEP(referenceCoordinates=list(centre) + [1.0, 0, 0, 0],
                                              initialVelocities=[0.0] * 7))
        return mbs.AddObject(ei.ObjectRigidBody(physicsMass=m,
                                                physicsInertia=_rod_inertia(m, l, axis),
                                                nodeNumber=node))

    bar1 = rod([l1 / 2, 0.0, 0.0], m1, l1, np.array([1.0, 0.0, 0.0]))
    c2 = np.array([l1, 0.0, 0.0]) + l2 / 2 * n
    bar2 = rod(c2, m2, l2, n)

    origin = mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    start1 = mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=bar1, localPosition=[-l1 / 2, 0, 0]))
    mbs.AddObject(ei.ObjectJointRevoluteZ(markerNumbers=[origin, start1]))
    end1 = mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=bar1, localPosition=[l1 / 2, 0, 0]))
    start2 = mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=bar2,
                                              localPosition=list(-l2 / 2 * n)))
    mbs.AddObject(ei.ObjectJointRevoluteZ(markerNumbers=[end1, start2],
                                          rotationMarker0=_Z_TO_X, rotationMarker1=_Z_TO_X))

    keep = []
    push = mbs.AddLoad(ei.LoadForceVector(markerNumber=end1, loadVector=[0.0, F0, 0.0]))
    keep.append(_bracket_load(mbs, push, F0))
    # Bar 2 turns about e1 relative to bar 1 and bar 1 about z, so both bodies' x axes stay
    # along e1: the torque and its reaction are body-fixed along x.
    on2 = mbs.AddLoad(ei.LoadTorqueVector(markerNumber=start2, loadVector=[T0, 0.0, 0.0],
                                          bodyFixed=True))
    keep.append(_bracket_load(mbs, on2, T0))
    on1 = mbs.AddLoad(ei.LoadTorqueVector(markerNumber=end1, loadVector=[-T0, 0.0, 0.0],
                                          bodyFixed=True))
    keep.append(_bracket_load(mbs, on1, T0))

    s = _position_sensor(mbs, bar2)
    mbs.Assemble()
    chans = {"xc2": (s, lambda v: v[:, 0]), "yc2": (s, lambda v: v[:, 1]),
             "zc2": (s, lambda v: v[:, 2])}
    return mbs, chans, keep


def windmill(Omega_bar=1.0, blades=4, omega_T=9.26, k_zeta=14.0, e=0.3, L=2.7, mb=20.0,
             ma=100.0):
    """P5, models/windmill.mbd (slider tower): planar, so planar rigid bodies (x, y, phi).
    One body carries the tower-top mass ma (no rotary inertia) and the massless hub: its y is
    held at 0, its x on a spring k_T = M omega_T^2 to ground, its angle prescribed,
    phi = Omega t. Blade i (0-based) is a uniform rod hinged at e (cos psi_i, sin psi_i) by a
    revolute joint with a torsional spring k_zeta on the angle difference blade - hub.
    A triangular 20 N pulse along +x at the hub (0, 5, 10 ms). Initial state: rigid spin Omega
    about the origin."""
    mbs = exu.SystemContainer().AddSystem()
    M = ma + blades * mb
    kT = M * omega_T ** 2
    Omega = Omega_bar * omega_T

    ground_node = mbs.AddNode(ei.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    fixed = mbs.AddMarker(ei.MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))
    hub_node = mbs.AddNode(ei.NodeRigidBody2D(referenceCoordinates=[0.0, 0.0, 0.0],
                                              initialVelocities=[0.0, 0.0, Omega]))
    hub = mbs.AddObject(ei.ObjectRigidBody2D(physicsMass=ma, physicsInertia=0.0,
                                             nodeNumber=hub_node))
    hx, hy, hphi = (mbs.AddMarker(ei.MarkerNodeCoordinate(nodeNumber=hub_node, coordinate=c))
                    for c in range(3))
    mbs.AddObject(ei.CoordinateSpringDamper(markerNumbers=[fixed, hx], stiffness=kT))
    mbs.AddObject(ei.CoordinateConstraint(markerNumbers=[fixed, hy]))
    drive = mbs.AddObject(ei.CoordinateConstraint(markerNumbers=[fixed, hphi]))

    def spin(mbs, t, itemNumber, lOffset):
        return Omega * t

    keep = [CreateSymbolicUserFunction(mbs, spin, "offsetUserFunction", drive)]
    mbs.SetObjectParameter(drive, "offsetUserFunction", keep[-1])

    rc = e + L / 2
    lag = []
    for i in range(blades):
        psi = 2 * math.pi * i / blades
        c, s = math.cos(psi), math.sin(psi)
        node = mbs.AddNode(ei.NodeRigidBody2D(
            referenceCoordinates=[rc * c, rc * s, psi],
            initialVelocities=[-Omega * rc * s, Omega * rc * c, Omega]))
        blade = mbs.AddObject(ei.ObjectRigidBody2D(physicsMass=mb, physicsInertia=mb * L * L / 12,
                                                   nodeNumber=node))
        on_hub = mbs.AddMarker(ei.MarkerBodyPosition(bodyNumber=hub,
                                                     localPosition=[e * c, e * s, 0.0]))
        root = mbs.AddMarker(ei.MarkerBodyPosition(bodyNumber=blade,
                                                   localPosition=[-L / 2, 0.0, 0.0]))
        mbs.AddObject(ei.RevoluteJoint2D(markerNumbers=[on_hub, root]))
        # Coordinate markers act on the displacement part of the angle (the reference angle
        # psi_i excluded), so blade - hub is the lag angle with no offset.
        bphi = mbs.AddMarker(ei.MarkerNodeCoordinate(nodeNumber=node, coordinate=2))
        mbs.AddObject(ei.CoordinateSpringDamper(markerNumbers=[hphi, bphi], stiffness=k_zeta))
        lag.append(node)

    kick = mbs.AddLoad(ei.LoadForceVector(markerNumber=mbs.AddMarker(
        ei.MarkerBodyPosition(bodyNumber=hub, localPosition=[0.0, 0.0, 0.0])),
        loadVector=[4000.0, 0.0, 0.0]))

    def pulse(mbs, t, loadVector):  # 4000 N/s * min(t, 10 ms - t), clipped at 0: 20 N at 5 ms
        return loadVector * esym.max(0.0, esym.min(t, 0.01 - t))

    keep.append(CreateSymbolicUserFunction(mbs, pulse, "loadVectorUserFunction", kick))
    mbs.SetLoadParameter(kick, "loadVectorUserFunction", keep[-1])

    coord = exu.OutputVariableType.Coordinates
    sensors = [mbs.AddSensor(ei.SensorNode(nodeNumber=n, outputVariableType=coord,
                                           storeInternal=True, writeToFile=False))
               for n in [hub_node] + lag]
    mbs.Assemble()
    chans = {"x_hub": (sensors[0], lambda v: v[:, 0])}
    for i in range(blades):
        # zeta_i = (blade angle displacement) - (hub angle displacement): both start at 0.
        chans[f"zeta{i + 1}"] = ((sensors[0], sensors[i + 1]),
                                 lambda h, b: b[:, 2] - h[:, 2])
    return mbs, chans, keep
