"""Robot dynamics: RNEA against Pinocchio and closed forms, mimic torques, energy balance (payloads: test_payload.py)."""

from __future__ import annotations

import textwrap

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots import InvalidInput, ModelError
from pinarms.robots.dynamics import MissingInertials, kinetic_energy, potential_energy, total_mass

G = 9.81

#: Two links pitching about the horizontal y axis; link k is a slender box of mass m_k whose
#: centre of mass lies c_k along its x axis; joint 2 sits L1 along link 1.
M1, C1, L1, M2, C2 = 2.0, 0.15, 0.40, 1.2, 0.20
TWO_LINK_URDF = textwrap.dedent(
    f"""\
    <robot name="two_link">
      <link name="base_link"/>
      <link name="l1"><inertial><origin xyz="{C1} 0 0"/><mass value="{M1}"/>
        <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
      <link name="l2"><inertial><origin xyz="{C2} 0 0"/><mass value="{M2}"/>
        <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <link name="tcp"/>
      <joint name="j1" type="revolute"><parent link="base_link"/><child link="l1"/>
        <axis xyz="0 -1 0"/><origin xyz="0 0 0.3"/><limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
      <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
        <axis xyz="0 -1 0"/><origin xyz="{L1} 0 0"/><limit lower="-3" upper="3" effort="20" velocity="2"/></joint>
      <joint name="tool" type="fixed"><parent link="l2"/><child link="tcp"/><origin xyz="0.3 0 0"/></joint>
    </robot>
    """
)

NO_INERTIALS_URDF = textwrap.dedent(
    """\
    <robot name="bare">
      <link name="base_link"/><link name="a"/><link name="tcp"/>
      <joint name="j1" type="revolute"><parent link="base_link"/><child link="a"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="tool" type="fixed"><parent link="a"/><child link="tcp"/><origin xyz="0.3 0 0"/></joint>
    </robot>
    """
)


@pytest.fixture(scope="module")
def two_link():
    return robots.from_urdf_text(TWO_LINK_URDF)


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


@pytest.fixture(scope="module")
def koji():
    return robots.load("koji_turner")


def _states(robot, n, seed):
    rng = np.random.default_rng(seed)
    return robot.random_q(n, seed=seed), rng.normal(size=(n, robot.nq)), rng.normal(size=(n, robot.nq)) * 3.0


# ------------------------------------------------------------------ closed forms
def test_gravity_of_a_horizontal_link_is_m_g_times_the_lever(two_link):
    # both links level (q = 0): joint 1 holds M1 at C1 and M2 at L1 + C2; joint 2 holds M2 at C2
    tau = two_link.gravity(np.zeros(2))
    np.testing.assert_allclose(tau, [G * (M1 * C1 + M2 * (L1 + C2)), G * M2 * C2], rtol=1e-12)


def test_gravity_closed_form_over_random_angles(two_link):
    q = two_link.random_q(200, seed=3)
    c1, c12 = np.cos(q[:, 0]), np.cos(q[:, 0] + q[:, 1])
    expected = np.column_stack([G * (M1 * C1 * c1 + M2 * (L1 * c1 + C2 * c12)), G * M2 * C2 * c12])
    np.testing.assert_allclose(two_link.gravity(q), expected, rtol=1e-12, atol=1e-12)


def test_point_payload_adds_the_jacobian_transpose_of_its_weight(aubo):
    loaded = aubo.with_payload(3.0)
    q = aubo.random_q(50, seed=5)
    J = aubo.jacobian(q)[:, :3, :]  # linear rows at the tcp, base axes
    weight = np.array([0.0, 0.0, 3.0 * G])  # the force the arm must push up with
    np.testing.assert_allclose(loaded.gravity(q) - aubo.gravity(q), np.einsum("nij,i->nj", J, weight), atol=1e-10)


# ------------------------------------------------------------------ against Pinocchio
@pytest.mark.parametrize("name", ["aubo_i3", "koji_turner", "scara_mushroom", "gantry_flower", "ur5", "panda"])
def test_rnea_equals_pinocchio_one_state_at_a_time(name):
    robot = robots.load(name)
    q, qd, qdd = _states(robot, 40, seed=1)
    data = robot.model.createData()
    qp = robot.q_to_pinocchio(q)
    expected = np.array([pin.rnea(robot.model, data, qp[k], qd[k], qdd[k]) for k in range(40)])
    got = robot.inverse_dynamics(q, qd, qdd)
    assert got.shape == (40, robot.nq)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(robot.inverse_dynamics(q[7], qd[7], qdd[7]), expected[7], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(robot.gravity(q), robot.inverse_dynamics(q, 0 * qd, 0 * qdd), atol=1e-12)


def test_mimic_torques_are_the_coupling_transpose_of_the_full_chain(koji):
    """τ_indep = Gᵀ τ_full with the parallelogram's passive joints as their own coordinates."""
    full = pin.buildModelFromXML(koji.urdf_text, mimic=False)
    assert full.nv == 6 and koji.nq == 4
    G_map = np.zeros((full.nv, koji.nq))
    offset = np.zeros(full.nq)
    for i in range(1, koji.model.njoints):
        joint = koji.model.joints[i]
        row = full.joints[full.getJointId(koji.model.names[i])].idx_v
        if "Mimic" in joint.shortname():
            mimic = joint.extract()
            G_map[row, joint.idx_v] = mimic.scaling
            offset[row] = mimic.offset
        else:
            G_map[row, joint.idx_v] = 1.0
    assert np.count_nonzero(G_map == -1.0) == 2  # elbow_parallel and wrist_level follow with −1
    q, qd, qdd = _states(koji, 25, seed=2)
    data = full.createData()
    tau_full = np.array([pin.rnea(full, data, G_map @ q[k] + offset, G_map @ qd[k], G_map @ qdd[k]) for k in range(25)])
    np.testing.assert_allclose(koji.inverse_dynamics(q, qd, qdd), tau_full @ G_map, rtol=1e-10, atol=1e-9)


# ------------------------------------------------------------------ energy balance
def _random_trajectory(robot, seed, n=400, duration=1.5):
    """A smooth random motion: a quintic per joint inside the limits; q, qd, qdd at n instants."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, duration, n)
    mid = 0.5 * (robot.lower + robot.upper)
    half = 0.3 * (robot.upper - robot.lower)
    coef = rng.uniform(-1.0, 1.0, size=(6, robot.nq)) / duration ** np.arange(6)[:, None] * half / 3.0
    powers = t[:, None] ** np.arange(6)
    q = mid + powers @ coef
    k = np.arange(6)
    qd = (t[:, None] ** np.clip(k - 1, 0, None) * k) @ coef
    qdd = (t[:, None] ** np.clip(k - 2, 0, None) * k * (k - 1)) @ coef
    return t, q, qd, qdd, (mid, coef)


def _q_of(t, mid, coef):
    return mid + (np.atleast_1d(t)[:, None] ** np.arange(6)) @ coef


@pytest.mark.parametrize("name,payload", [("aubo_i3", 0.0), ("aubo_i3", 3.0), ("koji_turner", 25.0), ("ur5", 0.0)])
def test_power_equals_the_rate_of_change_of_energy(name, payload):
    """τ·qd = d(kinetic + potential)/dt along a random trajectory, within 1e-6 relative."""
    robot = robots.load(name).with_payload(payload)
    t, q, qd, qdd, (mid, coef) = _random_trajectory(robot, seed=11)
    k = np.arange(6)
    power = np.sum(robot.inverse_dynamics(q, qd, qdd) * qd, axis=1)

    def energy(tt):
        qq = _q_of(tt, mid, coef)
        vv = (np.atleast_1d(tt)[:, None] ** np.clip(k - 1, 0, None) * k) @ coef
        return kinetic_energy(robot, qq, vv) + potential_energy(robot, qq)

    h = 1e-4
    inner = t[1:-1]
    dE = (energy(inner + h) - energy(inner - h)) / (2.0 * h)
    scale = np.max(np.abs(power))
    assert scale > 1.0  # the motion does real work
    assert np.max(np.abs(power[1:-1] - dE)) / scale < 1e-6


def test_robot_without_inertials_gives_a_named_error():
    bare = robots.from_urdf_text(NO_INERTIALS_URDF)
    assert bare.fk(np.zeros(1)).shape == (4, 4)  # kinematics still work
    with pytest.raises(MissingInertials, match=r"no mass beyond joint\(s\) \['j1'\].*<inertial>"):
        bare.gravity(np.zeros(1))
    with pytest.raises(MissingInertials):
        bare.inverse_dynamics(np.zeros(1), np.zeros(1), np.zeros(1))
    assert issubclass(MissingInertials, ModelError)
    # a payload gives the joint something to move
    assert bare.with_payload(1.0).gravity(np.zeros(1)).shape == (1,)


def test_state_shapes_must_agree(aubo):
    q = aubo.random_q(3)
    with pytest.raises(InvalidInput, match="qd has 2 rows but q has 3"):
        aubo.inverse_dynamics(q, np.zeros((2, 6)), np.zeros((3, 6)))
    with pytest.raises(InvalidInput, match="qdd"):
        aubo.inverse_dynamics(q, np.zeros((3, 6)), np.full((3, 6), np.nan))


# ------------------------------------------------------------------ the AUBO-i3 model's numbers
def test_aubo_weighs_the_datasheet_16_kg_with_the_manufacturers_mass_split(aubo):
    masses = np.array([aubo.model.inertias[i].mass for i in range(aubo.model.njoints)])
    assert total_mass(aubo) == pytest.approx(16.0, abs=1e-9)
    manufacturer = np.array([0.97332, 1.173, 2.7791, 1.5214, 0.63348, 0.63348, 0.13713])
    np.testing.assert_allclose(masses / masses.sum(), manufacturer / manufacturer.sum(), rtol=1e-12)


def test_aubo_efforts_follow_the_stated_rule():
    """Large module = UR5's headroom × the 3 kg holding torque at full reach; small = × 28/150 (docs/robots/aubo_i3.md)."""
    from pinarms.robots.dynamics import holding_torques

    ur5 = robots.load("ur5")
    ur5_hold, _ = holding_torques(ur5.with_payload(5.0, frame="tool0"), n=4000, starts=1)
    assert ur5_hold[1] == pytest.approx(105.54, abs=0.01)  # 5 kg at the UR5's full reach
    aubo = robots.load("aubo_i3")
    hold, q = holding_torques(aubo.with_payload(3.0, frame="flange"), n=4000, starts=1)
    assert hold[1] == pytest.approx(54.73, abs=0.01)
    assert abs(q[1, 1]) == pytest.approx(np.pi / 2, abs=1e-3) and abs(q[1, 2]) < 1e-3  # stretched level
    large = ur5.effort_limit[1] / ur5_hold[1] * max(hold[1], hold[2])
    small = large * ur5.effort_limit[3] / ur5.effort_limit[1]
    np.testing.assert_allclose(aubo.effort_limit, [large] * 3 + [small] * 3, atol=0.05)


#: Rated payloads the built-in arms are sized for (docs/robots/*.md): a mushroom bundle with
#: margin, a flower bunch with margin, one fresh koji block.
RATED_KG = {"scara_mushroom": 1.0, "gantry_flower": 2.0, "koji_turner": 4.0, "koji_turner_rail": 4.0}

#: Time [s] to reach the speed limit from rest: 0.25 s, or v / a where the paper gives an acceleration
#: (seed 002: 1500 rad/s² through 0.01 m/rad = 15 m/s² at 1 m/s).
ACCEL_TIME_S = {"scara_mushroom": 0.25, "gantry_flower": 1.0 / 15.0, "koji_turner": 0.25, "koji_turner_rail": 0.25}


@pytest.mark.parametrize("name", sorted(RATED_KG))
def test_estimated_arms_efforts_follow_the_sizing_rule(name):
    """Effort = hold the rated payload anywhere and reach top speed from rest in ACCEL_TIME_S, rounded up."""
    from pinarms.robots.dynamics import holding_torques

    robot = robots.load(name)
    demand, _ = holding_torques(robot.with_payload(RATED_KG[name]), n=4000, accel_time=ACCEL_TIME_S[name])
    np.testing.assert_array_equal(robot.effort_limit, np.maximum(np.ceil(demand), 1.0))


@pytest.mark.parametrize("name", ["aubo_i3", "koji_turner"])
def test_energies_and_subtree_masses_equal_the_body_by_body_sums(name):
    """Pinocchio's energy and subtree-mass algorithms (or, for mimic joints, the body sum) to 1e-12."""
    arm = robots.load(name).with_payload(1.5)
    model = arm.model
    data = model.createData()
    rng = np.random.default_rng(3)
    q = rng.uniform(-1.0, 1.0, size=(5, arm.nq))
    qd = rng.uniform(-1.0, 1.0, size=(5, arm.nq))
    ke, pe = kinetic_energy(arm, q, qd), potential_energy(arm, q)
    for k in range(q.shape[0]):
        qp = arm.q_to_pinocchio(q[k]).reshape(-1)
        pin.forwardKinematics(model, data, qp, qd[k])
        ref_ke = 0.5 * sum(model.inertias[i].vtiv(data.v[i]) for i in range(1, model.njoints))
        ref_pe = -sum(model.inertias[i].mass * float(model.gravity.linear @ data.oMi[i].act(model.inertias[i].lever))
                      for i in range(1, model.njoints))
        assert ke[k] == pytest.approx(ref_ke, abs=1e-12 * max(1.0, abs(ref_ke)))
        assert pe[k] == pytest.approx(ref_pe, abs=1e-12 * max(1.0, abs(ref_pe)))
    subtree = np.array([model.inertias[i].mass for i in range(model.njoints)])
    for i in range(model.njoints - 1, 0, -1):
        subtree[model.parents[i]] += subtree[i]
    pin.computeSubtreeMasses(model, data)
    np.testing.assert_allclose(np.asarray(data.mass)[1:], subtree[1:], rtol=0.0, atol=1e-12)
    assert subtree[1] > 1.5  # the payload is carried by the first joint's subtree
